"""Finger benchmark: build time against the number of joints N (must grow linearly).

Prints one JSON object: median build time for N = 1..max-n (CAD build, and build +
tessellation + measurements), and time(N)/(N·time(1)) from the same run (target <= 1.2).
Run: .venv/bin/python benchmarks/finger.py [--max-n 5] [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from rjcad.cad.build import build_finger_model
from rjcad.cad.finger import FingerParams, build_finger


def template(n: int) -> dict:
    """n identical joints of the paper's proximal joint."""
    return {"joint": [{"stiffness_nmm_per_rad": 5.2}] * n}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-n", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    cad, full = {}, {}
    for n in range(1, args.max_n + 1):
        t_cad, t_full = [], []
        for _ in range(args.repeats):
            fp = FingerParams.from_dict(template(n))
            t0 = time.perf_counter()
            build_finger(fp)
            t_cad.append(time.perf_counter() - t0)
            fp = FingerParams.from_dict(template(n))
            t0 = time.perf_counter()
            build_finger_model(fp)
            t_full.append(time.perf_counter() - t0)
        cad[n], full[n] = statistics.median(t_cad), statistics.median(t_full)
    out = {
        "median_build_s": {str(n): cad[n] for n in cad},
        "median_build_tessellate_measure_s": {str(n): full[n] for n in full},
        "ratio_time_n_over_n_time_1": {str(n): cad[n] / (n * cad[1]) for n in cad},
        "ratio_full_n_over_n_full_1": {str(n): full[n] / (n * full[1]) for n in full},
        "target_ratio_max": 1.2,
        "repeats": args.repeats,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
