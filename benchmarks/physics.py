"""Physics benchmark: a 1000-step pull+release stroke of a 3-joint finger (target < 0.5 s) and
joint-model throughput (target >= 1e6 samples/s), with a plain-numpy ceiling and the optional
effects measured in the same run. Prints one JSON object (medians).
Run: .venv/bin/python benchmarks/physics.py [--n 1000000] [--steps 500] [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time

import numpy as np

from rjcad.physics.finger import FingerModel, simulate_stroke
from rjcad.physics.inverse import design_finger
from rjcad.physics.joint import PAPER_JOINT, Setup, motion_direction, simulate


def med(fn, repeats):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000, help="joint-model samples per evaluation")
    ap.add_argument("--steps", type=int, default=500, help="finger steps each way (500: 1001 in all)")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    d = math.pi / 180
    # the full finger model: capstan, pin friction with the tendon-induced part, gravity on the links
    m = FingerModel((5.2, 7.8, 10.4), (90 * d,) * 3, (90 * d,) * 3, (6.0,) * 3, wrap=(0.45, 0, 0), mu_t=0.2,
                    friction=(2.0,) * 3, gamma=(1.0,) * 3, link_mass=(17.6, 14.4, 9.8), gravity=(0.0, -1.0))
    c = simulate_stroke(m, 25.0, steps=args.steps)
    t_finger = med(lambda: simulate_stroke(m, 25.0, steps=args.steps), args.repeats)
    n = args.n
    t = np.linspace(0, 100, n)
    th = 0.8 + 0.7 * np.sin(t)
    setup = Setup("tendon", 1.5, routed=True)
    s = motion_direction(th)
    simulate(PAPER_JOINT, setup, th)
    t_joint = med(lambda: simulate(PAPER_JOINT, setup, th), args.repeats)
    t_joint_dir = med(lambda: simulate(PAPER_JOINT, setup, th, direction=s), args.repeats)
    # ceiling: the same arithmetic written as bare numpy (no direction finding, no checks)
    k, th0, f = PAPER_JOINT.stiffness, PAPER_JOINT.preload, PAPER_JOINT.mu_j * 1.5

    def plain():
        x = th + th0
        return np.maximum((k * x + s * f + np.where(s > 0, 1.89 * x, -3.15 * x)) * np.where(s > 0, 1.24, 0.67),
                          0) / 6.0

    t_plain = med(plain, args.repeats)
    # all optional effects on, with non-uniform sample times (measured data)
    rng = np.random.default_rng(0)
    tt = np.cumsum(rng.uniform(0.5, 1.5, n)) * (100.0 / n)
    full = PAPER_JOINT.with_(viscous=0.05, cubic=0.3, relaxation_stiffness=1.0, relaxation_time=2.0)
    t_full = med(lambda: simulate(full, setup, th, tt), args.repeats)
    t_design = med(lambda: design_finger([65, 50, 50], 25, "proximal-first"), args.repeats)
    out = {
        "finger_steps": len(c.tendon_mm),
        "finger_1000_step_stroke_s": t_finger * 1000 / len(c.tendon_mm),
        "finger_target_s": 0.5,
        "joint_samples_per_s": n / t_joint,
        "joint_given_direction_samples_per_s": n / t_joint_dir,
        "joint_numpy_ceiling_samples_per_s": n / t_plain,
        "joint_vs_numpy_ceiling": t_plain / t_joint,
        "joint_all_effects_nonuniform_t_samples_per_s": n / t_full,
        "joint_target_samples_per_s": 1e6,
        "inverse_design_s": t_design,
        "n": n,
        "repeats": args.repeats,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
