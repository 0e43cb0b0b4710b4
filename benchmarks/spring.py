"""Spring benchmark: optimiser latency and vectorised model throughput.

Prints one JSON object. Ratios compare figures measured in this same run;
every figure is the median of several repeats after a warm-up (the machine is noisy).
Target: the optimiser's median time per design of the paper joint <= 50 ms.
Run: .venv/bin/python benchmarks/spring.py [--n 1000000] [--repeats 7] [--quick]
"""

from __future__ import annotations

import argparse
import math
import statistics
from functools import partial

import numpy as np

from _timing import emit, median_time, parse_args, target

from rjcad import spring as sp
from rjcad.errors import InfeasibleDesign
from rjcad.materials import get_material, get_printer
from rjcad.spring.optimise import design_spring, optimise_arrays


def design_or_none(req: sp.SpringRequirement):
    """The optimiser's design for ``req``, or None when it is infeasible (timed all the same)."""
    try:
        return design_spring(req)
    except InfeasibleDesign:
        return None


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000, help="designs in the vectorised arrays")
    ap.add_argument("--repeats", type=int, default=7)
    args = parse_args(ap, quick={"n": 2000, "repeats": 2})
    rng = np.random.default_rng(0)
    n = args.n

    # 1. Optimiser latency, one design at a time (paper joint and random requirements).
    paper = sp.SpringRequirement(5.2, math.radians(90), math.radians(90))
    per_paper, _ = median_time(lambda: design_spring(paper), max(args.repeats, 50))
    reqs = [
        sp.SpringRequirement(float(k), math.radians(float(r)), math.radians(float(p)), outer_radius_max=60.0)
        for k, r, p in zip(rng.uniform(1, 20, 50), rng.uniform(30, 150, 50), rng.uniform(0, 120, 50))
    ]
    # each requirement once, cold: its own time, not a median
    per_random = [median_time(partial(design_or_none, req), 1, warmup=0)[0] for req in reqs]

    # 2. Vectorised model over n designs.
    E = np.full(n, 2200.0)
    b = rng.uniform(2, 10, n)
    t = rng.uniform(0.5, 2, n)
    L = rng.uniform(50, 500, n)
    r_in = rng.uniform(2, 6, n)
    p = rng.uniform(1, 3, n)
    theta = rng.uniform(0.5, 4, n)

    def plain():
        return E * b * t**3 / L

    def stiffness_only():
        return sp.stiffness(E, b, t, L, "pinned")

    def full_model():
        K = sp.stiffness(E, b, t, L, "pinned")
        sigma = sp.peak_stress(K * theta, b, t, "pinned")
        turns = sp.turns_for_length(L, r_in, p)
        gap = sp.coil_gap(r_in, p, turns, t, theta)
        return K, sigma, turns, gap

    t_plain, _ = median_time(plain, args.repeats)  # each after a warm-up (page faults, allocator)
    t_stiff, _ = median_time(stiffness_only, args.repeats)
    t_full, _ = median_time(full_model, args.repeats)

    # 3. Batched optimiser (the sweep's path): designs per second.
    m = min(n, 20_000)
    K = rng.uniform(1, 6, m)
    wind = rng.uniform(1, 4, m)
    batch = lambda: optimise_arrays(  # noqa: E731
        K, wind, material=get_material("absplus-p430"), printer=get_printer("generic-0.4"),
        allowed_stress=31 / 1.5, end="pinned", outer_radius_max=60.0)
    t_batch, _ = median_time(batch, max(3, args.repeats // 2))

    out = {
        "optimiser_median_ms_per_design_paper_joint": per_paper * 1e3,
        "optimiser_median_ms_per_design_random": statistics.median(per_random) * 1e3,
        "optimiser_max_ms_per_design_random": max(per_random) * 1e3,
        "vector_designs": n,
        "numpy_plain_a_b3_over_c_per_s": n / t_plain,
        "stiffness_evals_per_s": n / t_stiff,
        "stiffness_vs_numpy_ceiling": t_plain / t_stiff,
        "full_model_evals_per_s": n / t_full,
        "full_model_vs_numpy_ceiling": t_plain / t_full,
        "full_model_note": "stiffness + peak stress + exact-length turns (6 Newton steps) + wound coil gap",
        "batched_optimiser_designs_per_s": m / t_batch,
        "repeats": args.repeats,
        "targets": {"optimiser_median_ms_per_design_paper_joint": target(per_paper * 1e3, at_most=50.0)},
    }
    emit(out)


if __name__ == "__main__":
    main()
