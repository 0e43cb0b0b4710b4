"""Benchmarks must keep running: a smoke run with tiny sizes (not a timed test)."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_spring_benchmark_prints_its_json():
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "spring.py"), "--n", "2000", "--repeats", "2"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    for key in ("optimiser_median_ms_per_design_paper_joint", "stiffness_evals_per_s",
                "numpy_plain_a_b3_over_c_per_s", "stiffness_vs_numpy_ceiling", "full_model_evals_per_s",
                "batched_optimiser_designs_per_s"):
        assert d[key] > 0, key


def test_identify_benchmark_prints_its_json():
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "identify.py"), "--sizes", "600,1200",
                        "--repeats", "1"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["paper_campaign_s"] > 0
    assert d["paper_campaign_effects"] == ["coulomb_pin", "tendon_pin_friction", "capstan_path"]
    assert d["samples_per_experiment"] == [600, 1200] and all(s > 0 for s in d["seconds"])
    assert len(d["scaling_exponent"]) == 1
