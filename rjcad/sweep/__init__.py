"""Design-parameter sweeps: analytic mode (the vectorised spring optimiser) or build mode (CAD + checks).

- :mod:`~rjcad.sweep.spec`: the sweep file (grid or Latin hypercube) and its design points.
- :mod:`~rjcad.sweep.analytic`: every point through the spring optimiser, with predicted life.
- :mod:`~rjcad.sweep.build`: one joint built and checked per point.
- :mod:`~rjcad.sweep.execute`: tasks on a local process pool or a Dask distributed cluster (given its
  scheduler address; the tasks are the same plain functions either way), with progress.
- :mod:`~rjcad.sweep.report`: results.csv (+ .parquet), pareto.png and summary.md.

:func:`run_sweep`, here, ties them together (and resumes an interrupted sweep).
"""

from __future__ import annotations

import json
import os
import stat
import time
from contextlib import suppress
from dataclasses import dataclass, field
from pathlib import Path

from rjcad.io.outputs import OutputError, cannot_write, check_writable, make_dirs, output_set, refuse_special, unmake
from rjcad.progress import Progress
from rjcad.progress import report as tell  # rjcad.sweep.report is a module
from rjcad.sweep.analytic import analytic_rows
from rjcad.sweep.build import build_task
from rjcad.sweep.execute import DesignCounter, run_tasks
from rjcad.sweep.report import pareto_front, read_results, write_report, write_results
from rjcad.sweep.resume import Earlier, read_earlier
from rjcad.sweep.spec import DESIGN_KEYS, INPUTS, SweepSpec, point_id

__all__ = [
    "DESIGN_KEYS",
    "INPUTS",
    "DesignCounter",
    "SweepResult",
    "SweepSpec",
    "analytic_rows",
    "build_task",
    "pareto_front",
    "point_id",
    "read_earlier",
    "read_results",
    "run_sweep",
    "run_tasks",
    "write_report",
    "write_results",
]


@dataclass
class SweepResult:
    """A finished sweep: its rows in point order, how many were computed and resumed, wall time [s], and
    notes for the user (what --resume kept and dropped)."""

    rows: list[dict]
    computed: int
    skipped: int
    seconds: float
    notes: list[str] = field(default_factory=list)


def run_sweep(
    spec: SweepSpec,
    out_dir: str | Path,
    *,
    build: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    keep_meshes: bool = False,
    stream=None,
    progress: Progress | None = None,
) -> SweepResult:
    """Run a sweep and write results.csv (+ .parquet), pareto.png and summary.md into ``out_dir`` (one set).

    ``resume``: keep the intact rows of an earlier run (``rjcad.sweep.resume``) and compute the other designs.
    Progress: ``progress`` (a ``rjcad.progress.Progress``) is told each finished design; without it, a plain line
    goes to ``stream`` (a text file) every few seconds, if given.
    Interrupted (Ctrl-C; SIGTERM through the CLI) or failing, it leaves the earlier output set as it was;
    the rows a build-mode run finished are in ``results.partial.jsonl``, for ``--resume``.
    """
    out = check_writable(out_dir)
    points = spec.points()
    log_path = out / "results.partial.jsonl"
    earlier = read_earlier(out / "results.csv", log_path) if resume else Earlier()
    notes = [earlier.note()] if resume else []
    done = {r["id"] for r in earlier.rows}
    todo = _todo(points, done)
    t0 = time.perf_counter()
    counter = DesignCounter(len(todo), stream=stream, report=progress)
    new_rows: list[dict] = []
    if build:
        n = 0 if scheduler else ((os.cpu_count() or 1) if workers is None else workers)
        where = "on the cluster" if scheduler else (f"{n} worker{'s' if n > 1 else ''}" if n else "no workers")
        counter.start(f"building and checking ({where})")
        _build_rows(todo, out, log_path, workers, scheduler, keep_meshes, counter, new_rows)
    else:
        counter.start("designing (analytic)")
        for k in range(0, len(todo), 100_000):
            part = analytic_rows(todo[k : k + 100_000])
            new_rows.extend(part)
            counter.update(len(part))
    tell(progress, "writing results.csv, pareto.png and summary.md")
    rows = _finish(out, points, earlier.rows + new_rows, build, notes, log_path)
    return SweepResult(rows, len(new_rows), len(earlier.rows), time.perf_counter() - t0, notes)


def _todo(points: list[dict], done: set[str]) -> list[dict]:
    """The points still to compute, each design once (a sweep file may name one twice)."""
    todo, seen = [], set(done)
    for pt in points:
        pid = point_id(pt)
        if pid not in seen:
            seen.add(pid)
            todo.append(pt)
    return todo


def _open_log(path: Path):
    """The build log opened to append, never through a link nor on a FIFO or a device (``refuse_special``), with a
    line break first where an interruption cut its last line."""
    refuse_special(path)
    flags = os.O_RDWR | os.O_APPEND | os.O_CREAT | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0)
    fd = os.open(path, flags, 0o644)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OutputError(path, "not a regular file: rjcad does not append to it")
        size = os.lseek(fd, 0, os.SEEK_END)
        cut = size > 0 and os.pread(fd, 1, size - 1) != b"\n"
    except BaseException:
        os.close(fd)
        raise
    log = os.fdopen(fd, "a", encoding="utf-8")
    if cut:
        log.write("\n")  # after a line the interruption cut, so that the next row starts a line of its own
    return log


def _build_rows(
    todo: list[dict],
    out: Path,
    log_path: Path,
    workers: int | None,
    scheduler: str | None,
    keep_meshes: bool,
    progress: DesignCounter,
    new_rows: list[dict],
) -> None:
    """Build mode: run the tasks, each row appended to the log ``log_path`` as it comes (kept by an
    interrupted run; an earlier interrupted run's rows stay in it too, until a run finishes)."""
    workers = (os.cpu_count() or 1) if workers is None else workers
    mesh_dir = check_writable(out / "meshes") if keep_meshes else None
    made = make_dirs(out)
    try:
        log = _open_log(log_path)
    except OSError as e:
        unmake(made)
        raise cannot_write(log_path, e) from None
    except BaseException:
        unmake(made)
        raise

    def keep(row):
        new_rows.append(row)
        try:
            log.write(json.dumps(row, default=str) + "\n")
            log.flush()
        except OSError as e:
            raise cannot_write(log_path, e) from None

    try:
        with log:
            run_tasks(
                build_task, todo, workers, scheduler, progress, keep, mesh_dir=str(mesh_dir) if mesh_dir else None
            )
    except BaseException:
        _drop_empty_log(log_path)
        unmake(made)  # a folder this run made, left empty: no row came (a kept log keeps it)
        raise
    _drop_empty_log(log_path)


def _drop_empty_log(log_path: Path) -> None:
    """No row came: leave no empty log behind."""
    with suppress(OSError):
        if log_path.is_file() and not log_path.is_symlink() and log_path.stat().st_size == 0:
            log_path.unlink()


def _finish(
    out: Path, points: list[dict], rows: list[dict], build: bool, notes: list[str], log_path: Path
) -> list[dict]:
    """Rows in point order, written as one set (results.csv, .parquet, pareto.png, summary.md); the log goes."""
    order = {point_id(pt): i for i, pt in enumerate(points)}
    rows.sort(key=lambda r: order.get(r["id"], len(order)))
    with output_set(out, remove=("results.parquet",)) as stage:
        write_results(stage, rows)
        write_report(stage, rows, build=build, notes=notes)
    log_path.unlink(missing_ok=True)
    return rows
