"""Life benchmark: the spring optimiser with and without the life constraint, and the Table I critique.

Prints one JSON object. Every figure is the median of several repeats after a warm-up; ratios compare
figures measured in this same run. Target: the optimiser stays well under 50 ms per design with --min-cycles.
Run: .venv/bin/python benchmarks/life.py [--n 100000] [--repeats 7] [--quick]
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys

import numpy as np
from _timing import emit, median_time, parse_args, target

from rjcad import life
from rjcad import spring as sp
from rjcad.materials import get_material, get_printer
from rjcad.spring.optimise import design_spring, optimise_arrays


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=100_000, help="requirements in the batched optimiser")
    ap.add_argument("--repeats", type=int, default=7)
    args = parse_args(ap, quick={"n": 100, "repeats": 2})
    rng = np.random.default_rng(0)

    # 0. Cold start: fitting the design model from the packaged table (what `rjcad spring` pays once).
    def cold():
        life._CACHE.clear()
        life.life_model()

    cold_fit, _ = median_time(cold, args.repeats)

    # 1. One design at a time, the paper joint, without and with the life constraint.
    plain = sp.SpringRequirement(5.2, math.radians(90), math.radians(90))
    with_life = sp.SpringRequirement(5.2, math.radians(90), math.radians(90), min_cycles=1e5)
    reps = args.repeats if args.quick else max(args.repeats, 50)
    t_plain, _ = median_time(lambda: design_spring(plain), reps)
    t_life, _ = median_time(lambda: design_spring(with_life), reps)

    # 2. Batched optimiser over n requirements, without and with the life constraint.
    n = args.n
    K = rng.uniform(0.5, 10, n)
    rot = rng.uniform(0.5, 2.5, n)
    windup = rot + rng.uniform(0, 2.0, n)
    kw = dict(
        material=get_material("absplus-p430"),
        printer=get_printer("generic-0.4"),
        allowed_stress=20.0,
        outer_radius_max=60.0,
        rotation=rot,
    )
    t_batch, _ = median_time(lambda: optimise_arrays(K, windup, **kw), args.repeats)
    t_batch_life, _ = median_time(lambda: optimise_arrays(K, windup, min_cycles=1e5, **kw), args.repeats)

    # 3. The whole critique (3 laws × 2 variants, leave-one-out, profile intervals) and the CLI.
    few = 1 if args.quick else max(3, args.repeats // 2)
    t_crit, _ = median_time(lambda: life.critique(), few)
    t_cli, _ = median_time(
        lambda: subprocess.run(
            [sys.executable, "-m", "rjcad", "spring", "--stiffness", "5.2", "--min-cycles", "1e5", "--json"],
            check=True,
            capture_output=True,
        ),
        few,
    )

    emit(
        {
            "design_model_cold_fit_ms": cold_fit * 1e3,
            "optimiser_ms_per_design_plain": t_plain * 1e3,
            "optimiser_ms_per_design_min_cycles": t_life * 1e3,
            "min_cycles_vs_plain_ratio": t_life / t_plain,
            "batched_designs_per_s_plain": n / t_batch,
            "batched_designs_per_s_min_cycles": n / t_batch_life,
            "batched_min_cycles_vs_plain_ratio": t_batch_life / t_batch,
            "critique_table_i_ms": t_crit * 1e3,
            "cli_spring_min_cycles_json_ms": t_cli * 1e3,
            "n": n,
            "repeats": args.repeats,
            "targets": {"optimiser_ms_per_design_min_cycles": target(t_life * 1e3, at_most=50.0)},
        }
    )


if __name__ == "__main__":
    main()
