"""Check benchmark: watertight + manifold throughput, motion sweep and clearance times, the two printing
checks (overhang; slicer with supports off, PrusaSlicer included) on the default finger, and the whole
`rjcad check` on a big two-body mesh with how each check's time grows with the triangle count.

The big mesh is the default joint with each body's triangles split at their edge midpoints (same shape,
4× the triangles per level; levels per body (0, 1), (1, 2), (2, 3), (3, 4): 26 k to 1.7 M triangles), written
as an STL beside the joint's manifest, so that the motion sweep and the clearance run as for a real build.
Each check is timed in-process on every size (wall and CPU seconds) and its growth fitted as CPU time ∝
triangles^exponent (`check_scaling_exponent`: CPU time, which other processes on the cores do not inflate);
the whole `rjcad check --json` runs as a subprocess on the largest size (wall time, CPU time and peak RSS of
that process). The slicer is not part of these: `rjcad check` runs PrusaSlicer only
with `--slicer prusa`.

And the whole `rjcad check --slicer prusa` on the default finger's 3MF against PrusaSlicer alone on the same
bodies and settings, measured in turn in the same run (`finger_check_over_slicer`: ratio of the medians;
`_paired`: median of each round's ratio), with `rjcad check` without the slicer and the G-code read time it
reports (`finger_vs_slicer`; each `rjcad check` in a fresh process, so no G-code cache carries over).

Prints one JSON object (medians of --repeats after a warm-up; the big-mesh figures are single runs).
Targets: watertight + manifold >= 1e6 triangles/s on a >= 1M-triangle mesh; the default joint's motion
sweep <= 2 s; the overhang check on the default finger <= 1 s (first call on fresh meshes: ray structures
built inside; --quick: a one-joint finger); the slicer check on the default finger <= 30 s, PrusaSlicer
included (one run; not with --quick, nor without prusa-slicer); the finger's `rjcad check --slicer prusa` <= 1.3 x
PrusaSlicer alone and without the slicer <= 5 s (not with --quick); the whole `rjcad check` on the >= 1.5M-triangle
mesh <= 60 s and <= 4 GB peak RSS (not with --quick, which stops at 26 k triangles).
Run: .venv/bin/python benchmarks/check.py [--repeats 3] [--quick]
"""

from __future__ import annotations

import argparse
import json
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh
from _timing import emit, median_of, median_time, parse_args, target, timed_runs

from rjcad import check as chk
from rjcad.cad.build import build_finger_model, write_finger, write_joint
from rjcad.check.copies import simplified
from rjcad.design.params import JointParams
from rjcad.materials import get_printer


def _finger_check(cmd: list[str]) -> tuple[float, dict]:
    """Wall seconds and JSON report of one `rjcad check` in its own process."""
    ((seconds, out),) = timed_runs(lambda: subprocess.run(cmd, capture_output=True, text=True).stdout, 1, warmup=0)
    return seconds, json.loads(out)


def finger_vs_slicer(quick: bool, repeats: int) -> dict:
    """`rjcad check --slicer prusa` on the default finger (3MF + manifest, as `rjcad finger` writes them) against
    PrusaSlicer alone slicing the same bodies with the check's settings, and `rjcad check` without the slicer; run
    in turn ``repeats`` times (no warm-up: each `rjcad check` is a fresh process), medians and their ratio, and
    the median of each round's ratio. Not with --quick, nor without prusa-slicer."""
    keys = (
        "finger_check_slicer_s",
        "finger_prusaslicer_alone_s",
        "finger_check_no_slicer_s",
        "finger_check_gcode_read_s",
        "finger_check_over_slicer",
        "finger_check_over_slicer_paired",
    )
    if quick or not shutil.which("prusa-slicer"):
        return dict.fromkeys(keys)
    from rjcad.design.finger_params import FingerParams

    template = Path(__file__).resolve().parents[1] / "templates" / "finger.toml"
    rows = []
    with tempfile.TemporaryDirectory() as d:
        write_finger(FingerParams.from_toml(str(template)), d, png=False)
        mesh, man = str(Path(d, "finger.3mf")), chk.load_manifest(Path(d, "finger.json"))
        bodies, names = chk.load_bodies(mesh)
        names, prn = chk.name_bodies(bodies, names, man), get_printer(man.printer or "generic-0.4")
        cmd = [sys.executable, "-m", "rjcad", "check", mesh, "--manifest", str(Path(d, "finger.json")), "--json"]
        for _ in range(max(repeats, 1)):
            chk.GCODE_CACHE.clear()
            ((alone, (gcode, error, _)),) = timed_runs(
                lambda: chk.start_slicer(bodies, names, prn, "prusa").wait(), 1, warmup=0
            )
            assert gcode is not None, error
            whole, rep = _finger_check(cmd + ["--slicer", "prusa"])
            plain, _ = _finger_check(cmd)
            read = re.search(r"G-code read in ([\d.]+) s", rep["checks"][-1]["detail"])
            rows.append(
                {
                    "whole": whole,
                    "alone": alone,
                    "plain": plain,
                    "read": float(read.group(1)) if read else 0.0,
                    "ratio": whole / alone,
                }
            )
    med = median_of(rows)
    return dict(
        zip(keys, (med["whole"], med["alone"], med["plain"], med["read"], med["whole"] / med["alone"], med["ratio"]))
    )


def print_checks(quick: bool, repeats: int) -> dict:
    """The overhang and slicer checks on the default finger (templates/finger.toml; --quick: a one-joint finger)."""
    from rjcad.design.finger_params import FingerParams

    template = Path(__file__).resolve().parents[1] / "templates" / "finger.toml"
    fp = (
        FingerParams.from_dict({"joint": [{"stiffness_nmm_per_rad": 5.2}]})
        if quick
        else FingerParams.from_toml(str(template))
    )
    meshes = build_finger_model(fp).meshes
    names, prn = list(meshes), get_printer("generic-0.4")

    def fresh():
        return [m.copy() for m in meshes.values()]

    t_over, over = median_time(lambda b: chk.check_overhang(b, names, prn), repeats, setup=fresh)
    out = {
        "finger_triangles": int(sum(len(m.faces) for m in meshes.values())),
        "finger_overhang_s": t_over,
        "finger_overhang_failing_mm2": over.value,
        "finger_overhang_passed": over.passed,
        "finger_slicer_s": None,
        "finger_prusaslicer_s": None,
        "finger_gcode_read_s": None,
    }
    if not quick and shutil.which("prusa-slicer"):
        t_slice, res = median_time(lambda: chk.check_slicer(list(meshes.values()), names, prn, "prusa"), 1, warmup=0)
        m = re.search(r"sliced in ([\d.]+) s, G-code read in ([\d.]+) s", res.detail)
        out.update(
            {
                "finger_slicer_passed": res.passed,
                "finger_slicer_s": t_slice,
                "finger_prusaslicer_s": float(m.group(1)) if m else None,
                "finger_gcode_read_s": float(m.group(2)) if m else None,
            }
        )
    return out


#: Subdivision levels of the default joint's two bodies (largest body first) per size; 26 k … 1.7 M triangles.
LEVELS = [(0, 1), (1, 2), (2, 3), (3, 4)]
BIG_TRIANGLES = 1_500_000


def refined(bodies: list[trimesh.Trimesh], levels) -> trimesh.Trimesh:
    """The bodies with each triangle split at its edge midpoints ``levels[k]`` times (same shape), as one mesh."""
    out = []
    for b, n in zip(bodies, levels):
        v, f = b.vertices, b.faces
        for _ in range(n):
            v, f = trimesh.remesh.subdivide(v, f)
        out.append(trimesh.Trimesh(v, f, process=False))
    return trimesh.util.concatenate(out)


def _cpu() -> float:
    u = resource.getrusage(resource.RUSAGE_SELF)
    return u.ru_utime + u.ru_stime


def time_checks(stl: Path, manifest: Path) -> tuple[dict[str, float], dict[str, float]]:
    """Wall and CPU seconds of each check (and of loading the file) on one mesh, as `run_checks` runs them (one run
    each). CPU time is what the check costs; wall time also holds what other processes take from the cores."""
    man = chk.load_manifest(manifest)
    wall, cpu = {}, {}

    def run(name, fn):
        c0 = _cpu()
        wall[name], out = median_time(fn, 1, warmup=0)
        cpu[name] = _cpu() - c0
        return out

    bodies, names = run("load", lambda: chk.load_bodies(stl))
    names = chk.name_bodies(bodies, names, man)
    prn, cl = get_printer(man.printer), float(man.clearance_mm)
    run("watertight", lambda: chk.check_watertight(bodies, names))
    _, mans = run("manifold", lambda: chk.check_manifold(bodies, names))
    run("bodies", lambda: chk.check_bodies(bodies, len(man.bodies)))
    copies = run("simplify", lambda: simplified(mans))
    run("clearance", lambda: chk.check_clearance(bodies, names, mans, cl, 0.02, copies))
    run("motion", lambda: chk.check_motion(bodies, names, mans, man, cl, prn, copies))
    run("min_feature", lambda: chk.check_min_feature(bodies, names, prn, 0.02))
    run("bed", lambda: chk.check_bed(bodies, prn))
    run("overhang", lambda: chk.check_overhang(bodies, names, prn))
    return wall, cpu


#: Runs a command and prints its peak RSS [kB], CPU seconds and exit code. A child forked from this small process
#: measures only itself: Linux keeps the RSS high-water mark across exec, so a child of the benchmark would
#: inherit the benchmark's size.
LAUNCH = (
    "import os, subprocess, sys; p = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, "
    "stderr=subprocess.DEVNULL); _, s, u = os.wait4(p.pid, 0); "
    "print(u.ru_maxrss, u.ru_utime + u.ru_stime, os.waitstatus_to_exitcode(s))"
)


def whole_check(stl: Path, manifest: Path) -> dict:
    """Wall and CPU seconds, peak RSS [GB] and exit code of `rjcad check STL --manifest M --json` in its own process."""
    cmd = [
        sys.executable,
        "-c",
        LAUNCH,
        sys.executable,
        "-m",
        "rjcad",
        "check",
        str(stl),
        "--manifest",
        str(manifest),
        "--json",
    ]
    secs, out = median_time(lambda: subprocess.run(cmd, capture_output=True, text=True, check=True).stdout, 1, warmup=0)
    rss_kb, cpu, code = out.split()
    return {
        "big_check_s": secs,
        "big_check_cpu_s": float(cpu),
        "big_check_peak_rss_gb": int(rss_kb) / 2**20,
        "big_check_exit_code": int(code),
    }


def scaling(d: Path, quick: bool) -> dict:
    """Each check's seconds on the default joint written in ``d`` and on its refinements, their fitted exponents,
    and the whole check on the largest."""
    levels = LEVELS[:1] if quick else LEVELS
    bodies, _ = chk.load_bodies(d / "joint.stl")
    manifest, stl = d / "joint.json", d / "joint.stl"
    sizes, rows = [int(sum(len(b.faces) for b in bodies))], [time_checks(stl, manifest)]
    for lv in levels:
        stl = d / "refined.stl"
        mesh = refined(bodies, lv)
        mesh.export(stl)
        sizes.append(len(mesh.faces))
        del mesh
        rows.append(time_checks(stl, manifest))
    whole = whole_check(stl, manifest)
    names = list(rows[0][0])
    exponent = {
        k: float(np.polyfit(np.log(sizes), np.log([max(cpu[k], 1e-6) for _, cpu in rows]), 1)[0]) for k in names
    }
    return {
        "check_triangles": sizes,
        "check_seconds": {k: [w[k] for w, _ in rows] for k in names},
        "check_cpu_seconds": {k: [c[k] for _, c in rows] for k in names},
        "check_scaling_exponent": exponent,
        "big_mesh_triangles": sizes[-1],
        **whole,
    }


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
        scale = scaling(Path(d), args.quick)
    names = chk.name_bodies(bodies, None, manifest)
    _, mans = chk.check_manifold(bodies, names)
    prn = get_printer("generic-0.4")
    t_motion, motion = median_time(lambda: chk.check_motion(bodies, names, mans, manifest, 0.25, prn), args.repeats)
    t_clear, _ = median_time(lambda: chk.check_clearance(bodies, names, mans, 0.25, 0.02), args.repeats)
    t_feat, _ = median_time(lambda: chk.check_min_feature(bodies, names, prn, 0.02), args.repeats)
    prints = print_checks(args.quick, args.repeats)
    versus = finger_vs_slicer(args.quick, args.repeats)
    big = scale["big_mesh_triangles"] >= BIG_TRIANGLES
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
        **versus,
        **scale,
        "repeats": args.repeats,
        "targets": {
            "watertight_manifold_tri_per_s": target(tris / t_solid if tris >= 1_000_000 else None, at_least=1e6),
            "joint_motion_sweep_s": target(t_motion, at_most=2.0),
            "finger_overhang_s": target(prints["finger_overhang_s"], at_most=1.0),
            "finger_slicer_s": target(prints["finger_slicer_s"], at_most=30.0),
            "finger_check_over_slicer": target(versus["finger_check_over_slicer"], at_most=1.3),
            "finger_check_no_slicer_s": target(versus["finger_check_no_slicer_s"], at_most=5.0),
            "big_check_s": target(scale["big_check_s"] if big else None, at_most=60.0),
            "big_check_peak_rss_gb": target(scale["big_check_peak_rss_gb"] if big else None, at_most=4.0),
        },
    }
    emit(out)


if __name__ == "__main__":
    main()
