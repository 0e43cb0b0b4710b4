"""Finger benchmark: build time against the number of joints N (must grow linearly).

Prints one JSON object: median build time for N = 1..max-n (CAD build, and build +
tessellation + measurements), and time(N)/(N·time(1)) from the same run (target <= 1.2
for every N). One warm-up build of N = 1 comes first (not with --quick).
Run: .venv/bin/python benchmarks/finger.py [--max-n 5] [--repeats 3] [--quick]
"""

from __future__ import annotations

import argparse

from _timing import emit, median_time, parse_args, target

from rjcad.cad.build import build_finger_model
from rjcad.cad.finger import build_finger
from rjcad.design.finger_params import FingerParams


def template(n: int) -> dict:
    """n identical joints of the paper's proximal joint."""
    return {"joint": [{"stiffness_nmm_per_rad": 5.2}] * n}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-n", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=3)
    args = parse_args(ap, quick={"max_n": 2, "repeats": 1})
    if not args.quick:
        build_finger(FingerParams.from_dict(template(1)))  # warm-up (the first build pays for OCC's start-up)
    cad, full = {}, {}
    for n in range(1, args.max_n + 1):

        def fresh(n: int = n) -> FingerParams:  # a new object per run: no spring design cached across runs
            return FingerParams.from_dict(template(n))

        cad[n], _ = median_time(build_finger, args.repeats, warmup=0, setup=fresh)
        full[n], _ = median_time(build_finger_model, args.repeats, warmup=0, setup=fresh)
    ratio = {n: cad[n] / (n * cad[1]) for n in cad}
    out = {
        "median_build_s": {str(n): cad[n] for n in cad},
        "median_build_tessellate_measure_s": {str(n): full[n] for n in full},
        "ratio_time_n_over_n_time_1": {str(n): ratio[n] for n in cad},
        "ratio_full_n_over_n_full_1": {str(n): full[n] / (n * full[1]) for n in full},
        "repeats": args.repeats,
        "targets": {"worst_ratio_time_n_over_n_time_1": target(max(ratio.values()), at_most=1.2)},
    }
    emit(out)


if __name__ == "__main__":
    main()
