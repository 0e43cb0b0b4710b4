"""Shared by every benchmark: one timer, the --quick switch, the targets object and the JSON output.

Not a benchmark itself (`make bench` skips files starting with "_"). Times are wall-clock seconds
(time.perf_counter), and CPU seconds where a figure's name says so (time.process_time: user + system of the
whole process, every thread); a figure is the median of several runs after untimed warm-up runs. --quick (a smoke
run, not a measurement) takes tiny sizes and skips the warm-up runs: every timed call still runs at least once.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable
from typing import Any

#: False after ``parse_args`` saw --quick: the timers below then run no untimed warm-up.
WARM_UP = True


def timed_runs(
    fn: Callable, repeats: int, *, warmup: int = 1, setup: Callable | None = None
) -> list[tuple[float, Any]]:
    """(seconds, result) of ``repeats`` timed calls of ``fn``, after ``warmup`` untimed ones.

    ``setup``, if given, runs untimed before every call and its result is ``fn``'s argument
    (e.g. a fresh parameter object, so that no cache carries over from one run to the next).
    """
    warmup = warmup if WARM_UP else 0
    out = []
    for i in range(warmup + repeats):
        arg = (setup(),) if setup is not None else ()
        t0 = time.perf_counter()
        result = fn(*arg)
        dt = time.perf_counter() - t0
        if i >= warmup:
            out.append((dt, result))
    return out


def median_time(fn: Callable, repeats: int, *, warmup: int = 1, setup: Callable | None = None) -> tuple[float, Any]:
    """Median seconds of ``repeats`` calls of ``fn`` after ``warmup`` untimed ones, and the last call's result."""
    runs = timed_runs(fn, max(repeats, 1), warmup=warmup, setup=setup)
    return statistics.median(t for t, _ in runs), runs[-1][1]


def median_wall_cpu(fn: Callable, repeats: int, *, warmup: int = 1) -> tuple[float, float, Any]:
    """(median wall seconds, median CPU seconds, the last call's result) of ``repeats`` calls of ``fn`` after
    ``warmup`` untimed ones. CPU time is the steadier figure on a shared machine: another job's load stretches the
    wall time far more than it does the process's own CPU time."""
    warmup = warmup if WARM_UP else 0
    walls, cpus, result = [], [], None
    for i in range(warmup + max(repeats, 1)):
        t0, c0 = time.perf_counter(), time.process_time()
        result = fn()
        if i >= warmup:
            walls.append(time.perf_counter() - t0)
            cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus), result


def median_of(rows: list[dict[str, float]]) -> dict[str, float]:
    """Key-wise median of per-run figures (every row has the same keys)."""
    return {k: statistics.median(r[k] for r in rows) for k in rows[0]}


def target(value: float | None, *, at_most: float | None = None, at_least: float | None = None) -> dict:
    """One stated target: ``{"value", "target", "goal": "at most" | "at least", "met"}`` (met None without a value)."""
    if (at_most is None) == (at_least is None):
        raise ValueError("give exactly one of at_most, at_least")
    goal, limit = ("at most", at_most) if at_most is not None else ("at least", at_least)
    met = None if value is None else bool(value <= limit if at_most is not None else value >= limit)
    return {"value": value, "target": limit, "goal": goal, "met": met}


def parse_args(ap: argparse.ArgumentParser, quick: dict[str, Any]) -> argparse.Namespace:
    """``ap``'s arguments plus --quick, which makes ``quick`` the defaults (a smoke run; flags given still win) and
    turns the warm-up runs off."""
    global WARM_UP
    ap.add_argument("--quick", action="store_true", help="tiny sizes, no warm-up: a smoke run, not a measurement")
    args = ap.parse_args()
    if args.quick:
        ap.set_defaults(**quick)
        args = ap.parse_args()
        WARM_UP = False
    return args


def emit(out: dict) -> None:
    """Print the benchmark's one JSON object."""
    print(json.dumps(out, indent=2))
