"""A term outside the catalogue that the final residual asks for, proposed apart from the accepted effects.

The final residual of every experiment, whitened by its noise σ, is regressed on a small library of candidate
terms (:data:`LIBRARY`), pooled over the experiments. Terms are added greedily by their held-out score: each set
is fitted on the training cycles and scored on the held-out cycles (the identification's folds). A term is kept
only if it removes at least MATERIAL of the held-out excess over the noise, h² − 1 (h: held-out RMSE / σ; 1 is
the noise floor). Its coefficient's 95 % interval comes from a bootstrap over whole cycles (samples within a
cycle are not independent). Nothing is proposed when the residual is explained (``verdict.FLOOR_RATIO``), nor
when the terms found do not bring it to that floor. :func:`extend` identifies the campaign again on the data
less the terms, so that the catalogue effects reported are those still needed beside them.

Stiffness-relative terms use the spring's part of the prediction, s = the design model with the fitted
stiffness and preload and no other effect (N·mm for a torque, N for a tendon), so that their coefficient is a
fraction of the stiffness. τ = t/T − ½ over each experiment (T its duration); d = ±1 the direction of motion. A
backlash is a family of terms, one per play width, each the play operator's shape with its amplitude fitted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from rjcad.identify.fit import Prepared, base_values, predict
from rjcad.identify.select import Identification, identify
from rjcad.identify.verdict import FLOOR_RATIO

#: Least share of the held-out excess over the noise (h² − 1) a term must remove to be proposed. With the
#: residual at h ≈ 3 (excess 8) a term must bring it to h ≤ 2.75; a fit to noise alone removes ~1/n of it.
MATERIAL = 0.2
#: At most this many terms in a proposal.
MAX_TERMS = 2
#: Bootstrap resamples of whole cycles for the coefficients' 95 % intervals.
BOOTSTRAP = 200


@dataclass(frozen=True)
class Columns:
    """What a term's column is built from, per experiment (all samples): τ, d, θ [rad], the spring's part s, the
    prediction ŷ, t [s], ``unit``: 1 for a torque, 1/pulley radius for a tension (so that a coefficient in
    quantity units is N·mm at the joint for both), and ``slope``: the fitted stiffness in the quantity's units per
    rad (K·unit)."""

    tau: np.ndarray
    direction: np.ndarray
    theta: np.ndarray
    spring: np.ndarray
    prediction: np.ndarray
    t: np.ndarray
    unit: float
    slope: float


class Term:
    """One candidate term: ``column`` (quantity units per unit of coefficient) and ``words`` for a coefficient."""

    key = ""
    expression = ""
    unit = ""

    def column(self, c: Columns) -> np.ndarray:
        raise NotImplementedError

    def words(self, coef: float, q: str, k: float) -> str:
        """The term in words for coefficient ``coef`` (``q``: the quantity unit, ``k``: the fitted stiffness)."""
        raise NotImplementedError


class StiffnessDrift(Term):
    key, expression, unit = "stiffness_drift", "c·s·τ", "fraction of the stiffness over the run"

    def column(self, c):
        return c.spring * c.tau

    def words(self, coef, q, k):
        return (
            f"a stiffness that drifts over each run: {-coef / 2:+.1%} at its start, {coef / 2:+.1%} at its end "
            f"({coef:+.1%} in all)"
        )


class DirectionStiffness(Term):
    key, expression, unit = "direction_stiffness", "c·s·d", "fraction of the stiffness, + while the angle grows"

    def column(self, c):
        return c.spring * c.direction

    def words(self, coef, q, k):
        return (
            f"a stiffness that differs by direction of motion: {coef:+.1%} while the angle grows, "
            f"{-coef:+.1%} while it falls"
        )


class OffsetDrift(Term):
    key, expression, unit = "offset_drift", "c·τ", "N·mm at the joint over the run"

    def column(self, c):
        return c.tau * c.unit

    def words(self, coef, q, k):
        return f"an offset that drifts over each run by {coef:+.3g} {q} (a zero that wanders, or warm-up)"


class Band(Term):
    key, expression, unit = "band", "c·d", "N·mm at the joint, half-width"

    def column(self, c):
        return c.direction * c.unit

    def words(self, coef, q, k):
        sense = "against" if coef < 0 else "with"
        return (
            f"a band of constant half-width {abs(coef):.3g} {q} {sense} the motion: a friction that does not depend "
            f"on the load, or a backlash of 2·|c|/K = {math.degrees(2 * abs(coef) / k):.3g}° between the spring "
            "and the measured angle (the samples at reversals, left out, would tell them apart)"
        )


class Cubic(Term):
    key, expression, unit = "cubic", "c·θ³", "N·mm at the joint per rad³"

    def column(self, c):
        return c.theta**3 * c.unit

    def words(self, coef, q, k):
        return f"a term growing with the cube of the angle ({coef:+.3g} {q}/rad³)"


class Lag(Term):
    key, expression, unit = "lag", "−c·dŷ/dt", "s"

    def column(self, c):
        return -np.gradient(c.prediction, c.t)

    def words(self, coef, q, k):
        return f"the measured quantity lagging the angle by {coef * 1e3:.3g} ms"


def play(theta: np.ndarray, width: float, start_direction: float) -> np.ndarray:
    """The angle seen through a backlash of ``width`` [rad] (a play operator on ``theta`` [rad])."""
    out = np.empty_like(theta)
    s, half = theta[0] - start_direction * width / 2, width / 2
    for i, x in enumerate(theta):
        s = min(max(s, x - half), x + half)
        out[i] = s
    return out


class Backlash(Term):
    """A play of ``width_deg`` between the spring and the measured angle: the spring follows only once the play is
    taken up, so after each reversal the load stays flat over the play; the coefficient is the half-play [rad]."""

    unit = "rad, half the play"

    def __init__(self, width_deg: float):
        self.width = math.radians(width_deg)
        self.key = f"backlash_{width_deg:g}deg"
        self.expression = f"c·K·(play(θ, {width_deg:g}°) − θ)/({width_deg:g}°/2)"

    def column(self, c):
        return c.slope * (play(c.theta, self.width, float(c.direction[0])) - c.theta) / (self.width / 2)

    def words(self, coef, q, k):
        return (
            f"a backlash of {math.degrees(2 * abs(coef)):.3g}° between the spring and the measured angle (the load "
            f"stays flat over it after each reversal; its shape there fits a {math.degrees(self.width):g}° play)"
        )


#: The candidate terms, in the order a tie is broken.
LIBRARY: tuple[Term, ...] = (
    StiffnessDrift(),
    DirectionStiffness(),
    OffsetDrift(),
    Band(),
    Cubic(),
    Lag(),
    *(Backlash(w) for w in (1.0, 2.0, 4.0, 8.0, 16.0)),
)


def columns(p: Prepared, values: dict[str, float], spring_values: dict[str, float]) -> Columns:
    """The building blocks of every term for one experiment (``spring_values``: the spring-only model's)."""
    t = p.exp.t
    T = float(t[-1] - t[0]) or 1.0
    return Columns(
        tau=(t - t[0]) / T - 0.5,
        direction=p.motion.direction.astype(float),
        theta=p.motion.theta,
        spring=predict(spring_values, p),
        prediction=predict(values, p),
        t=t,
        unit=(unit := 1.0 if p.exp.quantity == "torque_nmm" else 1.0 / p.exp.pulley_radius),
        slope=values["stiffness_nmm_per_rad"] * unit,
    )


def spring_only(campaign, values: dict[str, float]) -> dict[str, float]:
    """The design model's values with the fitted stiffness and preload and every effect neutral."""
    return {**base_values(campaign), **{k: values[k] for k in ("stiffness_nmm_per_rad", "preload_deg")}}


@dataclass
class _Pooled:
    X: np.ndarray  # whitened columns, valid samples of every experiment
    y: np.ndarray  # whitened residual
    fold: np.ndarray  # held-out fold (−1: always trained on)
    block: np.ndarray  # (experiment, cycle) block id, for the bootstrap


def _pooled(prepared: list[Prepared], residuals: list[np.ndarray], cols: list[Columns]) -> _Pooled:
    X, y, fold, block = [], [], [], []
    for i, (p, r, c) in enumerate(zip(prepared, residuals, cols)):
        ok = p.valid
        X.append(np.column_stack([term.column(c)[ok] for term in LIBRARY]) / p.sigma)
        y.append(r[ok] / p.sigma)
        fold.append(p.folds[ok])
        block.append(i * 100_000 + p.motion.cycle[ok])
    return _Pooled(np.vstack(X), np.concatenate(y), np.concatenate(fold), np.concatenate(block))


def _heldout(d: _Pooled, cols: list[int]) -> float:
    """Pooled held-out RMSE (whitened) of a least-squares fit of ``cols`` on the other folds."""
    folds = [f for f in np.unique(d.fold) if f >= 0]
    if not folds:
        return math.inf
    sq, n = 0.0, 0
    for f in folds:
        test, train = d.fold == f, d.fold != f
        pred = 0.0
        if cols:
            coef, *_ = np.linalg.lstsq(d.X[train][:, cols], d.y[train], rcond=None)
            pred = d.X[test][:, cols] @ coef
        sq += float(np.sum((d.y[test] - pred) ** 2))
        n += int(test.sum())
    return math.sqrt(sq / max(n, 1))


def _interval(d: _Pooled, cols: list[int], seed: int = 0) -> np.ndarray:
    """95 % intervals (2, k) of the coefficients from a bootstrap over whole (experiment, cycle) blocks."""
    ids, inverse = np.unique(d.block, return_inverse=True)
    members = [np.flatnonzero(inverse == k) for k in range(len(ids))]
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(BOOTSTRAP):
        pick = np.concatenate([members[k] for k in rng.integers(0, len(ids), len(ids))])
        coef, *_ = np.linalg.lstsq(d.X[pick][:, cols], d.y[pick], rcond=None)
        draws.append(coef)
    return np.percentile(np.array(draws), [2.5, 97.5], axis=0)


def _columns(ident: Identification, values: dict[str, float] | None) -> list[Columns]:
    """:func:`columns` of every experiment at ``values`` (default: ``ident``'s final)."""
    values = ident.final.values if values is None else values
    spring = spring_only(ident.campaign, values)
    return [columns(p, values, spring) for p in ident.prepared]


def _data(ident: Identification, values: dict[str, float] | None = None, data=None) -> _Pooled:
    """The pooled regression of ``data`` (default: each experiment's y) minus ``ident``'s prediction."""
    cols = _columns(ident, values)
    ys = [p.exp.y for p in ident.prepared] if data is None else data
    return _pooled(ident.prepared, [y - c.prediction for y, c in zip(ys, cols)], cols)


def _coefficients(d: _Pooled, chosen: list[int]) -> np.ndarray:
    """Least-squares coefficients of the chosen terms on all of ``d``'s samples."""
    return np.linalg.lstsq(d.X[:, chosen], d.y, rcond=None)[0]


def next_term(d: _Pooled, chosen: list[int]) -> int | None:
    """The LIBRARY index of the term that, added to ``chosen``, lowers the held-out score most, if it removes at
    least MATERIAL of the held-out excess over the noise; else None (and None once the score is ≤ FLOOR_RATIO)."""
    h = _heldout(d, chosen)
    tried = {k: _heldout(d, [*chosen, k]) for k in range(len(LIBRARY)) if k not in chosen}
    if not tried or not math.isfinite(h) or h <= FLOOR_RATIO:  # explained to the floor: nothing left to propose
        return None
    k = min(tried, key=lambda j: (tried[j], j))
    return k if tried[k] < h and h**2 - tried[k] ** 2 >= MATERIAL * max(h**2 - 1.0, 0.0) else None


def correction(ident: Identification, chosen: list[int], coef: np.ndarray, values=None) -> list[np.ndarray]:
    """Σ c·column of the chosen terms per experiment (full length, quantity units), at ``values`` (default:
    ``ident``'s final)."""
    return [
        sum((k * LIBRARY[j].column(c) for j, k in zip(chosen, coef)), np.zeros(len(c.t)))
        for c in _columns(ident, values)
    ]


def fitted(
    ident: Identification, chosen: list[int], data=None, values=None
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(coefficients, their 95 % intervals (2, k), held-out RMSE without and with the terms) of the chosen terms on
    ``data`` (default: each experiment's y) minus ``ident``'s prediction at ``values`` (default: its final)."""
    d = _data(ident, values=values, data=data)
    return _coefficients(d, chosen), _interval(d, chosen), _heldout(d, []), _heldout(d, chosen)


def terms_json(
    chosen: list[int], coef: np.ndarray, ci: np.ndarray, before: float, after: float, k: float
) -> list[dict]:
    """The ``proposed`` list of an identification's JSON: each term with its words, coefficient and interval."""
    return [
        {
            "term": LIBRARY[i].key,
            "expression": LIBRARY[i].expression,
            "words": LIBRARY[i].words(float(coef[j]), "N·mm", k),
            "coefficient": float(coef[j]),
            "ci95": [float(ci[0, j]), float(ci[1, j])],
            "unit": LIBRARY[i].unit,
            "heldout_rmse_before": before,
            "heldout_rmse_after": after,
        }
        for j, i in enumerate(chosen)
    ]


def over_noise(ident) -> dict[str, float]:
    """{file: final RMSE / noise σ} of an identification (valid samples)."""
    return {p.exp.file: r / p.sigma for p, r in zip(ident.prepared, ident.final.rmse())}


@dataclass
class Extension:
    """The catalogue's answer on the data as measured (``catalogue``), and the terms proposed outside it: the
    ``chosen`` LIBRARY indices with their coefficients, 95 % intervals and the held-out RMSE (whitened) of the
    catalogue alone (``before``) and of the catalogue refitted with the terms (``after``)."""

    catalogue: Identification
    chosen: list[int]
    coef: np.ndarray
    ci: np.ndarray
    before: float
    after: float

    #: the stiffness fitted beside the terms [N·mm/rad] (a band's backlash is 2·|c|/K)
    stiffness: float = 0.0

    def json(self) -> list[dict]:
        return terms_json(self.chosen, self.coef, self.ci, self.before, self.after, self.stiffness)


def _less(campaign, ident: Identification, chosen: list[int], measured, progress, values=None):
    """Identify the campaign's data less the chosen terms, fitted on the residual of ``ident`` at ``values``."""
    coef = _coefficients(_data(ident, values=values, data=measured), chosen)
    less = [y - c for y, c in zip(measured, correction(ident, chosen, coef, values=values))]
    exps = tuple(replace(e, y=y) for e, y in zip(campaign.experiments, less))
    return identify(replace(campaign, experiments=exps), progress)


def _alternate(campaign, ident: Identification, chosen: list[int], measured, progress):
    """Add terms one per round (:func:`next_term` on the measured data less ``ident``'s prediction), each round
    identifying again on the data less the terms: (identification, terms)."""
    while len(chosen) < MAX_TERMS:
        k = next_term(_data(ident, data=measured), chosen)
        if k is None:
            break
        chosen = [*chosen, k]
        ident = _less(campaign, ident, chosen, measured, progress)
    return ident, chosen


def extend(campaign, progress=None):
    """Identify ``campaign``; where the catalogue leaves a residual, look for terms outside it by two routes and
    keep the one with the lower held-out error (within 2 %: the one with fewer effects and terms, then the
    first):

    - from the catalogue's answer: add the LIBRARY term that explains most of the residual left, identify again on
      the data less it (the catalogue effects reported are those still needed beside it), repeat;
    - from the design model: the term that explains most of the design residual first (a catalogue effect may
      have taken up part of a term's shape, e.g. a friction that grows with angle a stiffness that differs by
      direction), then the same rounds.

    Each term must remove ≥ MATERIAL of the held-out excess, and together they must bring the held-out error to
    FLOOR_RATIO or below (a library term that explains only part of the residual is not proposed).

    Returns (identification, Extension or None). With an Extension, the identification's experiments hold the data
    less the proposed terms; its ``catalogue`` is the answer on the data as measured.
    """
    first = identify(campaign, progress)
    if not any(v > FLOOR_RATIO for v in over_noise(first).values()):
        return first, None
    measured = [e.y for e in campaign.experiments]
    routes = [_alternate(campaign, first, [], measured, progress)]
    k = next_term(_data(first, values=first.design.values, data=measured), [])
    if k is not None:  # even if route A began with the same term: A keeps the catalogue effects it began with
        ident = _less(campaign, first, [k], measured, progress, values=first.design.values)
        routes.append(_alternate(campaign, ident, [k], measured, progress))
    scored = [
        (_heldout(_data(i, data=measured), c), len(i.effects) + len(c), n, i, c) for n, (i, c) in enumerate(routes)
    ]
    best = min(scored, key=lambda r: r[0])
    near = [r for r in scored if r[0] <= best[0] * 1.02]
    _, _, _, ident, chosen = min(near, key=lambda r: (r[1], r[2]))
    if not chosen:
        return first, None
    coef, ci, _, after = fitted(ident, chosen, data=measured)
    before = _heldout(_data(first), [])
    if not (after <= FLOOR_RATIO and before**2 - after**2 >= MATERIAL * (before**2 - 1.0)):
        return first, None  # the terms do not explain the data to the floor: nothing is proposed
    return ident, Extension(first, chosen, coef, ci, before, after, ident.final.values["stiffness_nmm_per_rad"])
