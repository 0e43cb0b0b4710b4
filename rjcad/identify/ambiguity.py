"""When the data cannot decide: rival effect sets that explain a campaign as well as the answer.

A rival of an accepted effect e is an effect f tried at the step e was accepted whose fit came
within ``BIC_GATE`` of e's (|ΔBIC_f − ΔBIC_e| < 10), or, when the data only bound one of e's
parameters, any effect tried at that step that was itself supported (ΔBIC < −10). The rival set
(e replaced by f, refitted) is *ambiguous* with the answer when |BIC_rival − BIC_answer| < 10, or
when one of the two needs a parameter the data only bound and the other fits every experiment
within 10 % of the noise floor (final RMSE ≤ max(1.1·σ, 1.05·the answer's RMSE)).
Of the ambiguous sets the answer is the simplest: fewest free parameters, then none only bounded,
then the lower BIC. Each remaining set is reported with the experiment that would separate it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from rjcad.identify.catalogue import EFFECTS

if TYPE_CHECKING:
    from rjcad.identify.fit import FitResult

BIC_GATE = 10.0
RMSE_MARGIN = 1.1


@dataclass
class Rival:
    """An effect set and its fit; ``bounded``: parameters the data only bound (or cannot pin)."""

    effects: list[str]
    fit: FitResult
    bounded: list[str]
    replaces: str = ""
    by: str = ""

    @property
    def k(self) -> int:
        return len(self.fit.names)


def _bounded(sel, fr) -> list[str]:
    return sorted(n for n, why in sel.post_check(fr).items() if not why.startswith("at its"))


def campaign_has(prepared, need: str) -> bool:
    """Whether the campaign carries what an effect ``need``s (catalogue ``Effect.needs``)."""
    exps = [p.exp for p in prepared]
    if need == "holds":  # a hold after the joint has moved (a hold before any motion shows no relaxation)
        for p in prepared:
            th = p.motion.theta
            moved = np.flatnonzero(np.abs(th - th[0]) > 0.1 * max(float(np.ptp(th)), 1e-12))
            if len(moved) and bool(p.motion.hold[moved[0] :].any()):
                return True
        return False
    if need == "speeds":
        peaks = []
        for p in prepared:
            for c in np.unique(p.motion.cycle):
                v = np.abs(p.motion.velocity[p.motion.cycle == c])
                if len(v):
                    peaks.append(float(v.max()))
        peaks = [x for x in peaks if x > 0]
        return bool(peaks) and max(peaks) >= 1.5 * min(peaks)
    if need == "routed":
        return any(e.routed for e in exps)
    if need == "tendon":
        return any(e.drive == "tendon" for e in exps)
    if need == "bearing":
        return any(e.drive == "tendon" and e.bearing is not None for e in exps)
    if need == "normal_load":
        return len({round(e.normal_load, 6) for e in exps}) > 1
    return True


def separating_experiment(a: str, b: str, prepared, values: dict, effects=EFFECTS) -> str:
    """In words, the experiment that would tell effect ``a`` from effect ``b`` apart."""
    tr = values.get("relaxation_time_s")
    texts = {
        "holds": (
            "holds at the top and bottom of a cycle, each at least 3·T_r long"
            + (f" (≥ {3 * tr:.2g} s with T_r = {tr:.2g} s)" if tr else "")
        ),
        "speeds": "the same cycle at a second speed (at least twice as fast or as slow)",
        "routed": "a tendon run routed through the base (capstan on the path)",
        "tendon": "a tendon-driven run",
        "bearing": "a tendon-driven run of a joint whose manifest the campaign names ([design] joint)",
        "normal_load": "runs at two different normal loads",
    }
    missing = [
        effects[e].needs for e in (a, b) if effects[e].needs in texts and not campaign_has(prepared, effects[e].needs)
    ]
    if missing:
        return "; ".join(dict.fromkeys(texts[m] for m in missing))
    return "more cycles or less noise (the campaign has what both need, but not enough of it)"


def _explains(sel, fr, ref) -> bool:
    """Every experiment fitted within RMSE_MARGIN of its noise (or 5 % of ``ref``'s RMSE)."""
    return all(r <= max(RMSE_MARGIN * p.sigma, 1.05 * r0) for r, r0, p in zip(fr.rmse(), ref.rmse(), sel.prepared))


def _rivals_of(sel, e: str, cands) -> list[tuple[str, bool]]:
    """(effect, within the BIC gate of e) for each effect tried beside e at its step that is a rival."""
    steps = [c.step for c in cands if c.effect == e and c.reason == "accepted"]
    if not steps:
        return []
    at = [c for c in cands if c.step == steps[-1] and c.delta_bic is not None]
    d_e = next(c.delta_bic for c in at if c.effect == e)
    return [
        (c.effect, abs(c.delta_bic - d_e) < BIC_GATE)
        for c in at
        if c.effect != e and (abs(c.delta_bic - d_e) < BIC_GATE or c.delta_bic < -BIC_GATE)
    ]


def find(sel, accepted: list[str], current, cands) -> tuple[Rival, list[dict]]:
    """The answer (the simplest of the ambiguous sets) and the others as ``ambiguous`` JSON entries."""
    answer = Rival(list(accepted), current, _bounded(sel, current))
    pool = [answer]
    start = {n: current.values[n] for n in current.names}
    for e in accepted:
        e_bounded = any(n in sel.effects[e].param_names for n in answer.bounded)
        for f, close_at_step in _rivals_of(sel, e, cands):
            if not (e_bounded or close_at_step):
                continue
            effs = [f if a == e else a for a in accepted]
            if any(set(effs) == set(r.effects) for r in pool) or len(set(effs)) < len(effs):
                continue
            keep = set(sel.free_names(effs))
            fr = sel.fit_set(effs, {n: v for n, v in start.items() if n in keep})
            rival = Rival(effs, fr, _bounded(sel, fr), replaces=e, by=f)
            close = abs(fr.bic - current.bic) < BIC_GATE
            if (
                close
                or (answer.bounded and not rival.bounded and _explains(sel, fr, current))
                or (rival.bounded and not answer.bounded and _explains(sel, current, fr))
            ):
                pool.append(rival)
    if len(pool) == 1:
        return answer, []
    best = min(pool, key=lambda r: (r.k, bool(r.bounded), r.fit.bic))
    out: list[dict[str, Any]] = []
    for r in pool:
        if r is best:
            continue
        a = sorted(set(r.effects) - set(best.effects))[0]
        b = sorted(set(best.effects) - set(r.effects))[0]
        out.append(
            {
                "effects": list(r.effects),
                "delta_bic": float(r.fit.bic - best.fit.bic),
                "free_parameters": r.k,
                "only_bounded": list(r.bounded),
                "separate_by": separating_experiment(
                    a, b, sel.prepared, {**best.fit.values, **r.fit.values}, sel.effects
                ),
            }
        )
    out.sort(key=lambda d: d["delta_bic"])
    return best, out
