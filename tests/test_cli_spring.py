import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from rjcad.cli import main

RJCAD = [sys.executable, "-m", "rjcad"]
PAPER = ["spring", "--stiffness", "5.2", "--rotation", "90", "--preload", "90"]


def run(argv, capsys):
    with pytest.raises(SystemExit) as e:
        main(argv)
    out, err = capsys.readouterr()
    return e.value.code, out, err


def test_json_has_the_pinned_keys(capsys):
    code, out, err = run(PAPER + ["--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    for key in ("width_mm", "thickness_mm", "length_mm", "inner_radius_mm", "pitch_mm", "turns",
                "outer_radius_mm", "spring_stiffness_nmm_per_rad", "joint_stiffness_nmm_per_rad",
                "max_stress_mpa", "allowed_stress_mpa", "min_coil_gap_mm", "material", "end"):
        assert key in d, key
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
    assert d["spring_stiffness_nmm_per_rad"] == pytest.approx(2.6, rel=0.005)
    assert d["max_stress_mpa"] <= d["allowed_stress_mpa"]
    assert d["rotation_deg"] == 90 and d["preload_deg"] == 90


def test_degrees_at_the_cli_radians_inside(capsys):
    _, out, _ = run(PAPER + ["--json"], capsys)
    a = json.loads(out)
    _, out, _ = run(["spring", "--stiffness", "5.2", "--rotation", "45", "--preload", "135", "--json"], capsys)
    b = json.loads(out)
    # same total wind-up (180°): same stress and width; the wound-gap target is the same too
    assert a["max_stress_mpa"] == pytest.approx(b["max_stress_mpa"])
    assert a["width_mm"] == b["width_mm"]


def test_readable_table(capsys):
    code, out, _ = run(PAPER, capsys)
    assert code == 0
    for label in ("width b", "thickness t", "length L", "pitch p", "turns n", "outer radius",
                  "joint stiffness", "peak stress", "allowed stress", "coil gap"):
        assert label in out
    assert "5.2000" in out


def test_options_change_the_design(capsys):
    _, out, _ = run(PAPER + ["--json", "--end", "clamped", "--printer", "dimension-elite",
                             "--material", "PETG", "--safety-factor", "2"], capsys)
    d = json.loads(out)
    assert d["end"] == "clamped" and d["printer"] == "dimension-elite" and d["material"] == "petg"
    assert d["allowed_stress_mpa"] == pytest.approx(44.0 / 2)


@pytest.mark.parametrize(
    "extra, param",
    [
        (["--stiffness", "-1"], "stiffness"),
        (["--stiffness", "0"], "stiffness"),
        (["--stiffness", "nan"], "stiffness"),
        (["--rotation", "400"], "rotation"),
        (["--material", "unobtainium"], "material"),
        (["--printer", "toaster"], "printer"),
        (["--end", "glued"], "end"),
        (["--safety-factor", "0.5"], "safety_factor"),
        (["--stiffness", "abc"], "stiffness"),
    ],
)
def test_bad_input_one_line_exit_2_no_traceback(extra, param, capsys):
    code, out, err = run(PAPER + extra, capsys)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert param in lines[0]
    assert "Traceback" not in err


def test_unknown_material_lists_the_known_ones(capsys):
    _, _, err = run(PAPER + ["--material", "unobtainium"], capsys)
    assert "absplus-p430" in err and "ultem-9085" in err


def test_infeasible_names_the_binding_constraint(capsys):
    code, out, err = run(PAPER + ["--max-outer-radius", "6"], capsys)
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert "outer radius" in err and "--max-outer-radius" in err


def test_missing_stiffness(capsys):
    code, _, err = run(["spring"], capsys)
    assert code == 2 and "--stiffness" in err and err.count("\n") == 1


def test_debug_shows_the_traceback(capsys):
    code, _, err = run(PAPER + ["--stiffness", "-1", "--debug"], capsys)
    assert code == 2
    assert "Traceback" in err and "stiffness" in err.strip().splitlines()[-1]


def test_config_file_and_override(tmp_path, capsys):
    cfg = tmp_path / "spring.toml"
    cfg.write_text('stiffness_nmm_per_rad = 7.8\nrotation_deg = 90\npreload_deg = 90\nmaterial = "pla"\n')
    code, out, err = run(["spring", "--config", str(cfg), "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(7.8, rel=0.005) and d["material"] == "pla"
    _, out, _ = run(["spring", "--config", str(cfg), "--stiffness", "5.2", "--json"], capsys)
    assert json.loads(out)["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)


def test_config_unknown_key_and_missing_file(tmp_path, capsys):
    cfg = tmp_path / "spring.toml"
    cfg.write_text("stiffness_nmm_per_rad = 5.2\nstifness = 3\n")
    code, _, err = run(["spring", "--config", str(cfg)], capsys)
    assert code == 2 and "stifness" in err and "known keys" in err and err.count("\n") == 1
    code, _, err = run(["spring", "--config", str(tmp_path / "nope.toml")], capsys)
    assert code == 2 and "not found" in err


def test_template_is_the_papers_joint(capsys):
    tpl = Path(__file__).parents[1] / "templates" / "spring.toml"
    code, out, err = run(["spring", "--config", str(tpl), "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
    assert d["rotation_deg"] == 90 and d["preload_deg"] == 90 and d["material"] == "absplus-p430"


def test_console_script_end_to_end():
    ok = subprocess.run(RJCAD + PAPER + ["--json"], capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0, ok.stderr
    assert math.isclose(json.loads(ok.stdout)["joint_stiffness_nmm_per_rad"], 5.2, rel_tol=0.005)
    bad = subprocess.run(RJCAD + PAPER + ["--rotation", "400"], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.count("\n") == 1 and "rotation" in bad.stderr and "Traceback" not in bad.stderr
