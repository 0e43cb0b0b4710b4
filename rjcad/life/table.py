"""Table I as shipped (``rjcad/data/table1.csv``) and as model input: stresses from the rod model's factors.

Data (paper Table I): seven ABSplus-P430 spiral springs, b = 4.8 mm, about 90° rotation at
30 cycles/min on top of the design's 90° preload; the last row is a run-out (no failure at
8.5e5 cycles: censored).

Stress per row as the spring designer computes it (``rjcad.spring.factors.cycle_stresses``): the
rod model's c, τ and m for the row's spiral (length L, pitch p and t from Table I; the inner radius
is not given, ``TABLE_I_INNER_RADIUS`` = 3 mm is assumed), outer end clamped (the paper's hooks
behaved clamped: its measured 5.19 for 5.2 designed with the clamped formula), loaded in the
designer's sense (unwind). σ(θ) = 6·m·T(θ)/(b·t²), T(θ) = c·E·b·t³/(12L)·θ·τ(θ), cycling θ =
preload → preload + rotation: amplitude (σ(θ_max) − σ(θ_p))/2, peak σ(θ_max) [MPa].
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from importlib import resources

import numpy as np

from rjcad import DEG
from rjcad.materials import get_material
from rjcad.spring.factors import JOINT_SENSE, cycle_stresses
from rjcad.spring.formulas import turns_for_length

#: Table I does not give the springs' inner radius: assumed [mm] (rjcad's smallest, the paper's pin scale).
TABLE_I_INNER_RADIUS = 3.0
#: The outer end assumed for Table I's springs: clamped, as the paper's joint measurement says.
TABLE_I_END = "clamped"


@dataclass(frozen=True)
class Table:
    """A fatigue table as shipped: conditions (``meta``) and per-row columns (mm, cycles)."""

    meta: dict
    length: np.ndarray
    pitch: np.ndarray
    thickness: np.ndarray
    backlash: np.ndarray
    cycles: np.ndarray
    censored: np.ndarray


def read_table(text: str | None = None) -> Table:
    """Parse a table CSV ('# key: value' header lines, then columns); default: the packaged Table I."""
    if text is None:
        text = resources.files("rjcad").joinpath("data", "table1.csv").read_text(encoding="utf-8")
    meta, body = {}, []
    for line in text.splitlines():
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            meta[key.strip()] = value.strip()
        elif line.strip():
            body.append(line)
    rows = list(csv.DictReader(io.StringIO("\n".join(body))))
    col = lambda k: np.array([float(r[k]) for r in rows])  # noqa: E731
    return Table(
        meta,
        col("length_mm"),
        col("pitch_mm"),
        col("thickness_mm"),
        col("backlash_mm"),
        col("cycles"),
        col("censored").astype(bool),
    )


@dataclass(frozen=True)
class LifeData:
    """Model input: stress amplitude [MPa], thickness [mm], backlash [mm], cycles, censored (run-out)."""

    stress_amp: np.ndarray
    thickness: np.ndarray
    backlash: np.ndarray
    cycles: np.ndarray
    censored: np.ndarray

    @property
    def n(self) -> int:
        return len(self.cycles)

    def subset(self, keep) -> LifeData:
        return LifeData(
            *(np.asarray(getattr(self, f))[keep] for f in ("stress_amp", "thickness", "backlash", "cycles", "censored"))
        )


def row_stresses(
    length, pitch, thickness, width, E, rotation, preload, end=TABLE_I_END, inner_radius=TABLE_I_INNER_RADIUS
):
    """(amplitude, peak) bending stress of a spring cycled preload → preload + rotation [MPa].

    The rod model's factors for the spiral (L, p, t, r_in; turns from the exact Archimedean length),
    as the spring designer uses them (rjcad.spring.factors.cycle_stresses, the joint's sense).
    """
    turns = turns_for_length(length, inner_radius, pitch)
    _, peak, amp = cycle_stresses(
        E, width, thickness, length, inner_radius, pitch, turns, preload, rotation, end, JOINT_SENSE
    )
    return amp, peak


def _table_stresses(tab: Table, end: str):
    """(amplitude, peak) of every row of ``tab`` under its own conditions [MPa]."""
    return row_stresses(
        tab.length,
        tab.pitch,
        tab.thickness,
        float(tab.meta["width_mm"]),
        get_material(tab.meta["material"]).youngs_modulus_mpa,
        float(tab.meta["rotation_deg"]) * DEG,
        float(tab.meta["preload_deg"]) * DEG,
        end,
    )


def table_i(runout_bound: float | None = None, end: str = TABLE_I_END) -> LifeData:
    """Table I as model input (optionally moving the run-out's bound to ``runout_bound`` cycles)."""
    tab = read_table()
    amp, _ = _table_stresses(tab, end)
    cycles = tab.cycles.copy()
    if runout_bound is not None:
        cycles[tab.censored] = runout_bound
    return LifeData(amp, tab.thickness, tab.backlash, cycles, tab.censored)


def table_i_peaks(end: str = TABLE_I_END) -> np.ndarray:
    """Peak stress of each Table I row [MPa]."""
    return _table_stresses(read_table(), end)[1]
