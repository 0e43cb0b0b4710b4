"""Identify benchmark: the paper campaign end to end, and how the time grows with the samples.

Prints one JSON object. Each figure is the median of --repeats runs after a warm-up (the
paper campaign; 1e5 samples: one run unless --repeats-large). Targets (issue #7): the paper
campaign (5 × 3000 samples, full selection) in ≤ 10 s; issue #37: the same campaign with a stiffness drifting
±5 % over each run (outside the catalogue: identified, the term proposed, identified again beside it) in ≤ 15 s; the time grows no worse than linearly
with samples per experiment (every scaling exponent ≤ 1.05). Issue #18: a 3-joint whole-finger campaign of
3 experiments × 3000 samples in ≤ 30 s (one hidden effect and a pair); issue #37: the default finger's campaign
with every spring drifting ±5 % over each run (outside the finger catalogue: the tension drifts, the angles do not)
identified, the term proposed and identified again beside it in ≤ 40 s; and the finger solver's speed on one path
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
from rjcad.identify.propose import extend

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "examples" / "paper_campaign" / "campaign.toml"


def run(path):
    """``rjcad identify``'s joint path: the catalogue, and beyond it where a residual is left."""
    return extend(load_campaign(path))[0]


def drifting_campaign(folder: Path, size: float = 0.05, samples: int = 3000) -> Path:
    """The paper preset's campaign with a stiffness drifting from +size to −size over each run, outside the
    catalogue (issue #37): each file's quantity gets size·K·(θ + θ₀)·(1 − 2t/T), over the pulley radius for a
    tension. Returns the campaign TOML."""
    import numpy as np

    design = PAPER_PRESET["design"]
    write_campaign(folder, PAPER_PRESET["effects"], PAPER_PRESET["params"], design=design, seed=1, samples=samples)
    k, pre = design["stiffness_nmm_per_rad"], math.radians(design["preload_deg"])
    for e in load_campaign(folder / "campaign.toml").experiments:
        t, theta = e.t, e.theta  # theta [rad] from the file
        d = size * k * (theta + pre) * (1.0 - 2.0 * (t - t[0]) / (t[-1] - t[0]))
        y = e.y + (d if e.quantity == "torque_nmm" else d / e.pulley_radius)
        header = f"t_s,theta_deg,{e.quantity}"
        np.savetxt(e.path, np.column_stack([t, np.degrees(theta), y]), delimiter=",", header=header, comments="")
    return folder / "campaign.toml"


def drifting_finger_campaign(folder: Path, size: float = 0.05, samples: int = 3000) -> Path:
    """The default finger's campaign (no catalogue effect) with every spring's stiffness drifting from +size to
    −size over each run: a common stiffness scale leaves the angles as they are and scales the tension, so each
    file's tension is multiplied by 1 + size·(1 − 2t/T). Returns the campaign TOML."""
    import numpy as np

    from rjcad.identify.finger.bench import write_finger_campaign

    write_finger_campaign(folder, [], seed=1, samples=samples)
    for f in sorted(folder.glob("*.csv")):
        head = f.read_text(encoding="utf-8").splitlines()[0]
        data = np.loadtxt(f, delimiter=",", skiprows=1)
        t = data[:, 0]
        col = head.split(",").index("tendon_force_n")
        data[:, col] *= 1.0 + size * (1.0 - 2.0 * (t - t[0]) / (t[-1] - t[0]))
        np.savetxt(f, data, delimiter=",", header=head, comments="", fmt="%.6f")
    return folder / "campaign.toml"


def finger_outside(repeats: int, samples: int) -> dict:
    """``rjcad identify``'s finger path on :func:`drifting_finger_campaign`: wall and CPU seconds, what it found
    and proposed."""
    from rjcad.identify.campaign import load_campaign as load_any
    from rjcad.identify.finger.propose import FingerBasis

    with tempfile.TemporaryDirectory() as tmp:
        toml = drifting_finger_campaign(Path(tmp) / "drift", samples=samples)
        t, cpu, (ident, ext) = median_wall_cpu(lambda: extend(load_any(toml), basis=FingerBasis(3)), repeats)
    return {
        "finger_outside_catalogue_s": round(t, 3),
        "finger_outside_catalogue_cpu_s": round(cpu, 3),
        "finger_outside_catalogue_effects": ident.effects,
        "finger_outside_catalogue_proposed": [] if ext is None else [x["term"] for x in ext.json()],
    }


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
        toml = drifting_campaign(Path(tmp) / "drift", samples=600 if args.quick else 3000)
        t, cpu, ident = median_wall_cpu(lambda: extend(load_campaign(toml)), args.repeats)
        out["outside_catalogue_campaign_s"] = round(t, 3)
        out["outside_catalogue_campaign_cpu_s"] = round(cpu, 3)
        out["outside_catalogue_proposed"] = [] if ident[1] is None else [x["term"] for x in ident[1].json()]
        out["outside_catalogue_effects"] = ident[0].effects
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
    out.update(finger_outside(args.repeats, 600 if args.quick else 3000))
    out["targets"] = {
        "paper_campaign_s": target(out["paper_campaign_s"], at_most=10.0),
        "outside_catalogue_campaign_s": target(out["outside_catalogue_campaign_s"], at_most=15.0),
        "finger_campaign_worst_s": target(max(out["finger_campaign_s"].values()), at_most=30.0),
        "finger_outside_catalogue_s": target(out["finger_outside_catalogue_s"], at_most=40.0),
        "worst_scaling_exponent": target(max(out["scaling_exponent"], default=None), at_most=1.05),
    }
    emit(out)


if __name__ == "__main__":
    main()
