"""The critique of the stress-only law: each candidate cause fitted, compared by AICc and leave-one-out,
and a parametric bootstrap of how often the procedure reaches each answer."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rjcad.life.effects import EFFECTS
from rjcad.life.likelihood import LifeModel, fit, loo, profile_interval
from rjcad.life.table import LifeData, table_i, table_i_peaks

#: An extension is chosen when its AICc is lower than the stress-only law's AND it cuts the
#: leave-one-out error by at least this fraction.
LOO_CUT = 0.2


@dataclass
class Candidate:
    """One law as compared: its better variant, that variant's leave-one-out, and both variants."""

    model: LifeModel
    loo_rmse: float
    loo_err: np.ndarray
    loo_pred: np.ndarray
    variants: dict = field(default_factory=dict)  # stress term True/False → LifeModel
    variant_loo: dict = field(default_factory=dict)  # stress term True/False → LOO RMSE


@dataclass
class Critique:
    """The stress-only law, every candidate cause, the choice, and profile intervals on the data."""

    data: LifeData
    baseline: Candidate
    candidates: dict[str, Candidate]
    chosen: tuple[str, ...]
    intervals: dict = field(default_factory=dict)
    peaks: np.ndarray | None = None  # peak stress per row [MPa], when known

    @property
    def extended(self) -> LifeModel:
        return self.candidates[self.chosen[0]].model if self.chosen else self.baseline.model

    @property
    def extended_cand(self) -> Candidate:
        return self.candidates[self.chosen[0]] if self.chosen else self.baseline

    def akaike_weights(self) -> dict[str, float]:
        """Relative support of the stress-only law and each extension: exp(−ΔAICc/2), normalised."""
        a = {"stress_only": self.baseline.model.aicc}
        a.update({e: c.model.aicc for e, c in self.candidates.items()})
        lo = min(a.values())
        w = {k: math.exp(-(v - lo) / 2) for k, v in a.items()}
        tot = sum(w.values())
        return {k: v / tot for k, v in w.items()}

    def to_dict(self) -> dict:
        d = self.data
        b, x = self.baseline, self.extended_cand
        base_mu, ext_mu = b.model.mean_log10(d), x.model.mean_log10(d)
        rows = []
        for i in range(d.n):
            obs = math.log10(d.cycles[i])
            rows.append(
                {
                    "row": i + 1,
                    "stress_amp_mpa": float(d.stress_amp[i]),
                    "thickness_mm": float(d.thickness[i]),
                    "backlash_mm": float(d.backlash[i]),
                    "observed_cycles": float(d.cycles[i]),
                    "censored": bool(d.censored[i]),
                    "baseline_cycles": float(10 ** base_mu[i]),
                    "extended_cycles": float(10 ** ext_mu[i]),
                    "baseline_residual_log10": float(obs - base_mu[i]),
                    "extended_residual_log10": float(obs - ext_mu[i]),
                    "baseline_loo_error_log10": float(b.loo_err[i]),
                    "extended_loo_error_log10": float(x.loo_err[i]),
                }
            )
        if self.peaks is not None:
            for r, p in zip(rows, self.peaks):
                r["stress_peak_mpa"] = float(p)
        base_aicc = b.model.aicc
        return {
            "baseline": {
                "params": b.model.params,
                "stress_term": b.model.stress,
                "loo_rmse_log10": b.loo_rmse,
                "aicc": base_aicc,
                "variants": _variants(b),
                "intervals_95": self.intervals.get("stress_only", {}),
            },
            "extended": {
                "effects": list(self.chosen),
                "params": x.model.params,
                "stress_term": x.model.stress,
                "loo_rmse_log10": x.loo_rmse,
                "aicc": x.model.aicc,
                "causes": [EFFECTS[e].cause for e in self.chosen],
                "intervals_95": self.intervals.get(self.chosen[0], {})
                if self.chosen
                else self.intervals.get("stress_only", {}),
            },
            "candidates": {
                e: {
                    "params": c.model.params,
                    "stress_term": c.model.stress,
                    "loo_rmse_log10": c.loo_rmse,
                    "aicc": c.model.aicc,
                    "variants": _variants(c),
                    "delta_aicc": c.model.aicc - base_aicc,
                    "intervals_95": self.intervals.get(e, {}),
                }
                for e, c in self.candidates.items()
            },
            "gain": b.loo_rmse / x.loo_rmse if x.loo_rmse > 0 else math.inf,
            "akaike_weights": self.akaike_weights(),
            "rule": f"each law at the better AICc of its variants with and without the stress term; an effect "
            f"is chosen when its AICc is below the stress-only law's and it cuts the leave-one-out "
            f"RMSE by >= {LOO_CUT:.0%}; the lowest AICc wins",
            "rows": rows,
        }


def _candidate(d: LifeData, effects: tuple[str, ...]) -> Candidate:
    """Both variants of a law (with and without the stress term); the one with the lower AICc, and its LOO."""
    variants = {st: fit(d, effects, stress=st) for st in (True, False)}
    loos = {st: loo(d, effects, st) for st in (True, False)}
    st = min(variants, key=lambda v: (variants[v].aicc, not v))
    return Candidate(variants[st], *loos[st], variants, {v: loos[v][0] for v in loos})


def _variants(c: Candidate) -> dict:
    return {
        ("with_stress" if st else "without_stress"): {
            "params": m.params,
            "aicc": m.aicc,
            "loglik": m.loglik,
            "loo_rmse_log10": c.variant_loo[st],
        }
        for st, m in c.variants.items()
    }


def critique(d: LifeData | None = None, effects=tuple(EFFECTS), intervals: bool = True) -> Critique:
    """Fit the stress-only law and each one-effect extension; choose by AICc and leave-one-out.

    Every law comes in two variants, with the Basquin term and without it (m = 0, one parameter
    fewer); each is compared at its better AICc. An extension is chosen when its AICc is below the
    stress-only law's and its leave-one-out RMSE is at least LOO_CUT lower; the lowest AICc wins.
    """
    table = d is None
    d = table_i() if d is None else d
    b = _candidate(d, ())
    cands = {eff: _candidate(d, (eff,)) for eff in effects}
    ok = [eff for eff, c in cands.items() if c.model.aicc < b.model.aicc and c.loo_rmse <= (1 - LOO_CUT) * b.loo_rmse]
    chosen = (min(ok, key=lambda eff: cands[eff].model.aicc),) if ok else ()
    c = Critique(d, b, cands, chosen)
    if intervals:
        c.intervals["stress_only"] = {"m": profile_interval(d, (), "m", model=b.variants[True])}
        for eff, cand in cands.items():
            c.intervals[eff] = {
                "m": profile_interval(d, (eff,), "m", model=cand.variants[True]),
                EFFECTS[eff].param: profile_interval(d, (eff,), EFFECTS[eff].param, model=cand.model),
            }
    if table:
        c.peaks = table_i_peaks()
    return c


def simulate(model: LifeModel, d: LifeData, rng: np.random.Generator, runout: float) -> LifeData:
    """A table at ``d``'s design points drawn from ``model`` (lives above ``runout`` are run-outs)."""
    logn = model.mean_log10(d) + rng.normal(0.0, model.params["s"], d.n)
    cyc = 10**logn
    return LifeData(d.stress_amp, d.thickness, d.backlash, np.minimum(cyc, runout), cyc >= runout)


def selection_frequencies(c: Critique, n_sim: int = 200, seed: int = 0) -> dict[str, dict[str, float]]:
    """Parametric bootstrap at Table I's design points: for data drawn from each fitted model
    (stress-only and each extension), how often the critique chooses each answer."""
    rng = np.random.default_rng(seed)
    runout = float(np.max(c.data.cycles[c.data.censored])) if c.data.censored.any() else math.inf
    gens = {"stress_only": c.baseline.model, **{e: cand.model for e, cand in c.candidates.items()}}
    out = {}
    for g, model in gens.items():
        counts = dict.fromkeys(gens, 0)
        for _ in range(n_sim):
            sim = simulate(model, c.data, rng, runout)
            if sim.censored.sum() >= sim.n - 4:  # too few failures to fit a 4-parameter model
                counts["stress_only"] += 1
                continue
            ch = critique(sim, intervals=False).chosen
            counts[ch[0] if ch else "stress_only"] += 1
        out[g] = {k: v / n_sim for k, v in counts.items()}
    return out
