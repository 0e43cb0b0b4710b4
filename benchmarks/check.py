"""Check benchmark: watertight + manifold throughput, motion sweep and clearance times, and the two
printing checks (overhang; slicer with supports off, PrusaSlicer included) on the default finger.

Prints one JSON object (medians of --repeats after a warm-up). Targets: watertight + manifold
>= 1e6 triangles/s on a >= 1M-triangle mesh; the default joint's motion sweep <= 2 s; the overhang
check on the default finger <= 1 s (first call on fresh meshes: ray structures built inside); the
slicer check on the default finger <= 30 s, PrusaSlicer included (one run; not with --quick, nor
without prusa-slicer).
Run: .venv/bin/python benchmarks/check.py [--repeats 3] [--quick]
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import tempfile
from pathlib import Path

import trimesh

from _timing import emit, median_time, parse_args, target

from rjcad import check as chk
from rjcad.cad.build import build_finger_model, write_joint
from rjcad.params import JointParams
from rjcad.materials import get_printer


def print_checks(quick: bool, repeats: int) -> dict:
    """The overhang and slicer checks on the default finger (templates/finger.toml)."""
    from rjcad.cad.finger import FingerParams

    template = Path(__file__).resolve().parents[1] / "templates" / "finger.toml"
    meshes = build_finger_model(FingerParams.from_toml(str(template))).meshes
    names, prn = list(meshes), get_printer("generic-0.4")

    def fresh():
        return [m.copy() for m in meshes.values()]

    t_over, over = median_time(lambda b: chk.check_overhang(b, names, prn), repeats, setup=fresh)
    out = {"finger_triangles": int(sum(len(m.faces) for m in meshes.values())), "finger_overhang_s": t_over,
           "finger_overhang_failing_mm2": over.value, "finger_overhang_passed": over.passed, "finger_slicer_s": None, "finger_prusaslicer_s": None,
           "finger_gcode_read_s": None}
    if not quick and shutil.which("prusa-slicer"):
        t_slice, res = median_time(lambda: chk.check_slicer(list(meshes.values()), names, prn, "prusa"), 1, warmup=0)
        m = re.search(r"sliced in ([\d.]+) s, G-code read in ([\d.]+) s", res.detail)
        out.update({"finger_slicer_passed": res.passed, "finger_slicer_s": t_slice, "finger_prusaslicer_s": float(m.group(1)) if m else None,
                    "finger_gcode_read_s": float(m.group(2)) if m else None})
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--subdivisions", type=int, default=8, help="icosphere subdivisions (8: 1.3 M triangles)")
    args = parse_args(ap, quick={"repeats": 1, "subdivisions": 5})
    big = trimesh.creation.icosphere(subdivisions=args.subdivisions, radius=50.0)
    tris = len(big.faces)

    def solid_checks():
        b = trimesh.Trimesh(big.vertices.copy(), big.faces.copy(), process=False)  # no cached results
        chk.check_watertight([b], ["sphere"])
        return chk.check_manifold([b], ["sphere"])[0]

    t_solid, res = median_time(solid_checks, args.repeats)
    assert res.passed
    with tempfile.TemporaryDirectory() as d:
        write_joint(JointParams(), d, png=False)
        bodies, _ = chk.load_bodies(Path(d) / "joint.stl")
        manifest = json.loads((Path(d) / "joint.json").read_text())
    names = chk.name_bodies(bodies, None, manifest)
    _, mans = chk.check_manifold(bodies, names)
    prn = get_printer("generic-0.4")
    t_motion, motion = median_time(lambda: chk.check_motion(bodies, names, mans, manifest, 0.25, prn), args.repeats)
    t_clear, _ = median_time(lambda: chk.check_clearance(bodies, names, mans, 0.25, 0.02), args.repeats)
    t_feat, _ = median_time(lambda: chk.check_min_feature(bodies, names, prn, 0.02), args.repeats)
    prints = print_checks(args.quick, args.repeats)
    out = {
        "solid_mesh_triangles": tris,
        "watertight_manifold_s": t_solid,
        "watertight_manifold_tri_per_s": tris / t_solid,
        "joint_triangles": int(sum(len(b.faces) for b in bodies)),
        "joint_motion_sweep_s": t_motion,
        "joint_motion_poses": int(motion.detail.split(" poses")[0].split()[-1]),
        "joint_clearance_s": t_clear,
        "joint_min_feature_s": t_feat,
        "min_feature_s_per_100k_triangles": t_feat / (sum(len(b.faces) for b in bodies) / 1e5),
        **prints,
        "repeats": args.repeats,
        "targets": {
            "watertight_manifold_tri_per_s": target(tris / t_solid if tris >= 1_000_000 else None, at_least=1e6),
            "joint_motion_sweep_s": target(t_motion, at_most=2.0),
            "finger_overhang_s": target(prints["finger_overhang_s"], at_most=1.0),
            "finger_slicer_s": target(prints["finger_slicer_s"], at_most=30.0),
        },
    }
    emit(out)


if __name__ == "__main__":
    main()
