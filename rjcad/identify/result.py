"""The identification result as plain JSON (keys pinned by issue #7)."""

from __future__ import annotations

import math

import numpy as np

from rjcad.identify.catalogue import EFFECTS
from rjcad.identify.diagnose import diagnose
from rjcad.identify.propose import Extension, over_noise
from rjcad.identify.select import Identification
from rjcad.identify.structure import structure
from rjcad.identify.verdict import verdict_json


def _r(x, nd: int = 6):
    if x is None:
        return None
    x = float(x)
    if not math.isfinite(x):
        return None
    return float(f"{x:.{nd}g}")


def residuals(ident: Identification, values=None) -> list[np.ndarray]:
    """y − ŷ per experiment (full length, quantity units) for ``values`` (default: the final model)."""
    preds = ident.final_predictions if values is None else ident.predictions(values)
    return [p.exp.y - yh for p, yh in zip(ident.prepared, preds)]


def selection_json(ident: Identification, params: dict, names: dict) -> dict:
    """The keys a joint and a finger identification share: the effects and parameters kept, what the data cannot
    identify, the selection's steps and candidates, the gain and the held-out figures, the design and the rival
    sets (``names``: effect id → its name)."""
    return {
        "effects": list(ident.effects),
        "params": {k: _r(v) for k, v in params.items()},
        "param_ci95": {k: [_r(a), _r(b)] for k, (a, b) in ident.ci95.items() if k not in ident.not_identifiable},
        "not_identifiable": sorted(ident.not_identifiable),
        "not_identifiable_why": dict(sorted(ident.not_identifiable.items())),
        "fitted": list(ident.final.names),
        "steps": [
            {
                "step": i + 1,
                "effect": s.effect,
                "name": names[s.effect] if s.action != "swapped" else "simpler set",
                "cause": s.cause,
                "action": s.action,
                "delta_bic": _r(s.delta_bic),
                "heldout_rmse": _r(s.heldout_rmse),
                "relevance": _r(s.relevance),
                "rmse": [_r(x) for x in s.rmse],
                "gain": _r(s.gain),
                **({"replaces": s.replaces} if s.replaces else {}),
            }
            for i, s in enumerate(ident.steps)
        ],
        "candidates": [
            {"step": c.step, "effect": c.effect, "delta_bic": _r(c.delta_bic), "reason": c.reason, "verdict": c.verdict}
            for c in ident.candidates
        ],
        "gain": _r(ident.gain),
        "heldout_rmse_design": _r(ident.heldout_design),
        "heldout_rmse_final": _r(ident.heldout_final),
        "design": ident.campaign.design.as_json(),
        "ambiguous": [{**a, "delta_bic": _r(a["delta_bic"])} for a in ident.ambiguous],
    }


def to_json(ident: Identification, extension: Extension | None = None) -> dict:
    """effects, params, param_ci95, not_identifiable, steps, experiments, gain, and the evidence behind them.

    heldout_rmse is whitened: residuals on held-out whole cycles divided by each experiment's noise
    σ, pooled (1.0 = the noise floor). With an ``extension`` (rjcad.identify.propose.extend): ``proposed`` lists
    the terms outside the catalogue, the verdict keys and ``catalogue_only`` are the catalogue's alone on the data
    as measured, and the rest is fitted beside the proposed terms. Each experiment's ``residual_structure`` tests
    the catalogue's final residual on the data as measured (rjcad.identify.structure).
    """
    fin, des = ident.final, ident.design
    params = {"stiffness_nmm_per_rad": fin.values["stiffness_nmm_per_rad"], "preload_deg": fin.values["preload_deg"]}
    for eff in ident.effects:
        for n in EFFECTS[eff].param_names:
            params[n] = fin.values[n]
    for n in ident.not_identifiable:  # reported, not fitted arbitrarily
        if n in fin.names:
            params.pop(n, None)
    r_design = [p.exp.y - yh for p, yh in zip(ident.prepared, ident.design_predictions)]
    r_final = residuals(ident)
    cat = ident if extension is None else extension.catalogue  # the catalogue's answer on the data as measured
    structures = [_clean(structure(p, p.exp.y - yh, yh)) for p, yh in zip(cat.prepared, cat.final_predictions)]
    exps = []
    for p, rmse_d, rmse_f, rd, rf, struct in zip(ident.prepared, des.rmse(), fin.rmse(), r_design, r_final, structures):
        e = p.exp
        exps.append(
            {
                "file": e.file,
                "quantity": e.quantity,
                "drive": e.drive,
                "normal_load_n": e.normal_load,
                "routed": e.routed,
                "samples": len(e.t),
                "samples_fitted": int(p.valid.sum()),
                "samples_masked_at_reversals": _n(p.motion.at_reversal),
                "masked_fraction_at_reversals": _r(_n(p.motion.at_reversal) / max(len(e.t), 1), 3),
                "outliers_angle": _n(p.motion.glitches),
                "outliers_quantity": _n(p.outliers),
                "cycles": p.motion.n_cycles,
                "reversals": len(p.motion.reversals),
                "rows_dropped": dict(e.dropped),
                "rmse_design": _r(rmse_d),
                "rmse_final": _r(rmse_f),
                "noise": _r(p.sigma),
                "final_over_noise": _r(rmse_f / p.sigma),
                "range": _r(p.span),
                "diagnostics_design": _clean(diagnose(p, rd)),
                "diagnostics_final": _clean(diagnose(p, rf)),
                "residual_structure": struct,
            }
        )
    names = {e: EFFECTS[e].name for e in EFFECTS}
    over = {e["file"]: e["final_over_noise"] for e in exps}
    notes = []
    if extension is not None:
        cat = extension.catalogue
        over = {k: _r(v) for k, v in over_noise(cat).items()}
        notes.append(
            "The catalogue alone leaves a residual that a term outside it explains (proposed): the effects, "
            "parameters and experiments' final RMSE above are fitted beside that term."
        )
    return {
        **selection_json(ident, params, names),
        **verdict_json(over, ident.effects),
        "proposed": [] if extension is None else _clean(extension.json()),
        "catalogue_only": None
        if extension is None
        else {"effects": list(extension.catalogue.effects), "final_over_noise": over},
        "experiments": exps,
        "notes": list(ident.campaign.notes) + _outlier_notes(ident) + list(ident.notes) + notes,
        "units": {
            "heldout_rmse": "residual / noise σ, pooled over held-out whole cycles (1 = noise floor)",
            "rmse": "the experiment's quantity (torque_nmm: N·mm, tendon_force_n: N)",
            "relevance": "max |Δprediction| / measured range",
        },
    }


def _outlier_notes(ident: Identification) -> list[str]:
    out = []
    for p in ident.prepared:
        a, q = _n(p.motion.glitches), _n(p.outliers)
        if a or q:
            out.append(
                f"{p.exp.file}: {a} angle outlier(s) replaced by the running median, "
                f"{q} spike(s) in {p.exp.quantity} left out (|x − median of 5| > 8σ)"
            )
    return out


def _n(mask) -> int:
    return 0 if mask is None else int(np.sum(mask))


def _clean(d):
    if isinstance(d, dict):
        return {k: _clean(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [_clean(v) for v in d]
    if isinstance(d, (float, np.floating)):
        return _r(d)
    return d
