"""Identify benchmark: the paper campaign end to end, and how the time grows with the samples.

Prints one JSON object. Each figure is the median of --repeats runs after a warm-up (the
paper campaign; 1e5 samples: one run unless --repeats-large). Targets (issue #7): the paper
campaign (5 × 3000 samples, full selection) in ≤ 10 s; the time grows no worse than linearly
with samples per experiment (every scaling exponent ≤ 1.05). Issue #18: a 3-joint whole-finger campaign of
3 experiments × 3000 samples in ≤ 30 s (one hidden effect and a pair), and the finger solver's speed on one path
(µs per step: the angles and tension that fits use, and the full closure with joint tensions and states; with
link weight too, as the campaigns' orientations give it). Each campaign figure comes as wall seconds and as CPU
seconds (``*_cpu_s``: the process's user + system time, every thread; steadier than wall time on a shared
machine). The scaling exponent is log(t_b/t_a)/log(n_b/n_a) between sizes measured in this same run.
Run: .venv/bin/python benchmarks/identify.py [--sizes 1000,10000,100000] [--repeats 3] [--quick]
"""

from __future__ import annotations

import argparse
import math
import tempfile
from dataclasses import replace
from pathlib import Path

from _timing import emit, median_time, median_wall_cpu, parse_args, target

from rjcad.identify.bench import PAPER_PRESET, write_campaign
from rjcad.identify.data import load_campaign
from rjcad.identify.select import identify

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "examples" / "paper_campaign" / "campaign.toml"


def run(path):
    camp = load_campaign(path)
    return identify(camp)


def finger(
    repeats: int,
    samples: int = 3000,
    sets=(("moment_arm",), ("viscous",), ("moment_arm", "coulomb_pin")),
    quick: bool = False,
) -> dict:
    """Whole-finger identification (3 joints, 3 experiments × 3000 samples), with the candidate fits in one thread
    and in two (the last set, same run), and the finger solver's speed. ``quick``: the last set's own run stands
    for its default thread count (not run again)."""
    import numpy as np

    from rjcad import DEG
    from rjcad.identify.campaign import load_campaign as load_any
    from rjcad.identify.finger.bench import write_finger_campaign
    from rjcad.identify.finger.problem import FingerSelector, identify_finger
    from rjcad.physics.finger import FingerModel, simulate_angles, simulate_path

    out = {"finger_campaign_s": {}, "finger_campaign_cpu_s": {}, "finger_campaign_found": {}, "finger_samples": samples}
    with tempfile.TemporaryDirectory() as tmp:
        for effects in sets:
            d = Path(tmp) / "_".join(effects)
            write_finger_campaign(d, list(effects), seed=1, samples=samples)
            t, cpu, ident = median_wall_cpu(lambda d=d: identify_finger(load_any(d / "campaign.toml")), repeats)
            out["finger_campaign_s"]["+".join(effects)] = round(t, 3)
            out["finger_campaign_cpu_s"]["+".join(effects)] = round(cpu, 3)
            out["finger_campaign_found"]["+".join(effects)] = ident.effects
        threads, cpus, workers = {}, {}, FingerSelector.workers
        try:
            for w in (1, 2):
                if quick and w == workers:
                    threads[str(w)], cpus[f"cpu_{w}"] = t, cpu  # the last set, just run with the default threads
                    continue
                FingerSelector.workers = w
                threads[str(w)], cpus[f"cpu_{w}"], _ = median_wall_cpu(
                    lambda: identify_finger(load_any(d / "campaign.toml")), repeats
                )
        finally:
            FingerSelector.workers = workers
        out["finger_campaign_threads_s"] = {
            "set": "+".join(effects),
            **{k: round(v, 3) for k, v in threads.items()},
            **{k: round(v, 3) for k, v in cpus.items()},
            "ratio_1_over_2": round(threads["1"] / threads["2"], 2),
        }
    m = FingerModel(
        (5.2, 7.8, 10.4), (90 * DEG,) * 3, (90 * DEG,) * 3, (6.0,) * 3, friction=(1.0,) * 3, gamma=(1.0,) * 3
    )
    heavy = replace(m, link_mass=(8.0, 6.0, 4.0), gravity=(0.0, -1.0))
    td = np.concatenate([np.linspace(0, 25, 1500), np.linspace(25, 0, 1500)])
    steps = {}
    for name, model in (("", m), ("_weight", heavy)):
        t_angles, _ = median_time(lambda model=model: simulate_angles(model, td), repeats)
        t_closure, _ = median_time(lambda model=model: simulate_path(model, td), repeats)
        steps[f"angles{name}"] = round(1e6 * t_angles / len(td), 3)
        steps[f"closure{name}"] = round(1e6 * t_closure / len(td), 3)
    out["finger_solver_us_per_step"] = steps
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000,100000", help="samples per experiment")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--repeats-large", type=int, default=1, help="repeats for sizes ≥ 1e5")
    args = parse_args(ap, quick={"sizes": "600,1200", "repeats": 1})
    sizes = [int(s) for s in args.sizes.split(",") if s]

    t_load, _ = median_time(lambda: load_campaign(PAPER), args.repeats)  # --quick: no warm-up (_timing)
    t_paper, cpu_paper, ident = median_wall_cpu(lambda: run(PAPER), args.repeats)
    out = {
        "paper_campaign_s": round(t_paper, 3),
        "paper_campaign_cpu_s": round(cpu_paper, 3),
        "paper_campaign_load_s": round(t_load, 4),
        "paper_campaign_effects": ident.effects,
        "samples_per_experiment": [],
        "seconds": [],
        "cpu_seconds": [],
        "effects_found": [],
    }
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            d = Path(tmp) / f"n{n}"
            write_campaign(
                d, PAPER_PRESET["effects"], PAPER_PRESET["params"], design=PAPER_PRESET["design"], seed=1, samples=n
            )
            reps = args.repeats_large if n >= 100_000 else args.repeats
            t, cpu, ident = median_wall_cpu(lambda d=d: run(d / "campaign.toml"), reps, warmup=0)
            out["samples_per_experiment"].append(n)
            out["seconds"].append(round(t, 3))
            out["cpu_seconds"].append(round(cpu, 3))
            out["effects_found"].append(ident.effects)
    s, t = out["samples_per_experiment"], out["seconds"]
    out["us_per_sample"] = [round(1e6 * ti / (5 * ni), 2) for ni, ti in zip(s, t)]
    out["scaling_exponent"] = [
        round(math.log(t[i + 1] / t[i]) / math.log(s[i + 1] / s[i]), 3) for i in range(len(s) - 1)
    ]
    out.update(finger(args.repeats) if not args.quick else finger(1, 300, (("moment_arm",),), quick=True))
    out["targets"] = {
        "paper_campaign_s": target(out["paper_campaign_s"], at_most=10.0),
        "finger_campaign_worst_s": target(max(out["finger_campaign_s"].values()), at_most=30.0),
        "worst_scaling_exponent": target(max(out["scaling_exponent"], default=None), at_most=1.05),
    }
    emit(out)


if __name__ == "__main__":
    main()
