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
from typing import Any

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

    def column(self, c: Any) -> np.ndarray:
        """The column from its building blocks (:class:`Columns` for a joint; a finger's are its own)."""
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


class Basis:
    """How a kind of campaign builds its terms' columns (a strategy): the joint's (:class:`JointBasis`) or the
    finger's (``rjcad.identify.finger.propose``). Every array is per prepared series and full length (the whole
    record); ``rows`` picks the samples the identification fits."""

    library: tuple[Term, ...] = ()

    def identify(self, campaign, progress) -> Identification:
        raise NotImplementedError

    def measured(self, ident: Identification) -> list[np.ndarray]:
        """Each series' measured data, full length."""
        raise NotImplementedError

    #: rounds of secant columns after the tangent fit (0: every term is linear in its coefficient)
    secant_rounds = 0

    def matrices(
        self, ident: Identification, values: dict[str, float], sizes: dict[int, float] | None = None
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """Per series: the prediction at ``values`` and the library's columns (samples × terms); the column of a
        term in ``sizes`` {index: coefficient} is its secant at that coefficient (y(c) − y(0))/c, else its
        tangent."""
        raise NotImplementedError

    def rows(self, p) -> np.ndarray:
        """Indices of the fitted samples of series ``p`` in its full record."""
        raise NotImplementedError

    def group(self, i: int, p) -> int:
        """The experiment series ``i`` (``p``) belongs to: its cycles are one block for the bootstrap."""
        return i

    def with_data(self, campaign, ident: Identification, data: list[np.ndarray]):
        """``campaign`` with each series' data replaced by ``data``."""
        raise NotImplementedError

    def words(self, term: Term, coef: float, ident: Identification) -> str:
        return term.words(coef, "N·mm", ident.final.values.get("stiffness_nmm_per_rad", 0.0))


class JointBasis(Basis):
    """The joint's terms (:data:`LIBRARY`), built from the spring's part of its prediction."""

    library = LIBRARY

    def identify(self, campaign, progress):
        return identify(campaign, progress)

    def measured(self, ident):
        return [p.exp.y for p in ident.prepared]

    def matrices(self, ident, values, sizes=None):
        spring = spring_only(ident.campaign, values)
        cols = [columns(p, values, spring) for p in ident.prepared]
        return [(c.prediction, np.column_stack([term.column(c) for term in self.library])) for c in cols]

    def rows(self, p):
        return np.flatnonzero(p.valid)

    def with_data(self, campaign, ident, data):
        return replace(campaign, experiments=tuple(replace(e, y=y) for e, y in zip(campaign.experiments, data)))


@dataclass
class _Pooled:
    X: np.ndarray  # whitened columns, valid samples of every experiment
    y: np.ndarray  # whitened residual
    fold: np.ndarray  # held-out fold (−1: always trained on)
    block: np.ndarray  # (experiment, cycle) block id, for the bootstrap


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


def _data(basis: Basis, ident: Identification, values=None, data=None, sizes=None) -> _Pooled:
    """The pooled regression of ``data`` (default: the measured data) minus ``ident``'s prediction at ``values``
    (default: its final), on the fitted samples of every series (``sizes``: see Basis.matrices)."""
    values = ident.final.values if values is None else values
    ys = basis.measured(ident) if data is None else data
    X, y, fold, block = [], [], [], []
    for i, (p, yi, (pred, cols)) in enumerate(zip(ident.prepared, ys, basis.matrices(ident, values, sizes))):
        rows, ok = basis.rows(p), p.valid
        X.append(cols[rows] / p.sigma)
        y.append((yi - pred)[rows] / p.sigma)
        fold.append(p.folds[ok])
        block.append(basis.group(i, p) * 100_000 + p.motion.cycle[ok])
    return _Pooled(np.vstack(X), np.concatenate(y), np.concatenate(fold), np.concatenate(block))


def _coefficients(d: _Pooled, chosen: list[int]) -> np.ndarray:
    """Least-squares coefficients of the chosen terms on all of ``d``'s samples."""
    return np.linalg.lstsq(d.X[:, chosen], d.y, rcond=None)[0]


def next_term(d: _Pooled, chosen: list[int]) -> int | None:
    """The library index of the term that, added to ``chosen``, lowers the held-out score most, if it removes at
    least MATERIAL of the held-out excess over the noise; else None (and None once the score is ≤ FLOOR_RATIO)."""
    h = _heldout(d, chosen)
    tried = {k: _heldout(d, [*chosen, k]) for k in range(d.X.shape[1]) if k not in chosen}
    if not tried or not math.isfinite(h) or h <= FLOOR_RATIO:  # explained to the floor: nothing left to propose
        return None
    k = min(tried, key=lambda j: (tried[j], j))
    return k if tried[k] < h and h**2 - tried[k] ** 2 >= MATERIAL * max(h**2 - 1.0, 0.0) else None


def solve(basis: Basis, ident: Identification, chosen: list[int], values=None, data=None):
    """(coefficients, sizes, pooled data) of the chosen terms on ``data`` minus ``ident``'s prediction at
    ``values``: a least-squares fit on the tangent columns, then ``basis.secant_rounds`` refits on the secant
    columns at the coefficients found (a term not linear in its coefficient, e.g. a finger's spring that is
    stiffer one way, is then fitted at its own size)."""
    sizes: dict[int, float] = {}
    d = _data(basis, ident, values, data)
    coef = _coefficients(d, chosen) if chosen else np.zeros(0)
    for _ in range(basis.secant_rounds if chosen else 0):
        sizes = dict(zip(chosen, map(float, coef)))
        d = _data(basis, ident, values, data, sizes)
        coef = _coefficients(d, chosen)
    return coef, sizes, d


def correction(
    basis: Basis, ident: Identification, chosen: list[int], coef: np.ndarray, values=None, sizes=None
) -> list[np.ndarray]:
    """Σ c·column of the chosen terms per series (full length, its units), at ``values`` (default: ``ident``'s
    final), each column the secant at ``sizes`` where given."""
    values = ident.final.values if values is None else values
    return [cols[:, chosen] @ coef for _, cols in basis.matrices(ident, values, sizes)]


def fitted(
    basis: Basis, ident: Identification, chosen: list[int], data=None, values=None
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(coefficients, their 95 % intervals (2, k), held-out RMSE without and with the terms) of the chosen terms on
    ``data`` (default: the measured data) minus ``ident``'s prediction at ``values`` (default: its final)."""
    coef, _, d = solve(basis, ident, chosen, values, data)
    return coef, _interval(d, chosen), _heldout(d, []), _heldout(d, chosen)  # without terms: the same residual


def terms_json(
    library: tuple[Term, ...], chosen: list[int], coef: np.ndarray, ci: np.ndarray, before: float, after: float, words
) -> list[dict]:
    """The ``proposed`` list of an identification's JSON: each term with its words (``words(term, c)``),
    coefficient and interval."""
    return [
        {
            "term": library[i].key,
            "expression": library[i].expression,
            "words": words(library[i], float(coef[j])),
            "coefficient": float(coef[j]),
            "ci95": [float(ci[0, j]), float(ci[1, j])],
            "unit": library[i].unit,
            "heldout_rmse_before": before,
            "heldout_rmse_after": after,
        }
        for j, i in enumerate(chosen)
    ]


def over_noise(ident) -> dict[str, float]:
    """{file: final RMSE / noise σ} of an identification (valid samples)."""
    return {p.exp.file: r / p.sigma for p, r in zip(ident.prepared, ident.final.rmse())}


def _explained(ident) -> bool:
    """Every series' final RMSE within FLOOR_RATIO of its noise."""
    return all(r / p.sigma <= FLOOR_RATIO for p, r in zip(ident.prepared, ident.final.rmse()))


@dataclass
class Extension:
    """The catalogue's answer on the data as measured (``catalogue``), and the terms proposed outside it: the
    ``chosen`` library indices with their coefficients, 95 % intervals and the held-out RMSE (whitened) of the
    catalogue alone (``before``) and of the catalogue refitted with the terms (``after``)."""

    catalogue: Identification
    chosen: list[int]
    coef: np.ndarray
    ci: np.ndarray
    before: float
    after: float
    #: the identification beside the terms (its words read its fitted values, e.g. a band's backlash 2·|c|/K)
    beside: Identification
    basis: Basis

    def json(self) -> list[dict]:
        words = lambda term, c: self.basis.words(term, c, self.beside)  # noqa: E731
        return terms_json(self.basis.library, self.chosen, self.coef, self.ci, self.before, self.after, words)


#: Rounds of identifying the answer again beside its terms while their correction to the data still moves by more
#: than POLISH_SIGMA (RMS over the fitted samples, in noise σ) in some series.
POLISH_ROUNDS, POLISH_SIGMA = 2, 0.1
#: A route whose terms alone (no catalogue effect) bring the held-out error to this is not bettered by 2 %: the
#: other route is not tried.
NOISE_TIE = 1.02


def _less(basis: Basis, campaign, ident: Identification, chosen: list[int], measured, progress, values=None):
    """Identify the campaign's data less the chosen terms, fitted on the residual of ``ident`` at ``values``."""
    coef, sizes, _ = solve(basis, ident, chosen, values, measured)
    less = [y - c for y, c in zip(measured, correction(basis, ident, chosen, coef, values, sizes))]
    return basis.identify(basis.with_data(campaign, ident, less), progress)


def _polish(basis: Basis, campaign, ident: Identification, chosen: list[int], measured, progress):
    """Identify again on the data less the terms fitted beside ``ident``'s answer, while that correction moves by
    more than POLISH_SIGMA from the one ``ident`` was identified on (POLISH_ROUNDS at most): a catalogue effect the
    terms were first fitted beside may have taken up part of a term, or changed its shape (alternating least
    squares)."""
    for _ in range(POLISH_ROUNDS):
        applied = [m - y for m, y in zip(measured, basis.measured(ident))]
        coef, sizes, _ = solve(basis, ident, chosen, None, measured)
        new = correction(basis, ident, chosen, coef, None, sizes)
        moved = max(
            float(np.sqrt(np.mean(((a - b) / p.sigma)[basis.rows(p)] ** 2)))
            for p, a, b in zip(ident.prepared, applied, new)
        )
        if moved <= POLISH_SIGMA:
            break
        ident = basis.identify(basis.with_data(campaign, ident, [m - c for m, c in zip(measured, new)]), progress)
    return ident


def _alternate(basis: Basis, campaign, ident: Identification, chosen: list[int], measured, progress):
    """Add terms one per round (:func:`next_term` on the measured data less ``ident``'s prediction), each round
    identifying again on the data less the terms: (identification, terms)."""
    while len(chosen) < MAX_TERMS:
        k = next_term(solve(basis, ident, chosen, data=measured)[2], chosen)
        if k is None:
            break
        chosen = [*chosen, k]
        ident = _less(basis, campaign, ident, chosen, measured, progress)
    return ident, chosen


def _score(basis: Basis, route, measured) -> float:
    """A route's held-out RMSE (whitened): its terms refitted on the measured data less its answer."""
    ident, chosen = route
    return _heldout(solve(basis, ident, chosen, data=measured)[2], chosen)


def extend(campaign, progress=None, basis: Basis | None = None):
    """Identify ``campaign``; where the catalogue leaves a residual, look for terms outside it by two routes and
    keep the one with the lower held-out error (within 2 %: the one with fewer effects and terms, then A):

    - A, from the catalogue's answer: add the library term that explains most of the residual left, identify
      again on the data less it (the catalogue effects reported are those still needed beside it), repeat;
    - B, from the design model: the term that explains most of the design residual first (a catalogue effect may
      have taken up part of a term's shape, e.g. a friction that grows with angle a stiffness that differs by
      direction), then the same rounds. B is tried first; where its one term alone brings the held-out error to
      NOISE_TIE, A is not tried (it could not be simpler, nor better by 2 %).

    The answer taken is identified again beside its terms until their correction settles (:func:`_polish`). Each
    term must remove ≥ MATERIAL of the held-out excess, and together they must bring the held-out error to
    FLOOR_RATIO or below (a library term that explains only part of the residual is not proposed). ``basis``: the
    joint's (default) or the finger's terms.

    Returns (identification, Extension or None). With an Extension, the identification's experiments hold the data
    less the proposed terms; its ``catalogue`` is the answer on the data as measured.
    """
    basis = JointBasis() if basis is None else basis
    first = basis.identify(campaign, progress)
    if _explained(first):
        return first, None
    measured = basis.measured(first)
    scored = []
    k = next_term(_data(basis, first, values=first.design.values, data=measured), [])
    if k is not None:  # even if route A begins with the same term: A keeps the catalogue effects it began with
        ident = _less(basis, campaign, first, [k], measured, progress, values=first.design.values)
        i, c = _alternate(basis, campaign, ident, [k], measured, progress)
        scored.append((_score(basis, (i, c), measured), len(i.effects) + len(c), 1, i, c))
    if not (scored and scored[0][0] <= NOISE_TIE and scored[0][1] == 1):
        i, c = _alternate(basis, campaign, first, [], measured, progress)
        scored.append((_score(basis, (i, c), measured), len(i.effects) + len(c), 0, i, c))
    best = min(scored, key=lambda r: r[0])
    near = [r for r in scored if r[0] <= best[0] * 1.02]
    _, _, _, ident, chosen = min(near, key=lambda r: (r[1], r[2]))
    if not chosen:
        return first, None
    ident = _polish(basis, campaign, ident, chosen, measured, progress)
    coef, ci, _, after = fitted(basis, ident, chosen, data=measured)
    before = _heldout(_data(basis, first), [])
    if not (after <= FLOOR_RATIO and before**2 - after**2 >= MATERIAL * (before**2 - 1.0)):
        return first, None  # the terms do not explain the data to the floor: nothing is proposed
    return ident, Extension(first, chosen, coef, ci, before, after, ident, basis)
