"""CLI benchmark: each command end to end as a new process (what a user waits for), and OpenSCAD on a comparable
module in the same run when it is installed.

Times the median of --repeats runs (after one untimed warm-up) of: `rjcad joint --out DIR` (every output;
its CAD in a forked process, rjcad.cad.process) and the same with RJCAD_CAD_PROCESS=0 (all in one process),
`rjcad finger --out DIR`, `rjcad spring --config templates/spring.toml` (the paper's joint, fully verified),
`rjcad check` on the default joint, `python -c "import rjcad.cli"`; and `openscad -o knuckle.stl
benchmarks/knuckle.scad` (a two-body knuckle with two spiral springs of the default spring's size, tessellated
as finely as rjcad's meshes) if `openscad` is on PATH, with the ratio openscad / rjcad joint, in wall time and
in CPU time (user + system; steadier when other work shares the machine: the load average is reported). In
process: the default joint's build + STL + STEP (no preview), and its ratio to OpenSCAD.
Targets: rjcad joint >= 2x faster than OpenSCAD end to end; rjcad spring <= 1 s; build + STL + STEP <= 0.5 s
(>= 10x OpenSCAD).
Run: .venv/bin/python benchmarks/cli.py [--repeats 5] [--quick]   (--quick: one run, no finger, no OpenSCAD)
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from _timing import emit, median_time, parse_args, target, timed_runs

ROOT = Path(__file__).resolve().parents[1]
SCAD = ROOT / "benchmarks" / "knuckle.scad"


def rjcad(*args: str) -> list[str]:
    """The command line running rjcad from this checkout in a new interpreter."""
    return [sys.executable, "-m", "rjcad", *args]


def run(argv: list[str], env: dict | None = None) -> float:
    """Run ``argv`` from the repository's root (with ``env`` added to the environment); its CPU seconds (user +
    system, the CAD process's included). A failure stops the benchmark."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, env={**os.environ, **(env or {})})
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({r.returncode}): {r.stderr[-2000:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def process_times(argv: list[str], repeats: int, env: dict | None = None) -> dict:
    """Median and every wall time [s] of ``repeats`` runs of ``argv`` as a new process, after one warm-up; and
    the median CPU seconds (a check on the wall times when other work shares the machine)."""
    runs = timed_runs(lambda: run(argv, env), repeats, warmup=1 if repeats > 1 else 0)  # --quick: no warm-up
    times = [t for t, _ in runs]
    return {"median_s": statistics.median(times), "runs_s": times,
            "median_cpu_s": statistics.median(cpu for _, cpu in runs)}


def in_process_build_stl_step(repeats: int) -> float:
    """Median seconds of the default joint's build + STL + STEP in this process (a fresh JointParams each run)."""
    from rjcad.cad import build as jb
    from rjcad.cad import export as ex
    from rjcad.params import JointParams

    def once(p):
        b = jb.build(p)
        ex.stl_bytes(list(b.meshes.values()))
        ex.step_bytes({"ground": b.solids.ground, "moving": b.solids.moving}, "joint")

    return median_time(once, repeats, warmup=1 if repeats > 1 else 0, setup=JointParams)[0]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--no-openscad", action="store_true", help="skip OpenSCAD even if it is installed")
    ap.add_argument("--no-finger", action="store_true", help="skip `rjcad finger` (the longest command)")
    args = parse_args(ap, quick={"repeats": 1, "no_openscad": True, "no_finger": True})
    n = args.repeats
    with tempfile.TemporaryDirectory() as tmp:
        run(rjcad("joint", "--out", f"{tmp}/j0"))  # the joint `check` reads
        out = {
            "import_cli": process_times([sys.executable, "-c", "import rjcad.cli"], n),
            "joint": process_times(rjcad("joint", "--out", f"{tmp}/joint"), n),
            "joint_one_process": process_times(rjcad("joint", "--out", f"{tmp}/joint1"), n,
                                               env={"RJCAD_CAD_PROCESS": "0"}),
            "finger": None if args.no_finger else process_times(rjcad("finger", "--out", f"{tmp}/finger"), n),
            "spring": process_times(rjcad("spring", "--config", "templates/spring.toml"), n),
            "check": process_times(rjcad("check", f"{tmp}/j0/joint.3mf", "--manifest", f"{tmp}/j0/joint.json"), n),
        }
        scad = shutil.which("openscad") if not args.no_openscad else None
        out["openscad"] = process_times([scad, "-o", f"{tmp}/knuckle.stl", str(SCAD)], n) if scad else None
        out["openscad_version"] = (subprocess.run([scad, "--version"], capture_output=True, text=True).stderr.strip()
                                   if scad else None)
    build_s = in_process_build_stl_step(n)
    osc = out["openscad"]["median_s"] if out["openscad"] else None
    ratio = osc / out["joint"]["median_s"] if osc else None
    out.update({
        "in_process_build_stl_step_s": build_s,
        "ratio_openscad_over_rjcad_joint": ratio,
        "ratio_joint_over_joint_one_process": out["joint"]["median_s"] / out["joint_one_process"]["median_s"],
        "ratio_openscad_over_rjcad_joint_cpu": (out["openscad"]["median_cpu_s"] / out["joint"]["median_cpu_s"]
                                                if osc else None),
        "load_average_1min": os.getloadavg()[0],
        "cpus": os.cpu_count(),
        "ratio_openscad_over_in_process_build_stl_step": osc / build_s if osc else None,
        "repeats": n,
        "targets": {
            "ratio_openscad_over_rjcad_joint": target(ratio, at_least=2.0),
            "spring_s": target(out["spring"]["median_s"], at_most=1.0),
            "in_process_build_stl_step_s": target(build_s, at_most=0.5),
        },
    })
    emit(out)


if __name__ == "__main__":
    main()
