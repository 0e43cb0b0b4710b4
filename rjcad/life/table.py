"""Table I as shipped (``rjcad/data/table1.csv``) and as model input: stresses from the spring formulas.

Data (paper Table I): seven ABSplus-P430 spiral springs, b = 4.8 mm, about 90° rotation at
30 cycles/min on top of the design's 90° preload; the last row is a run-out (no failure at
8.5e5 cycles: censored).

Stress per row from rjcad's spring model, pinned outer end by default (rjcad's default end):
σ(θ) = m_end·6·K·θ/(b·t²) = 0.8·E·t·θ/L, cycling θ = preload → preload + rotation, so the
amplitude σ_a = 0.8·E·t·rotation/(2L) [MPa] and the peak σ_max = 0.8·E·t·(preload + rotation)/L
(4·σ_a for Table I).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from importlib import resources

import numpy as np

from rjcad.materials import get_material
from rjcad.spring.formulas import peak_stress, stiffness, stress_amplitude
from rjcad.units import DEG



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
    return Table(meta, col("length_mm"), col("pitch_mm"), col("thickness_mm"), col("backlash_mm"),
                 col("cycles"), col("censored").astype(bool))


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

    def subset(self, keep) -> "LifeData":
        return LifeData(*(np.asarray(getattr(self, f))[keep] for f in
                          ("stress_amp", "thickness", "backlash", "cycles", "censored")))


def row_stresses(length, thickness, width, E, rotation, preload, end="pinned"):
    """(amplitude, peak) bending stress of a spring cycled preload → preload + rotation [MPa].

    σ(θ) = m_end·6·K·θ/(b·t²) with K from rjcad.spring.formulas (pinned: 0.8·E·t·θ/L; clamped: E·t·θ/(2L)).
    """
    K = stiffness(E, width, thickness, length, end)
    return (stress_amplitude(K, rotation, width, thickness, end),
            peak_stress(K * (preload + rotation), width, thickness, end))


def _table_stresses(tab: Table, end: str):
    """(amplitude, peak) of every row of ``tab`` under its own conditions [MPa]."""
    return row_stresses(tab.length, tab.thickness, float(tab.meta["width_mm"]),
                        get_material(tab.meta["material"]).youngs_modulus_mpa,
                        float(tab.meta["rotation_deg"]) * DEG, float(tab.meta["preload_deg"]) * DEG, end)


def table_i(runout_bound: float | None = None, end: str = "pinned") -> LifeData:
    """Table I as model input (optionally moving the run-out's bound to ``runout_bound`` cycles)."""
    tab = read_table()
    amp, _ = _table_stresses(tab, end)
    cycles = tab.cycles.copy()
    if runout_bound is not None:
        cycles[tab.censored] = runout_bound
    return LifeData(amp, tab.thickness, tab.backlash, cycles, tab.censored)


def table_i_peaks(end: str = "pinned") -> np.ndarray:
    """Peak stress of each Table I row [MPa]."""
    return _table_stresses(read_table(), end)[1]
