"""Sweep outputs: results.csv (+ .parquet), pareto.png and summary.md."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rjcad.io.config import write_atomic
from rjcad.io.untrusted import read_text, regular_or_absent
from rjcad.plotting import pyplot, save_png
from rjcad.sweep.spec import INPUTS


def read_results(path: Path) -> list[dict]:
    """The rows of a results.csv as written (none if it does not exist); ``--resume`` reads an earlier run
    with ``rjcad.sweep.resume.read_earlier``, which keeps only intact rows."""
    if not regular_or_absent(path):
        return []
    return list(csv.DictReader(io.StringIO(read_text(path, "CSV"), newline="")))


def _columns(rows: list[dict]) -> list[str]:
    cols = list(INPUTS) + ["id", "status", "feasible", "binding", "error"]
    for r in rows:
        for k in r:
            if k not in cols:
                cols.append(k)
    return cols


def write_results(out: Path, rows: list[dict]) -> None:
    """results.csv (a line per row, line breaks in values made spaces) and results.parquet (with pyarrow)."""
    cols = _columns(rows)
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: _one_line(r.get(k, "")) for k in cols})
    write_atomic(out / "results.csv", buf.getvalue())
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    table = pa.table({c: [str(r.get(c, "")) for r in rows] for c in cols})
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    write_atomic(out / "results.parquet", sink.getvalue().to_pybytes())


def _one_line(v):
    """A value as one line: an error message's line breaks become spaces (so a damaged file loses no neighbour)."""
    return " ".join(v.splitlines()) if isinstance(v, str) and ("\n" in v or "\r" in v) else v


def pareto_front(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Indices of points not dominated when minimising x and maximising y."""
    order = np.lexsort((-y, x))
    front, best = [], -np.inf
    for i in order:
        if y[i] > best:
            front.append(i)
            best = y[i]
    return np.array(front, dtype=int)


def write_report(out: Path, rows: list[dict], build: bool, notes: Sequence[str] = ()) -> None:
    """pareto.png (outer radius vs stress margin, and vs life when known) and summary.md (with ``notes``)."""
    ok = [
        r
        for r in rows
        if str(r.get("feasible")) in ("True", "true", "1") and r.get("outer_radius_mm") not in ("", None)
    ]
    mats = sorted({r["material"] for r in ok})
    _write_pareto(out / "pareto.png", ok, mats)
    _write_summary(out / "summary.md", rows, ok, mats, build, notes)


def _write_pareto(path: Path, ok: list[dict], mats: list[str]) -> None:
    """pareto.png: outer radius against stress margin per material, and against predicted life when known."""
    has_life = any(r.get("predicted_cycles") not in ("", None) for r in ok)
    fig, axes = pyplot().subplots(1, 2 if has_life else 1, figsize=(12 if has_life else 7, 5), squeeze=False)
    for m_i, mat in enumerate(mats):
        sub = [r for r in ok if r["material"] == mat]
        x = np.array([float(r["outer_radius_mm"]) for r in sub])
        y = np.array([float(r["allowed_stress_mpa"]) / float(r["max_stress_mpa"]) for r in sub])
        c = f"C{m_i}"
        axes[0, 0].scatter(x, y, s=8, alpha=0.35, color=c)
        f = pareto_front(x, y)
        axes[0, 0].plot(x[f], y[f], "-o", ms=3, color=c, label=f"{mat} (Pareto front)")
        if has_life:
            lp = [
                (float(r["outer_radius_mm"]), float(r["predicted_cycles"]))
                for r in sub
                if r.get("predicted_cycles") not in ("", None)
            ]
            if lp:
                lx, ly = np.array(lp).T
                axes[0, 1].scatter(lx, ly, s=8, alpha=0.35, color=c)
                fl = pareto_front(lx, ly)
                axes[0, 1].plot(lx[fl], ly[fl], "-o", ms=3, color=c, label=mat)
    axes[0, 0].set_xlabel("outer radius [mm] (encumbrance)")
    axes[0, 0].set_ylabel("stress margin, allowed / peak [-]")
    axes[0, 0].set_title("Pareto front: small and safe")
    if mats:
        axes[0, 0].legend(fontsize=8)
    if has_life:
        axes[0, 1].set_yscale("log")
        axes[0, 1].set_xlabel("outer radius [mm]")
        axes[0, 1].set_ylabel("predicted cycles")
        axes[0, 1].legend(fontsize=8)
    fig.tight_layout()
    save_png(fig, path, dpi=100)


def _write_summary(path: Path, rows: list[dict], ok: list[dict], mats: list[str], build: bool, notes) -> None:
    """summary.md: counts by status and binding constraint, the smallest feasible spring per material."""
    n = len(rows)
    by_status: dict[str, int] = {}
    for r in rows:
        by_status[r.get("status", "")] = by_status.get(r.get("status", ""), 0) + 1
    binding: dict[str, int] = {}
    for r in rows:
        if r.get("binding"):
            binding[r["binding"]] = binding.get(r["binding"], 0) + 1
    verified = (
        "every design was built through `design_spring`, so wound by the full rod model (`verified` = true)"
        if build
        else "the springs come from the rod model's table only (`verified` = false); `rjcad spring` "
        "or build mode winds each one with the full rod model"
    )
    lines = [
        f"# Sweep summary ({'build' if build else 'analytic'} mode)",
        "",
        f"Spring physics: {verified}.",
        "",
        f"- designs: {n}",
        *[f"- {k or 'unknown'}: {v}" for k, v in sorted(by_status.items())],
    ]
    if notes:
        lines += ["", "## This run", "", *[f"- {note}" for note in notes]]
    if binding:
        lines += [
            "",
            "## Binding constraints of the infeasible designs",
            "",
            *[f"- {k}: {v}" for k, v in sorted(binding.items(), key=lambda kv: -kv[1])],
        ]
    if ok:
        lines += [
            "",
            "## Smallest feasible spring per material",
            "",
            "| material | outer radius [mm] | stiffness [N·mm/rad] | rotation [deg] | stress margin |",
            "|---|---|---|---|---|",
        ]
        for mat in mats:
            best = min((r for r in ok if r["material"] == mat), key=lambda r: float(r["outer_radius_mm"]))
            lines.append(
                f"| {mat} | {float(best['outer_radius_mm']):.2f} | "
                f"{float(best['stiffness_nmm_per_rad']):.2f} | {float(best['rotation_deg']):.0f} | "
                f"{float(best['allowed_stress_mpa']) / float(best['max_stress_mpa']):.2f} |"
            )
    if build:
        times = [float(r["build_s"]) for r in rows if r.get("build_s") not in ("", None)]
        if times:
            lines += ["", f"Build time per design: median {float(np.median(times)):.2f} s over {len(times)} designs."]
    write_atomic(path, "\n".join(lines) + "\n")
