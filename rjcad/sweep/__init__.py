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
import time
from dataclasses import dataclass
from pathlib import Path

from rjcad.sweep.analytic import analytic_rows
from rjcad.sweep.build import build_task
from rjcad.sweep.execute import Progress, run_tasks
from rjcad.sweep.report import pareto_front, read_results, write_report, write_results
from rjcad.sweep.spec import DESIGN_KEYS, INPUTS, SweepSpec, point_id

__all__ = [
    "DESIGN_KEYS", "INPUTS", "Progress", "SweepResult", "SweepSpec", "analytic_rows", "build_task", "pareto_front",
    "point_id", "read_results", "run_sweep", "run_tasks", "write_report", "write_results",
]


def _done_rows(csv_path: Path, partial: Path) -> list[dict]:
    """Rows of an earlier run (for --resume): results.csv, then the rows an interrupted build-mode run logged."""
    done_rows = read_results(csv_path)
    if partial.exists():
        seen = {r["id"] for r in done_rows}
        for line in partial.read_text().splitlines():
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                continue  # a line cut by the interruption
            if r.get("id") not in seen:
                done_rows.append(r)
                seen.add(r["id"])
    return done_rows


@dataclass
class SweepResult:
    """A finished sweep: its rows in point order, how many were computed and resumed, wall time [s]."""

    rows: list[dict]
    computed: int
    skipped: int
    seconds: float


def run_sweep(spec: SweepSpec, out_dir: str | Path, *, build: bool = False, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False, keep_meshes: bool = False,
              stream=None) -> SweepResult:
    """Run a sweep and write results.csv (+ .parquet), pareto.png and summary.md into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    points = spec.points()
    csv_path = out / "results.csv"
    partial = out / "results.partial.jsonl"
    done_rows = _done_rows(csv_path, partial) if resume else []
    done_ids = {r["id"] for r in done_rows}
    todo = [pt for pt in points if point_id(pt) not in done_ids]
    t0 = time.perf_counter()
    progress = Progress(len(todo), stream=stream)
    new_rows: list[dict] = []
    workers = (os.cpu_count() or 1) if workers is None else workers
    if build:
        with partial.open("a") as log:
            def keep(row):
                new_rows.append(row)
                log.write(json.dumps(row, default=str) + "\n")
                log.flush()
            mesh_dir = str(out / "meshes") if keep_meshes else None
            run_tasks(build_task, todo, workers, scheduler, progress, keep, mesh_dir=mesh_dir)
    else:
        chunk = 100_000
        for k in range(0, len(todo), chunk):
            part = analytic_rows(todo[k:k + chunk])
            new_rows.extend(part)
            progress.update(len(part))
    order = {point_id(pt): i for i, pt in enumerate(points)}
    rows = done_rows + new_rows
    rows.sort(key=lambda r: order.get(r["id"], len(order)))
    write_results(out, rows)
    write_report(out, rows, build=build)
    partial.unlink(missing_ok=True)
    return SweepResult(rows, len(new_rows), len(done_rows), time.perf_counter() - t0)
