"""Physics benchmark: a 1000-step pull+release stroke of a 3-joint finger (target < 0.5 s) and
joint-model throughput (target >= 1e6 samples/s). Prints one JSON object (medians).
Run: .venv/bin/python benchmarks/physics.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time

import numpy as np

from rjcad.physics.finger import FingerModel, simulate_stroke
from rjcad.physics.joint import PAPER_JOINT, Setup, simulate


def med(fn, repeats):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    d = math.pi / 180
    m = FingerModel((5.2, 7.8, 10.4), (90 * d,) * 3, (90 * d,) * 3, (6.0,) * 3, wrap=(0.45, 0, 0), mu_t=0.2,
                    friction=(2.0,) * 3, gamma=(1.0,) * 3)
    t_finger = med(lambda: simulate_stroke(m, 25.0, steps=500), args.repeats)  # 501 + 500 = 1001 steps
    n = 1_000_000
    t = np.linspace(0, 100, n)
    th = 0.8 + 0.7 * np.sin(t)
    setup = Setup("tendon", 1.5, routed=True)
    simulate(PAPER_JOINT, setup, th)
    t_joint = med(lambda: simulate(PAPER_JOINT, setup, th), args.repeats)
    out = {
        "finger_1000_step_stroke_s": t_finger,
        "finger_target_s": 0.5,
        "joint_samples_per_s": n / t_joint,
        "joint_target_samples_per_s": 1e6,
        "repeats": args.repeats,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
