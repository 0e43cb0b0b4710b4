"""Joint benchmark: build time of the default joint, export times, triangle count, STL size.

Prints one JSON object; every time is the median of several repeats in this run.
Target: build + all exports <= 3 s on a 2-core machine.
Run: .venv/bin/python benchmarks/joint.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from rjcad.cad import build as jb
from rjcad.params import JointParams


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    runs = []
    for _ in range(args.repeats):
        p = JointParams()  # a fresh object: the spring design is not cached across runs
        t0 = time.perf_counter()
        b = jb.build(p)
        t1 = time.perf_counter()
        files = jb.render_files(b, "joint", png=True)
        t2 = time.perf_counter()
        runs.append({
            "total_s": t2 - t0,
            "build_tessellate_measure_s": t1 - t0,
            "cad_build_s": b.timings["build_s"],
            "tessellate_s": b.timings["tessellate_s"],
            "measure_s": b.timings["measure_s"],
            "stl_3mf_export_s": b.timings["stl_3mf_s"],
            "step_export_s": b.timings["step_s"],
            "png_s": b.timings["png_s"],
            "exports_s": t2 - t1,
            "triangles": b.manifest["mesh"]["triangles"],
            "stl_bytes": len(files["joint.stl"]),
        })
    med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
    out = {
        "median_total_s": med["total_s"],
        "target_total_s": 3.0,
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
        "repeats": args.repeats,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
