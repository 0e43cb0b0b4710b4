"""The life law rjcad designs with: Table I's model as a constraint of the spring optimiser.

Used by ``rjcad.spring.optimise`` (``--min-cycles``) and by every design's predicted life.
"""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np

from rjcad.life.likelihood import LEVEL, LifeModel, fit
from rjcad.life.table import LifeData, table_i

#: The model rjcad designs with: the critique's choice on Table I, its effects and whether its
#: chosen variant keeps the stress term (tests/test_life.py checks that critique() still chooses
#: exactly this, so a change of data or rule cannot leave the designer on a stale model).
DESIGN_EFFECTS: tuple[str, ...] = ("pin_backlash",)
DESIGN_STRESS_TERM = False
_CACHE: dict = {}


def life_model() -> LifeModel:
    """The design model: Table I refitted with DESIGN_EFFECTS, with its parameter covariance (cached)."""
    if "m" not in _CACHE:
        _CACHE["m"] = fit(table_i(), DESIGN_EFFECTS, stress=DESIGN_STRESS_TERM)
    return _CACHE["m"]


def remedy() -> str:
    """What to change when the life constraint binds (depends on the design model's terms)."""
    m = life_model()
    if not m.stress or m.params["m"] <= 1e-9:
        return (
            "lower --backlash or --min-cycles (the Table I life model has no stress effect, "
            "so no spring geometry raises it; see rjcad life)"
        )
    return "lower --backlash, the rotation or --min-cycles, or allow a wider spring (--width-max)"


def _query(amp, thickness, backlash) -> LifeData:
    amp = np.atleast_1d(np.asarray(amp, dtype=float))
    t = np.broadcast_to(np.asarray(thickness, dtype=float), amp.shape)
    bl = np.broadcast_to(np.asarray(backlash, dtype=float), amp.shape)
    return LifeData(amp, t, bl, np.ones_like(amp), np.zeros(amp.shape, dtype=bool))


def predict_cycles(stress_amp, thickness, backlash=0.25, level: float = LEVEL):
    """Median predicted cycles and the ``level`` prediction interval (arrays) for springs like Table I's."""
    m = life_model()
    d = _query(stress_amp, thickness, backlash)
    lo, hi = m.interval(d, level)
    return 10 ** m.mean_log10(d), 10**lo, 10**hi


def amplitude_limit(min_cycles: float, thickness, backlash=0.25, level: float = LEVEL):
    """Largest stress amplitude whose lower prediction bound reaches ``min_cycles`` [MPa], per thickness.

    Lower bound: a − m·u + c·x − z·√(s² + xᵀCx) ≥ log10 N_min with u = log10 σ_a; solved for u with
    the variance term updated by fixed-point iteration (the optimiser re-checks each design).
    0 when no amplitude reaches it, ∞ when every amplitude does (m = 0).
    """
    m = life_model()
    t = np.atleast_1d(np.asarray(thickness, dtype=float))
    z = NormalDist().inv_cdf(0.5 + level / 2)
    target = math.log10(min_cycles)
    beta, cov = m.beta(), m.cov
    assert cov is not None  # the design model is fitted with its covariance
    amp = np.full(t.shape, 5.0)
    for _ in range(4):
        d = _query(amp, t, backlash)
        X = m.design(d)
        sd = np.sqrt(m.params["s"] ** 2 + np.einsum("ij,jk,ik->i", X, cov, X))
        rest = X @ beta + m.params["m"] * np.log10(amp)  # everything but −m·u
        margin = rest - z * sd - target
        if m.params["m"] <= 1e-9:
            return np.where(margin >= 0, np.inf, 0.0)
        amp = np.clip(10 ** (margin / m.params["m"]), 1e-3, 1e4)
    return np.where(margin / m.params["m"] < -3, 0.0, amp)
