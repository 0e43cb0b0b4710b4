"""Check benchmark: watertight + manifold throughput, motion sweep and clearance times.

Prints one JSON object (medians of --repeats). Targets: watertight + manifold >= 1e6
triangles/s on a >= 1M-triangle mesh; the default joint's motion sweep <= 2 s.
Run: .venv/bin/python benchmarks/check.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import trimesh

from rjcad import check as chk
from rjcad.cad.build import write_joint
from rjcad.params import JointParams
from rjcad.materials import get_printer


def med(fn, repeats):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--subdivisions", type=int, default=8, help="icosphere subdivisions (8: 1.3 M triangles)")
    args = ap.parse_args()
    big = trimesh.creation.icosphere(subdivisions=args.subdivisions, radius=50.0)
    tris = len(big.faces)

    def solid_checks():
        b = trimesh.Trimesh(big.vertices.copy(), big.faces.copy(), process=False)  # no cached results
        chk.check_watertight([b], ["sphere"])
        return chk.check_manifold([b], ["sphere"])[0]

    t_solid, res = med(solid_checks, args.repeats)
    assert res.passed
    with tempfile.TemporaryDirectory() as d:
        write_joint(JointParams(), d, png=False)
        bodies, _ = chk.load_bodies(Path(d) / "joint.stl")
        manifest = json.loads((Path(d) / "joint.json").read_text())
    names = chk.name_bodies(bodies, None, manifest)
    _, mans = chk.check_manifold(bodies, names)
    prn = get_printer("generic-0.4")
    t_motion, motion = med(lambda: chk.check_motion(bodies, names, mans, manifest, 0.25, prn), args.repeats)
    t_clear, _ = med(lambda: chk.check_clearance(bodies, names, mans, 0.25, 0.02), args.repeats)
    t_feat, _ = med(lambda: chk.check_min_feature(bodies, names, prn, 0.02), args.repeats)
    out = {
        "solid_mesh_triangles": tris,
        "watertight_manifold_s": t_solid,
        "watertight_manifold_tri_per_s": tris / t_solid,
        "target_tri_per_s": 1e6,
        "joint_triangles": int(sum(len(b.faces) for b in bodies)),
        "joint_motion_sweep_s": t_motion,
        "joint_motion_poses": int(motion.detail.split(" poses")[0].split()[-1]),
        "target_motion_s": 2.0,
        "joint_clearance_s": t_clear,
        "joint_min_feature_s": t_feat,
        "repeats": args.repeats,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
