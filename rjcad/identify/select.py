"""Model selection over the effect catalogue: greedy forward steps, then a backward pass.

Forward: fit every remaining candidate jointly with the accepted effects; accept the best one
that is statistically supported (ΔBIC < −10 and a lower error on held-out whole cycles) and
practically relevant (it moves the prediction by > 1% of the measured range somewhere).
Backward: drop any accepted effect whose removal, the others refitted, costs ΔBIC ≤ 10.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from rjcad.identify.ambiguity import campaign_has
from rjcad.identify.ambiguity import find as rival_sets
from rjcad.identify.catalogue import CATALOGUE
from rjcad.identify.data import Campaign
from rjcad.identify.eiv import correct_viscous
from rjcad.identify.fit import (
    FitResult,
    Prepared,
    Problem,
    _jacobian,
    base_values,
    confidence,
    predict,
    prepare,
    unidentifiable,
)
from rjcad.progress import Progress, report

BIC_GATE = 10.0
RELEVANCE = 0.01


@dataclass
class Step:
    """One accepted (or, in the backward pass, dropped) effect."""

    effect: str
    cause: str
    #: "added" | "dropped" | "swapped" (to the simpler set the data cannot tell apart: ``effect``) | "replaced"
    #: (``effect`` in the place of ``replaces``, which fits better: the swap pass)
    action: str
    delta_bic: float  # BIC after the step − before (dropping an effect costs ≤ +10 by the rule)
    heldout_rmse: float | None  # whitened: 1.0 = noise floor
    relevance: float  # max |Δprediction| / measured range
    rmse: list[float]  # per experiment after the step, in its units
    gain: float  # geometric mean of rmse_design/rmse after the step
    replaces: str = ""  # the effect a "replaced" step took the place of


@dataclass
class Candidate:
    effect: str
    delta_bic: float | None
    verdict: str  # why it was accepted or not, in words
    step: int  # forward step number (1-based)
    reason: str = ""  # accepted | bic | relevance | heldout | not_identifiable | not_needed


@dataclass
class Identification:
    campaign: Campaign
    prepared: list[Prepared]
    design: FitResult
    final: FitResult
    effects: list[str]
    steps: list[Step]
    candidates: list[Candidate]
    not_identifiable: dict[str, str]
    ci95: dict[str, tuple[float, float]]
    heldout_design: float | None
    heldout_final: float | None
    notes: list[str] = field(default_factory=list)
    ambiguous: list[dict] = field(default_factory=list)  # rival effect sets the data cannot tell apart
    predictor: Callable[[dict[str, float], Prepared], np.ndarray] | None = None  # None: the joint model's

    def predictions(self, values=None) -> list[np.ndarray]:
        v = self.final.values if values is None else values
        f = self.predictor or predict
        return [f(v, p) for p in self.prepared]

    @cached_property
    def design_predictions(self) -> list[np.ndarray]:
        return self.predictions(self.design.values)

    @cached_property
    def final_predictions(self) -> list[np.ndarray]:
        return self.predictions(self.final.values)

    @property
    def gain(self) -> float:
        return _gain(self.design.rmse(), self.final.rmse())


def _gain(before, after) -> float:
    ratios = [b / a for b, a in zip(before, after) if a > 0 and b > 0]
    return float(math.exp(np.mean(np.log(ratios)))) if ratios else 1.0


class Selector:
    """State of one identification run."""

    def __init__(self, campaign: Campaign, prepared: list[Prepared] | None = None):
        self.campaign = campaign
        self.prepared = prepared if prepared is not None else self._prepare(campaign)
        self.design_json = self._design_json(campaign)
        self.base = self._base(campaign)
        self.prob = self.problem(self.base)
        self.frozen: dict[str, str] = {}  # parameters fixed at neutral: not identifiable
        # an effect whose input the campaign lacks altogether (the joint's geometry) is not a candidate
        self.catalogue = tuple(
            e
            for e in self.catalogue
            if getattr(e, "needs", "any") != "bearing" or campaign_has(self.prepared, "bearing")
        )
        self._lo: dict[str, float] = {}
        self._hi: dict[str, float] = {}
        for e in self.catalogue:
            lo, hi = e.bounds(self.design_json)
            self._lo.update(zip(e.param_names, lo))
            self._hi.update(zip(e.param_names, hi))
        self._fold_ids = sorted({int(f) for p in self.prepared for f in np.unique(p.folds) if f >= 0})

    # -- what a subclass for another kind of campaign replaces (rjcad.identify.finger) --------
    catalogue: tuple = CATALOGUE

    @property
    def effects(self) -> dict:
        return {e.id: e for e in self.catalogue}

    def _prepare(self, campaign) -> list:
        return prepare(campaign)

    def _base(self, campaign) -> dict[str, float]:
        return base_values(campaign)

    def _design_json(self, campaign) -> dict:
        return campaign.design.as_json()

    def problem(self, fixed: dict[str, float]) -> Problem:
        return Problem(self.campaign, self.prepared, fixed)

    def predict(self, values: dict[str, float], p) -> np.ndarray:
        return predict(values, p)

    def param_names(self, effects) -> tuple[str, ...]:
        return tuple(n for e in effects for n in self.effects[e].param_names)

    # -- fitting a set of effects ------------------------------------------------------------
    def free_names(self, effects, frozen=None) -> tuple[str, ...]:
        frozen = self.frozen if frozen is None else frozen
        return tuple(n for n in self.param_names(effects) if n not in frozen)

    def bounds(self, names):
        return [self._lo[n] for n in names], [self._hi[n] for n in names]

    def starts(self, effects, start: dict[str, float]) -> list[dict[str, float]]:
        """Start points: accepted parameters at ``start``; a new effect at each of its own start points."""
        s = dict(self.base)
        s.update(start)
        out = [s]
        for e in effects:
            eff = self.effects[e]
            if any(n not in start for n in eff.param_names):
                variants = eff.starts(self.design_json)
                out = [dict(o, **{k: v for k, v in var.items() if k not in start}) for o in out for var in variants]
        return out

    def check_identifiable(self, effects, start: dict[str, float]) -> dict[str, str]:
        """Structural check at the start point: parameters the campaign cannot determine."""
        names = self.free_names(effects)
        x0 = np.array([self.starts(effects, start)[0][n] for n in names])
        J = _jacobian(
            lambda x: np.concatenate(self.prob.residuals(self.prob.values(names, x))), x0, upper=self.bounds(names)[1]
        )
        return unidentifiable(J, names)

    def fit_set(self, effects, start: dict[str, float], masks=None, frozen=None) -> FitResult:
        names = self.free_names(effects, frozen)
        lo, hi = self.bounds(names)
        best: FitResult | None = None
        for s in self.starts(effects, start):
            prob = self.problem({**self.base, **{k: v for k, v in s.items() if k not in names}})
            fr = prob.fit(names, [s[n] for n in names], lo, hi, masks=masks)
            if best is None or fr.cost < best.cost:
                best = fr
        assert best is not None  # every effect has a start point
        return best

    def heldout(self, effects, start: dict[str, float]) -> float | None:
        """Whitened RMSE on held-out whole cycles: fit without fold f, predict fold f, pool all folds."""
        if not self._fold_ids:
            return None
        sq, n = 0.0, 0
        names = self.free_names(effects)
        for f in self._fold_ids:
            train = [p.valid & (p.folds != f) for p in self.prepared]
            test = [p.valid & (p.folds == f) for p in self.prepared]
            vals = self.fit_set(effects, start, masks=train).values if names else dict(self.base, **start)
            for r in self.prob.residuals(vals, test):
                sq += float(np.sum(r**2))
                n += len(r)
        return math.sqrt(sq / n) if n else None

    def relevance(self, a: dict[str, float], b: dict[str, float]) -> float:
        """max over experiments of max|ŷ_a − ŷ_b| / measured range, on valid samples."""
        rel = 0.0
        for p in self.prepared:
            d = np.abs(self.predict(a, p) - self.predict(b, p))[p.valid]
            if len(d):
                rel = max(rel, float(d.max()) / max(p.span, 1e-12))
        return rel

    def backward(self, accepted: list[str], current: FitResult, ho_cur, steps: list[Step], design: FitResult):
        """Drop, one at a time, the accepted effect whose removal (others refitted) costs the least, while ΔBIC ≤ 10.

        Mutates ``accepted`` and ``steps``; returns the new (fit, held-out RMSE).
        """
        while len(accepted) > 1:
            costs = []
            for e in accepted:
                rest = [a for a in accepted if a != e]
                keep = self.free_names(rest)
                fr = self.fit_set(rest, {n: current.values[n] for n in current.names if n in keep})
                costs.append((fr.bic - current.bic, e, fr))
            costs.sort(key=lambda x: x[0])
            cost, e, fr = costs[0]
            if cost > BIC_GATE:
                break
            accepted.remove(e)
            prev, current = current, fr
            ho_cur = self.heldout(accepted, {n: fr.values[n] for n in fr.names})
            steps.append(
                Step(
                    e,
                    self.effects[e].cause,
                    "dropped",
                    cost,
                    ho_cur,
                    self.relevance(prev.values, fr.values),
                    fr.rmse(),
                    _gain(design.rmse(), fr.rmse()),
                )
            )
        return current, ho_cur

    #: the refit's evaluations per side in post_check (a subclass with costlier evaluations may lower it)
    post_check_nfev = 60

    def post_check(self, fr: FitResult, rel: float = 0.2, gate: float = 4.0) -> dict[str, str]:
        """:meth:`profile_check`, remembered per fit (the ambiguity check and the final report ask twice)."""
        key = (fr.names, tuple(float(v) for v in fr.x), rel, gate)
        cache = self.__dict__.setdefault("_post_checks", {})
        if key not in cache:
            cache[key] = self.profile_check(fr, rel, gate)
        return cache[key]

    def profile_check(self, fr: FitResult, rel: float = 0.2, gate: float = 4.0) -> dict[str, str]:
        """Profile check of each fitted parameter: the data must pin it from both sides.

        The parameter is fixed at (1 ± ``rel``)·value and the others are refitted; a side whose
        whitened Δχ² stays below ``gate`` fits the data as well. Both sides flat: not identifiable
        (the others absorb it); one side flat: only a bound (e.g. γ⁻ ≥ K, a tendon slack in every
        release). A well-pinned parameter on a box bound is only noted.
        """
        out: dict[str, str] = {}
        if not fr.names:
            return out
        lo, hi = self.bounds(fr.names)
        chi0 = sum(float(np.sum(r**2)) for r in self.prob.residuals(fr.values))
        for n, a, b in zip(fr.names, lo, hi):
            v = fr.values[n]
            d = rel * max(abs(v), 1e-3)
            others = [m for m in fr.names if m != n]
            olo, ohi = self.bounds(others)
            dchi = {}
            for side, x in (("below", max(v - d, a)), ("above", min(v + d, b))):
                if abs(x - v) <= 1e-9 * max(abs(v), 1.0):
                    continue
                prob = self.problem({**self.base, **fr.values, n: x})
                if others:
                    chi = (
                        2.0
                        * prob.fit(others, [fr.values[m] for m in others], olo, ohi, max_nfev=self.post_check_nfev).cost
                    )
                else:
                    chi = sum(float(np.sum(r**2)) for r in prob.residuals(prob.fixed))
                dchi[side] = chi - chi0
            flat = [side for side, c in dchi.items() if c < gate]
            if dchi and len(flat) == len(dchi):
                out[n] = (
                    f"not identifiable: fixing it {100 * rel:g} % away from {v:.4g} and refitting the others "
                    f"fits as well (Δχ² < {gate:g})"
                )
            elif flat:
                out[n] = (
                    f"the data only bound it: values {flat[0]} {v:.4g} fit as well (a {100 * rel:g} % move "
                    f"that way changes χ² by < {gate:g}); what it acts on is out of reach there, "
                    f"e.g. a slack tendon"
                )
            elif v - a <= 1e-6 * max(abs(a), 1.0):
                out[n] = "at its lower bound"
            elif b - v <= 1e-6 * max(abs(b), 1.0):
                out[n] = "at its upper bound"
        return out

    #: candidate fits of a step run at once in this many threads (a subclass whose simulation releases the GIL
    #: may raise it; the fits are independent, so the result does not depend on it)
    workers = 1

    def _fit_candidates(self, jobs, start: dict[str, float]) -> list[FitResult]:
        """``fit_set`` of each (effects, parameters frozen for it) job, in ``workers`` threads."""

        def one(job):
            effs, bad = job
            return self.fit_set(effs, start, frozen={**self.frozen, **bad})

        if self.workers <= 1 or len(jobs) < 2:
            return [one(j) for j in jobs]
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(self.workers) as ex:
            return list(ex.map(one, jobs))

    @contextmanager
    def _freezing(self, extra: dict[str, str]):
        """Parameters ``extra`` held at neutral for the duration (one candidate's fits)."""
        kept = self.frozen
        self.frozen = {**kept, **extra}
        try:
            yield
        finally:
            self.frozen = kept

    def final_identifiability(self, accepted: list[str], current: FitResult):
        """What the final model cannot determine, judged in the final state (not at the step it was met).

        Parameters frozen when their effect was accepted are checked again with the final set (a
        confounding partner may have been dropped since); if that changes, the final set is refitted.
        Effects not accepted report the parameters this campaign could not identify at all.
        """
        acc = set(self.param_names(accepted))
        start = {n: current.values[n] for n in current.names}
        if any(n in acc for n in self.frozen):
            kept, self.frozen = self.frozen, {}
            now = self.check_identifiable(accepted, start)
            self.frozen = now
            if set(now) != {n for n in kept if n in acc}:
                current = self.fit_set(accepted, start)
        out = {n: r for n, r in self.frozen.items() if n in acc}
        start = {n: current.values[n] for n in current.names}
        for eff in self.catalogue:
            if eff.id not in accepted:
                bad = self.check_identifiable(accepted + [eff.id], start)
                out.update({n: r for n, r in bad.items() if n in eff.param_names})
        return current, out

    # -- the selection -----------------------------------------------------------------------
    #: ``rjcad.progress.Progress`` told each step (``identify(..., progress=)``), or None.
    progress: Progress | None = None

    def run(self) -> Identification:
        report(self.progress, "fitting the design model")
        design = self.prob.fit((), [], [], [])
        ho_design = self.heldout([], {})
        accepted: list[str] = []
        steps: list[Step] = []
        cands: list[Candidate] = []
        current, ho_cur = self._forward(design, ho_design, accepted, steps, cands)
        report(self.progress, "backward pass: dropping what is not needed")
        current, ho_cur = self.backward(accepted, current, ho_cur, steps, design)
        report(self.progress, "swap pass: effects that fit better in an accepted one's place")
        current, ho_cur = self.swap(accepted, current, ho_cur, steps, design, cands)
        report(self.progress, "rival effect sets and confidence intervals")
        return self._finish(design, ho_design, current, ho_cur, accepted, steps, cands)

    def _forward(self, design, ho_cur, accepted: list[str], steps: list[Step], cands: list[Candidate]):
        """Forward selection: at each step the candidate with the best ΔBIC that passes every gate is added
        (``accepted``, ``steps`` and ``cands`` grow in place); (the last fit, its held-out error)."""
        current = design
        step_no = 0
        while True:
            step_no += 1
            start = {n: current.values[n] for n in current.names}
            jobs, of = self._identifiable_candidates(accepted, start, step_no, cands)
            found = f" ({', '.join(accepted)} found)" if accepted else ""
            report(self.progress, f"forward step {step_no}: fitting {len(jobs)} candidate effects{found}")
            tried = [
                (fr.bic - current.bic, eff, fr, bad)
                for eff, (_, bad), fr in zip(of, jobs, self._fit_candidates(jobs, start))
            ]
            tried.sort(key=lambda x: x[0])
            chosen = self._choose(tried, current, ho_cur, accepted, step_no, cands)
            if chosen is None:
                return current, ho_cur
            d, eff, fr, ho, rel, bad = chosen
            accepted.append(eff.id)
            self.frozen.update(bad)
            current, ho_cur = fr, ho
            steps.append(Step(eff.id, eff.cause, "added", d, ho, rel, fr.rmse(), _gain(design.rmse(), fr.rmse())))

    def _identifiable_candidates(self, accepted: list[str], start, step_no: int, cands: list[Candidate]):
        """The fits to try at this step, ([(effects, parameters held)], [effect]); the effects this campaign
        cannot identify go to ``cands``."""
        jobs, of = [], []
        for eff in self.catalogue:
            if eff.id in accepted:
                continue
            effs = accepted + [eff.id]
            bad = {n: r for n, r in self.check_identifiable(effs, start).items() if n in eff.param_names}
            if not self.free_names([eff.id], {**self.frozen, **bad}):
                why = "not identifiable from this campaign: " + "; ".join(f"{n}: {r}" for n, r in bad.items())
                cands.append(Candidate(eff.id, None, why, step_no, "not_identifiable"))
                continue
            jobs.append((effs, bad))
            of.append(eff)
        return jobs, of

    def _choose(self, tried, current, ho_cur, accepted: list[str], step_no: int, cands: list[Candidate]):
        """The first of the ΔBIC-sorted ``tried`` that passes the BIC gate, relevance and the held-out error, as
        (ΔBIC, effect, fit, held-out error, relevance, held parameters), or None; every verdict goes to ``cands``."""
        chosen = None
        for d, eff, fr, bad in tried:
            if chosen is not None or d >= -BIC_GATE:
                why = "not needed" if chosen is not None else f"ΔBIC {d:+.1f} ≥ −{BIC_GATE:g}"
                cands.append(Candidate(eff.id, d, why, step_no, "not_needed" if chosen is not None else "bic"))
                continue
            rel = self.relevance(fr.values, current.values)
            if rel <= RELEVANCE:
                why = f"changes the prediction by only {100 * rel:.2f}% of the measured range"
                cands.append(Candidate(eff.id, d, why, step_no, "relevance"))
                continue
            with self._freezing(bad):
                ho = self.heldout(accepted + [eff.id], {n: fr.values[n] for n in fr.names})
            if ho is not None and ho_cur is not None and ho >= ho_cur:
                why = f"held-out error does not improve ({ho:.3g} ≥ {ho_cur:.3g})"
                cands.append(Candidate(eff.id, d, why, step_no, "heldout"))
                continue
            chosen = (d, eff, fr, ho, rel, bad)
            cands.append(Candidate(eff.id, d, "accepted", step_no, "accepted"))
        return chosen

    def _corrected(self, fr: FitResult) -> tuple[FitResult, str | None]:
        """``fr`` with its viscous coefficient corrected for the velocity's angle noise (rjcad.identify.eiv)."""
        return correct_viscous(fr, self.problem({**self.base, **fr.values}), *self.bounds(fr.names))

    def _nested_limits(self, design, current: FitResult, accepted: list[str], steps: list[Step]):
        """Each accepted effect with ``limits`` against the simpler set it reduces to there (a Maxwell arm with
        T_r → 0 is viscous damping with c = K_M·T_r; one with K_M → 0, or stiffening with k₃ → 0, is nothing):
        the simpler set is taken when, both corrected for the velocity's angle noise, it costs ΔBIC ≤ BIC_GATE.
        Returns (fit, effects, notes); each reduction is a "swapped" step."""
        notes: list[str] = []
        bic: float | None = None
        for eid in list(accepted):
            for lim in self.effects[eid].limits:
                if eid not in accepted:
                    break
                rest = [a for a in accepted if a != eid]
                if lim.simpler and lim.simpler not in rest:
                    rest.append(lim.simpler)
                keep = self.free_names(rest)
                start = {n: current.values[n] for n in current.names if n in keep} | lim.start(current.values)
                fr = self.fit_set(rest, start)
                if bic is None:  # the current set's, corrected likewise: once per set
                    bic = self._corrected(current)[0].bic
                cost = self._corrected(fr)[0].bic - bic
                if cost > BIC_GATE:
                    continue
                value = f"{lim.param} = {current.values[lim.param]:.4g}"
                steps.append(
                    self._swap_step(
                        design, current, rest, fr, f"{lim.words}: {value} fits no better than the limit", cost
                    )
                )
                notes.append(
                    f"{eid} reduced to {lim.simpler or 'nothing'} ({lim.words}; ΔBIC {cost:+.1f}, the data cannot tell "
                    f"{value} from its limit)"
                )
                accepted, current, bic = rest, fr, None
        return current, accepted, notes

    def swap(self, accepted: list[str], current: FitResult, ho_cur, steps: list[Step], design, cands):
        """Replace an accepted effect e by an effect f with fewer parameters, tried at e's forward step and
        supported there on its own (ΔBIC < −10), when the set with f in e's place fits better by more than the BIC
        gate (refitted): the forward pass is greedy, and an effect with more parameters can win a step by absorbing
        part of an effect not yet added (the best swap first, until none helps). Mutates ``accepted`` and
        ``steps``."""
        tried: set[frozenset[str]] = {frozenset(accepted)}
        for _ in range(len(self.catalogue)):
            best = None
            for e in accepted:
                at = [c.step for c in cands if c.effect == e and c.reason == "accepted"]
                size = len(self.effects[e].param_names)
                rivals = [
                    c.effect
                    for c in cands
                    if at
                    and c.step == at[-1]
                    and c.effect not in accepted
                    and (c.delta_bic or 0.0) < -BIC_GATE
                    and len(self.effects[c.effect].param_names) < size
                ]
                for f in rivals:
                    effs = [f if a == e else a for a in accepted]
                    if frozenset(effs) in tried:
                        continue
                    tried.add(frozenset(effs))
                    keep = set(self.free_names(effs))
                    fr = self.fit_set(effs, {n: current.values[n] for n in current.names if n in keep})
                    cost = fr.bic - current.bic
                    if cost < -BIC_GATE and (best is None or cost < best[0]):
                        best = (cost, e, f, effs, fr)
            if best is None:
                break
            cost, e, f, effs, fr = best
            ho_cur = self.heldout(effs, {n: fr.values[n] for n in fr.names})
            rel = self.relevance(current.values, fr.values)
            steps.append(
                Step(
                    f,
                    self.effects[f].cause,
                    "replaced",
                    cost,
                    ho_cur,
                    rel,
                    fr.rmse(),
                    _gain(design.rmse(), fr.rmse()),
                    e,
                )
            )
            accepted[:] = effs
            current = fr
        return current, ho_cur

    def _swap_step(self, design, current: FitResult, effects: list[str], fr: FitResult, cause: str, cost: float):
        """The "swapped" step from ``current`` to the simpler set ``effects`` fitted as ``fr`` (ΔBIC ``cost``)."""
        return Step(
            ", ".join(effects) or "design simulation",
            cause,
            "swapped",
            cost,
            self.heldout(list(effects), {n: fr.values[n] for n in fr.names}),
            self.relevance(current.values, fr.values),
            fr.rmse(),
            _gain(design.rmse(), fr.rmse()),
        )

    def _finish(self, design, ho_design, current, ho_cur, accepted, steps, cands) -> Identification:
        """The identification: the simplest set the data cannot tell from the selected one, the viscous
        correction, the final identifiability and the notes."""
        current, not_ident = self.final_identifiability(accepted, current)
        best, ambiguous = rival_sets(self, accepted, current, cands)
        notes = []
        if best.effects != accepted:
            notes.append(
                f"the data cannot tell {', '.join(accepted)} from {', '.join(best.effects)}: "
                f"the simpler set is kept (see ambiguous)"
            )
            cause = f"the data cannot tell {', '.join(accepted)} from it: the simpler set is kept"
            steps.append(self._swap_step(design, current, best.effects, best.fit, cause, best.fit.bic - current.bic))
            accepted = list(best.effects)
            current, not_ident = self.final_identifiability(accepted, best.fit)
        current, accepted, reduced = self._nested_limits(design, current, accepted, steps)
        notes += reduced
        if reduced:
            current, not_ident = self.final_identifiability(accepted, current)
            ho_cur = self.heldout(accepted, {n: current.values[n] for n in current.names})
        current, note = self._corrected(current)
        if note:
            notes.append(note)
        if not self._fold_ids:
            notes.append("no experiment has two whole cycles: the held-out check was skipped")
        for n, why in self.post_check(current).items():
            if why.startswith("at its"):
                notes.append(f"{n} = {current.values[n]:.4g} is {why}")
            else:
                not_ident.setdefault(n, why)
        return Identification(
            self.campaign,
            self.prepared,
            design,
            current,
            accepted,
            steps,
            cands,
            not_ident,
            confidence(current, self.prob),
            ho_design,
            ho_cur,
            notes,
            ambiguous,
            predictor=self.predict,
        )


def identify(campaign: Campaign, progress: Progress | None = None) -> Identification:
    """Find what the design simulation gets wrong, which effects explain it, and the gain; ``progress`` (a
    ``rjcad.progress.Progress``) is told each step.

    BLAS runs single-threaded: the fits are many small problems, and threaded OpenBLAS made
    them 9× slower on a busy 2-core machine (12.9 s against 1.4 s, same run).
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        selector = Selector(campaign)
        selector.progress = progress
        return selector.run()
