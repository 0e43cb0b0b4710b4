"""Joint benchmark: build time of the default joint (desktop layout), export times, triangle count, STL size;
and the stacked layout's total in the same run, for the ratio.

Prints one JSON object; every time is the median of several repeats in this run, after a warm-up.
Target: build + all exports <= 3 s on a 2-core machine.
Run: .venv/bin/python benchmarks/joint.py [--repeats 5] [--quick]
"""

from __future__ import annotations

import argparse

from _timing import emit, median_of, parse_args, target, timed_runs

from rjcad.cad import build as jb
from rjcad.design.params import JointParams


def one_run(p: JointParams) -> dict:
    """Build and render ``p`` once: the builder's own phase timings, the triangles and the STL size."""
    b = jb.build(p)
    files = jb.render_files(b, "joint", png=True)
    return {
        "cad_build_s": b.timings["build_s"],
        "tessellate_s": b.timings["tessellate_s"],
        "measure_s": b.timings["measure_s"],
        "stl_3mf_export_s": b.timings["stl_3mf_s"],
        "step_export_s": b.timings["step_s"],
        "png_s": b.timings["png_s"],
        "triangles": b.manifest["mesh"]["triangles"],
        "stl_bytes": len(files["joint.stl"]),
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    args = parse_args(ap, quick={"repeats": 1})
    # a fresh JointParams per run: the spring design is not cached across runs
    runs = timed_runs(one_run, args.repeats, setup=JointParams)
    med = median_of([{"total_s": t, **r} for t, r in runs])
    stacked = median_of(
        [{"total_s": t, **r} for t, r in timed_runs(one_run, args.repeats, setup=lambda: JointParams(layout="stacked"))]
    )
    out = {
        "layout": JointParams().layout,
        "median_total_s": med["total_s"],
        "median_cad_build_s": med["cad_build_s"],
        "median_tessellate_s": med["tessellate_s"],
        "median_measure_s": med["measure_s"],
        "median_stl_3mf_export_s": med["stl_3mf_export_s"],
        "median_step_export_s": med["step_export_s"],
        "median_png_s": med["png_s"],
        "png_share_of_total": med["png_s"] / med["total_s"],
        "triangles": int(med["triangles"]),
        "stl_bytes": int(med["stl_bytes"]),
        "stl_mb": med["stl_bytes"] / 1e6,
        "stacked_median_total_s": stacked["total_s"],
        "desktop_over_stacked_total": med["total_s"] / stacked["total_s"],
        "repeats": args.repeats,
        "targets": {"median_total_s": target(med["total_s"], at_most=3.0)},
    }
    emit(out)


if __name__ == "__main__":
    main()
