"""Fast, conservative table surrogate of the rod model (rjcad.spring.rod) for the spring optimiser.

For Euler–Bernoulli bending with negligible axial strain the deformed centreline of
the printed spiral under a prescribed wind-up θ depends on the geometry only: with
every length divided by the coil-to-coil pitch p, on (r_in/p, turns, end, sense, arms)
and θ, not on E, b, t or the start angle. So do K_rod/(arms·E·b·t³/12L_arm) and
max|M|/T. ``tools/make_spring_surrogate.py`` solves the rod model once per grid point
and stores, per (end, sense), on a grid of r_in/p_arm (powers of √2, 0.35–16), turns
per arm (steps of 1/16 below 4 turns, 1/8 to 8, 1/6 to 14, 1/4 to 20) and θ (0–2π;
2.5° steps to 30°, then 7.5°):

* ``gap_ratio_min``   h = min over 0 ≤ θ' ≤ θ of the smallest centreline distance between
  coils / p (parts of one arm more than half a turn apart, or of either arm of a pair);
  the coil gap is p·h − t (``coil_gap``);
* ``hub_ratio_min``   q = min over 0 ≤ θ' ≤ θ of (smallest radius of the strip beyond its
  first quarter turn − r_in) / p; the pin gap is r_in − t/2 − r_pin + p·q (``pin_gap``);
* ``stress_factor``   m = max|M|/T of one arm at small wind-up, or the worst over 0 ≤ θ' ≤ θ
  (it grows by up to a few % unwinding); peak stress = 6·m·T_arm/(b·t²);
* ``torque_ratio``    T(θ) / (K·θ), K the small-wind-up stiffness;
* ``stiffness_ratio`` c = K / (arms·E·b·t³/12L_arm) (small wind-up; either sense).

A pair (two arms 180° apart, each of pitch 2p) is one arm of pitch 2p measured against
its copy turned by 180°. Lookups are multilinear in (log r_in/p, turns, θ), vectorised
with numpy broadcasting, and NaN outside the table (r_in/p outside [0.707, 16]; turns
outside [1, 20] for one arm, [0.5, 10] per arm for a pair; θ outside [0, 2π]; NaN
input): the caller then falls back to the rod model.

Conservative by default (``margin=False`` for the raw interpolation): h and q are
lowered, m raised, by margins the generator fitted to the errors against fresh, finer
rod solves at random off-grid geometries and thicknesses (``error_margin``). For h the
margin is β·spread + floor(θ), spread = how much the four (r_in/p, turns) corners of
the query's cell disagree up to θ: where a collapse of the coil pack sets in at different
wind-ups at the corners, the interpolation can be far off, elsewhere it is close.
Beyond the wind-up where h < 0.1 (every printable design, t ≥ 0.1·p, touches) the table
holds h = 0 and keeps q, m, tau at their last values.
"""

from __future__ import annotations

import functools
import importlib.resources
import io
import math
from pathlib import Path

import numpy as np

TWO_PI = 2.0 * math.pi
ENDS = ("clamped", "pinned")
SENSES = ("tighten", "unwind")
COLUMNS = ("h", "h_pair", "q", "m", "tau")  # stored per arm: h, h_pair and q in ARM pitches
DATA = ("data", "spring_surrogate.npz")


class _Tables(dict):
    """The file's arrays by name, each read (and a uint16 table decoded to float: value = offset + scale·code per
    column, 65535 = NaN) on its first use. A design reads one end and sense: a quarter of the tables."""

    def __init__(self, npz):
        super().__init__()
        self.npz = npz

    def __missing__(self, key):
        value = self.npz[key]  # KeyError for a name the file does not hold
        if value.dtype == np.uint16:
            value = np.where(value == 65535, np.nan, self["q_offset"] + self["q_scale"] * value)
        self[key] = value
        return value


@functools.lru_cache(maxsize=4)
def load(path=None) -> dict:
    """The file's arrays, tables decoded to float (NaN where not computed), each when first read; cached.
    ``path``: another file."""
    src = importlib.resources.files("rjcad").joinpath(*DATA) if path is None else Path(path)
    return _Tables(np.load(io.BytesIO(src.read_bytes()), allow_pickle=False))


@functools.lru_cache(maxsize=64)
def _table(column, end, sense, arms, path):
    """(axes, values) of one column restricted to the arms' domain: axes log2(r_in/p), turns, θ."""
    if end not in ENDS or sense not in SENSES or arms not in (1, 2):
        raise ValueError(f"end in {ENDS}, sense in {SENSES}, arms 1 or 2; got {end!r}, {sense!r}, {arms!r}")
    f = load(path)
    log_rho = np.log2(f["rho_arm"] * arms)  # a pair's pitch is half its arms' pitch
    lo, hi = np.log2(f["domain_rho"])
    ks = (log_rho >= lo - 1e-9) & (log_rho <= hi + 1e-9)
    n_lo, n_hi = f[f"domain_turns_{arms}"]
    ns = (f["turns"] >= n_lo - 1e-9) & (f["turns"] <= n_hi + 1e-9)
    if column in ("c", "m0"):
        values = f[f"{end}_{column}"][np.ix_(ks, ns)]
        return (log_rho[ks], f["turns"][ns]), np.ascontiguousarray(values)
    values = f[f"{end}_{sense}"][np.ix_(ks, ns)][..., COLUMNS.index(column)]
    if column in ("h", "h_pair", "q"):
        values = values * arms  # stored in arm pitches
    return (log_rho[ks], f["turns"][ns], f["theta"]), np.ascontiguousarray(values)


def _axis(x, grid):
    """Cell index and weight of x on an increasing grid; NaN weight outside it (or for NaN x)."""
    i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, len(grid) - 2)
    w = (x - grid[i]) / (grid[i + 1] - grid[i])
    return i, np.where((x >= grid[0]) & (x <= grid[-1]), w, np.nan)


def _multilinear(table, cells):
    """Multilinear interpolation of ``table`` (one axis per cell) at the (index, weight) ``cells``."""
    out = 0.0
    for corner in range(1 << len(cells)):
        idx, weight = [], 1.0
        for d, (i, w) in enumerate(cells):
            up = (corner >> d) & 1
            idx.append(i + up if up else i)
            weight = weight * (w if up else 1.0 - w)
        out = out + weight * table[tuple(idx)]
    return out


def _cells(axes, coords):
    coords = list(np.broadcast_arrays(*(np.asarray(x, float) for x in coords)))
    with np.errstate(divide="ignore", invalid="ignore"):
        coords[0] = np.log2(coords[0])
    return [_axis(x, g) for x, g in zip(coords, axes)]


def _lookup(column, end, sense, arms, path, *coords):
    """Interpolate one column at broadcast (r_in/p, turns[, θ])."""
    axes, values = _table(column, end, sense, arms, path)
    return _multilinear(values, _cells(axes, coords))


@functools.lru_cache(maxsize=16)
def _spread(column, end, sense, arms, path):
    """Per (r_in/p, turns) cell and θ node: the largest spread (max − min) of its four corners at any θ' ≤ θ."""
    _, v = _table(column, end, sense, arms, path)
    corners = np.stack([v[:-1, :-1], v[1:, :-1], v[:-1, 1:], v[1:, 1:]])
    return np.maximum.accumulate(corners.max(axis=0) - corners.min(axis=0), axis=-1)


def gap_lookup(theta, r_in_over_p, turns, end: str = "clamped", sense: str = "tighten", arms: int = 1, path=None):
    """(h, spread): the interpolated gap ratio and its cell's corner spread up to θ (no margin)."""
    column = "h" if arms == 1 else "h_pair"
    axes, values = _table(column, end, sense, arms, path)
    cells = _cells(axes, (r_in_over_p, turns, theta))
    (i, _), (j, _), (k, w) = cells
    spread = _spread(column, end, sense, arms, path)
    return _multilinear(values, cells), spread[i, j, k] * (1.0 - w) + spread[i, j, k + 1] * w


def error_margin(
    column: str, theta, end: str = "clamped", sense: str = "tighten", arms: int = 1, path=None, spread=0.0
):
    """The margin built into a lookup at wind-up θ: ``h``, ``q`` [units of p], ``m`` (absolute).

    For ``h`` it is β·spread + floor(θ): the interpolation error grows with how much the
    cell's corners disagree (a collapse that sets in at different wind-ups at the corners).
    """
    _table("q", end, sense, arms, path)  # checks the arguments
    f = load(path)
    name = f"{end}_{sense}_{arms}"
    floor = _multilinear(f[f"margin_{column}_{name}"], [_axis(np.asarray(theta, float), f["theta"])])
    return floor + float(np.ravel(f[f"beta_h_{name}"])[0]) * spread if column == "h" else floor  # stored 1-d


def gap_ratio_min(
    theta,
    r_in_over_p,
    turns,
    end: str = "clamped",
    sense: str = "tighten",
    arms: int = 1,
    margin: bool = True,
    path=None,
):
    """h: min over 0 ≤ θ' ≤ θ of the smallest centreline distance between coils / p (≥ 0).

    Coil gap = p·h − t. ``margin``: lowered by the error the generator measured (conservative).
    """
    h, spread = gap_lookup(theta, r_in_over_p, turns, end, sense, arms, path)
    if margin:
        h = h - error_margin("h", theta, end, sense, arms, path, spread)
    return np.maximum(h, 0.0)


def hub_ratio_min(
    theta,
    r_in_over_p,
    turns,
    end: str = "clamped",
    sense: str = "tighten",
    arms: int = 1,
    margin: bool = True,
    path=None,
):
    """q: min over 0 ≤ θ' ≤ θ of (smallest radius beyond the first quarter turn − r_in) / p.

    Pin gap = r_in − t/2 − r_pin + p·q. ``margin``: lowered by the measured worst error.
    """
    q = _lookup("q", end, sense, arms, path, r_in_over_p, turns, theta)
    if margin:
        q = q - error_margin("q", theta, end, sense, arms, path)
    return q


def stress_factor(
    r_in_over_p,
    turns,
    theta=None,
    end: str = "clamped",
    sense: str = "tighten",
    arms: int = 1,
    margin: bool = True,
    path=None,
):
    """m = max|M| / T of one arm: at small wind-up (``theta`` None) or the worst over 0 ≤ θ' ≤ θ.

    Peak stress = 6·m·T_arm/(b t²). ``margin``: raised by the measured worst error.
    """
    theta = 0.0 if theta is None else theta
    m = _lookup("m", end, sense, arms, path, r_in_over_p, turns, theta)
    if margin:
        m = m + error_margin("m", theta, end, sense, arms, path)
    return m


def torque_ratio(theta, r_in_over_p, turns, end: str = "clamped", sense: str = "tighten", arms: int = 1, path=None):
    """T(θ) / (K·θ): the torque at wind-up θ over the small-wind-up stiffness times θ (1 at θ → 0)."""
    return _lookup("tau", end, sense, arms, path, r_in_over_p, turns, theta)


def stiffness_ratio(r_in_over_p, turns, end: str = "clamped", arms: int = 1, path=None):
    """c = K_rod / (arms·E·b·t³/12L_arm) at small wind-up (the same in either sense)."""
    return _lookup("c", end, "tighten", arms, path, r_in_over_p, turns)


def coil_gap(theta, r_in, pitch, turns, t, **kw):
    """Smallest coil gap over 0 ≤ θ' ≤ θ [mm]: pitch·h − t (``kw`` as :func:`gap_ratio_min`)."""
    return np.asarray(pitch) * gap_ratio_min(theta, np.asarray(r_in) / np.asarray(pitch), turns, **kw) - t


def pin_gap(theta, r_in, pitch, turns, t, pin_radius, **kw):
    """Smallest gap between the strip and a pin of radius r_pin over 0 ≤ θ' ≤ θ [mm]."""
    q = hub_ratio_min(theta, np.asarray(r_in) / np.asarray(pitch), turns, **kw)
    return np.asarray(r_in) - np.asarray(t) / 2 - pin_radius + np.asarray(pitch) * q
