"""Sweep benchmark: analytic designs per second, and build-mode parallel efficiency.

Prints one JSON object. Analytic: an LHS sweep of --analytic-n designs through the
vectorised optimiser (target >= 1e4 designs/s). Build: the same small set of joint
designs (--quick: one, at the smallest rotation, which has the fewest poses to check) with 1 and 2 local
workers, wall time each (median of --repeats) and the parallel efficiency t1 / (2·t2) (target >= 0.8 at 2 workers).
Run: .venv/bin/python benchmarks/sweep.py [--analytic-n 100000] [--build-n 12] [--repeats 1] [--quick]
"""

from __future__ import annotations

import argparse
import io
import tempfile

from _timing import emit, median_time, parse_args, target

from rjcad import sweep as sw


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--analytic-n", type=int, default=100_000)
    ap.add_argument("--build-n", type=int, default=12)
    ap.add_argument("--repeats", type=int, default=1)
    args = parse_args(ap, quick={"analytic_n": 500, "build_n": 1})
    spec = sw.SweepSpec.from_dict(
        {
            "sweep": {"mode": "lhs", "samples": args.analytic_n, "seed": 7},
            "params": {
                "stiffness_nmm_per_rad": {"range": [2, 12]},
                "rotation_deg": {"range": [60, 120]},
                "material": {"values": ["absplus-p430", "pla", "petg"]},
            },
        }
    )
    points = spec.points()
    sw.analytic_rows(points[: min(1000, max(1, len(points) // 10))])  # warm-up on a slice: the full run is the figure
    t_rows, _ = median_time(lambda: sw.analytic_rows(points), 1 if args.quick else 3, warmup=0)
    with tempfile.TemporaryDirectory() as d:
        t_full, _ = median_time(lambda: sw.run_sweep(spec, d, stream=io.StringIO()), 1, warmup=0)
    rotation = {"values": [15]} if args.quick else {"range": [70, 100]}
    build_spec = sw.SweepSpec.from_dict(
        {
            "sweep": {"mode": "lhs", "samples": args.build_n, "seed": 11},
            "params": {"stiffness_nmm_per_rad": {"range": [3, 8]}, "rotation_deg": rotation},
        }
    )
    # warm-up: start the fork server (it imports rjcad's build modules once) so that both timings are warm (--quick:
    # a smoke run, the one-worker run starts it)
    if not args.quick:
        with tempfile.TemporaryDirectory() as d:
            sw.run_sweep(
                sw.SweepSpec.from_dict({"params": {"stiffness_nmm_per_rad": {"values": [5.2]}}}),
                d,
                build=True,
                workers=2,
                stream=io.StringIO(),
            )
    walls = {}
    for workers in (1, 2):

        def run(workers: int = workers) -> None:
            with tempfile.TemporaryDirectory() as d:
                sw.run_sweep(build_spec, d, build=True, workers=workers, stream=io.StringIO())

        walls[workers], _ = median_time(run, args.repeats, warmup=0)  # warm: the fork server above
    out = {
        "analytic_designs": args.analytic_n,
        "analytic_designs_per_s": args.analytic_n / t_rows,
        "analytic_designs_per_s_with_csv_and_plots": args.analytic_n / t_full,
        "build_designs": args.build_n,
        "build_wall_s_1_worker": walls[1],
        "build_wall_s_2_workers": walls[2],
        "parallel_efficiency_2_workers": walls[1] / (2 * walls[2]),
        "note": "N worker processes forked from a server that imported rjcad's build modules once in a warm-up run "
        "(about 1 s, excluded from both timings); designs are built and checked in the workers",
    }
    out["targets"] = {
        "analytic_designs_per_s": target(out["analytic_designs_per_s"], at_least=1e4),
        "parallel_efficiency_2_workers": target(out["parallel_efficiency_2_workers"], at_least=0.8),
    }
    emit(out)


if __name__ == "__main__":
    main()
