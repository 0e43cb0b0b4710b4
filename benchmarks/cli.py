"""CLI benchmark: each command end to end as a new process (what a user waits for), and OpenSCAD on a comparable
module in the same run when it is installed.

Times the median of --repeats runs (after one untimed warm-up) of: `rjcad joint --out DIR` (every output;
its CAD in a forked process, rjcad.cad.process) and the same with RJCAD_CAD_PROCESS=0 (all in one process),
`rjcad finger --out DIR`, `rjcad spring --config templates/spring.toml` (the paper's joint, fully verified),
`rjcad check` on the default joint, `python -c "import rjcad.cli"`; and `openscad -o knuckle.stl
benchmarks/knuckle.scad` (a two-body knuckle with two spiral springs of the default spring's size, tessellated
as finely as rjcad's meshes) if `openscad` is on PATH, with the ratio openscad / rjcad joint, in wall time and
in CPU time (user + system; steadier when other work shares the machine: the load average is reported). The
two joints and OpenSCAD run in turn (joint, one-process joint, OpenSCAD, joint, ...), so a slow spell of a
shared machine hits all three; the ratio is also given as the median of each round's ratio ("_paired"), and what
the CAD process saves as the median of each round's difference ("saved_by_cad_process_s"). In process: the
default joint's build + STL + STEP (no preview), and its ratio to OpenSCAD.
Targets: rjcad joint >= 2x faster than OpenSCAD end to end; the CAD process saves >= 0.3 s (else it goes);
rjcad spring <= 1 s; build + STL + STEP <= 0.5 s (>= 10x OpenSCAD).
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
    return {
        "median_s": statistics.median(times),
        "runs_s": times,
        "median_cpu_s": statistics.median(cpu for _, cpu in runs),
    }


def process_times_in_turn(commands: dict[str, tuple[list[str], dict | None]], repeats: int) -> dict[str, dict]:
    """``process_times`` of several commands run in turn (A B C A B C ...; one untimed round first), so that a
    slow spell of a shared machine hits each alike: each command's times, and per round the ratio of each
    command's time to the first's (``ratios_to_first``)."""
    warmup = 1 if repeats > 1 else 0
    rounds = [
        {name: timed_runs(lambda a=argv, e=env: run(a, e), 1, warmup=0)[0] for name, (argv, env) in commands.items()}
        for _ in range(warmup + repeats)
    ][warmup:]
    first = next(iter(commands))
    out = {}
    for name in commands:
        times = [r[name][0] for r in rounds]
        out[name] = {
            "median_s": statistics.median(times),
            "runs_s": times,
            "median_cpu_s": statistics.median(r[name][1] for r in rounds),
            "ratios_to_first": [r[name][0] / r[first][0] for r in rounds],
        }
    return out


def saved(joint: dict, variant: dict) -> float:
    """Median over the rounds of (variant's time − the joint's) [s]: what the joint's way saves."""
    return statistics.median(v - j for v, j in zip(variant["runs_s"], joint["runs_s"]))


def in_process_build_stl_step(repeats: int) -> float:
    """Median seconds of the default joint's build + STL + STEP in this process (a fresh JointParams each run)."""
    from rjcad.cad import build as jb
    from rjcad.cad import export as ex
    from rjcad.cad import mesh_export as mx
    from rjcad.design.params import JointParams

    def once(p):
        b = jb.build(p)
        mx.stl_bytes(list(b.meshes.values()))
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
        scad = shutil.which("openscad") if not args.no_openscad else None
        turn = {
            "joint": (rjcad("joint", "--out", f"{tmp}/joint"), None),
            "joint_one_process": (rjcad("joint", "--out", f"{tmp}/joint1"), {"RJCAD_CAD_PROCESS": "0"}),
        }
        if scad:
            turn["openscad"] = ([scad, "-o", f"{tmp}/knuckle.stl", str(SCAD)], None)
        out = {
            "import_cli": process_times([sys.executable, "-c", "import rjcad.cli"], n),
            **process_times_in_turn(turn, n),
            "finger": None if args.no_finger else process_times(rjcad("finger", "--out", f"{tmp}/finger"), n),
            "spring": process_times(rjcad("spring", "--config", "templates/spring.toml"), n),
            # on the joint the timed `rjcad joint` runs wrote
            "check": process_times(
                rjcad("check", f"{tmp}/joint/joint.3mf", "--manifest", f"{tmp}/joint/joint.json"), n
            ),
        }
        out.setdefault("openscad", None)
        out["openscad_version"] = (
            subprocess.run([scad, "--version"], capture_output=True, text=True).stderr.strip() if scad else None
        )
    build_s = in_process_build_stl_step(n)
    osc = out["openscad"]["median_s"] if out["openscad"] else None
    ratio = osc / out["joint"]["median_s"] if osc else None
    out["saved_by_cad_process_s"] = saved(out["joint"], out["joint_one_process"])
    out.update(
        {
            "in_process_build_stl_step_s": build_s,
            "ratio_openscad_over_rjcad_joint": ratio,
            "ratio_openscad_over_rjcad_joint_paired": (
                statistics.median(out["openscad"]["ratios_to_first"]) if osc else None
            ),
            "ratio_joint_over_joint_one_process": out["joint"]["median_s"] / out["joint_one_process"]["median_s"],
            "ratio_openscad_over_rjcad_joint_cpu": (
                out["openscad"]["median_cpu_s"] / out["joint"]["median_cpu_s"] if osc else None
            ),
            "load_average_1min": os.getloadavg()[0],
            "cpus": os.cpu_count(),
            "ratio_openscad_over_in_process_build_stl_step": osc / build_s if osc else None,
            "repeats": n,
            "targets": {
                "ratio_openscad_over_rjcad_joint": target(ratio, at_least=2.0),
                "saved_by_cad_process_s": target(out["saved_by_cad_process_s"], at_least=0.3),
                "spring_s": target(out["spring"]["median_s"], at_most=1.0),
                "in_process_build_stl_step_s": target(build_s, at_most=0.5),
            },
        }
    )
    emit(out)


if __name__ == "__main__":
    main()
