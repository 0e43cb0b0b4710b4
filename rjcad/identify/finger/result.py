"""The JSON and the report of a whole-finger identification: the joint result's top-level keys, with the
experiments' figures per measured quantity (each joint's angle, the tension) and a verdict per joint."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from rjcad.identify.formatting import fmt
from rjcad.identify.report import proposed_section, structure_line
from rjcad.identify.result import _clean, _r, selection_json
from rjcad.identify.select import Identification
from rjcad.identify.structure import structure
from rjcad.identify.verdict import verdict_json, verdict_sentences

if TYPE_CHECKING:
    from rjcad.identify.finger.catalogue import FingerEffect
    from rjcad.identify.finger.data import FingerCampaign
    from rjcad.identify.finger.problem import Channel
    from rjcad.identify.propose import Extension
    from rjcad.physics.finger import FingerModel


# A finger identification is the joint pipeline's Identification, whose annotations name the joint's Campaign and
# Prepared: its campaign is a FingerCampaign and its prepared series are Channels (FingerSelector).
def _channels(ident: Identification) -> list[Channel]:
    return cast("list[Channel]", ident.prepared)


def _model(ident: Identification) -> FingerModel:
    return cast("FingerCampaign", ident.campaign).design.model


def _per_exp(ident: Identification, fits: tuple[list[float], list[float]]) -> list[dict[str, Any]]:
    out: dict[int, dict[str, Any]] = {}
    for ch, rd, rf in zip(_channels(ident), *fits):
        e = out.setdefault(
            ch.exp_index,
            {
                "file": ch.exp.file,
                "drive": "finger",
                "orientation": ch.exp.orientation,
                "samples": len(ch.exp.t),
                "cycles": ch.motion.n_cycles,
                "quantities": [],
                "rmse_design": {},
                "rmse_final": {},
                "noise": {},
                "final_over_noise": {},
                "samples_fitted": {},
            },
        )
        q = ch.quantity
        e["quantities"].append(q)
        e["rmse_design"][q], e["rmse_final"][q], e["noise"][q] = _r(rd), _r(rf), _r(ch.sigma)
        e["final_over_noise"][q] = _r(rf / ch.sigma)
        e["samples_fitted"][q] = int(ch.valid.sum())
    return [out[k] for k in sorted(out)]


def _structures(ident: Identification) -> dict[tuple[int, str], list[dict]]:
    """Per (experiment, quantity): the tests of the final residual's structure (rjcad.identify.structure), the
    motion's coordinate being the tendon's path."""
    out = {}
    for ch, yh in zip(_channels(ident), ident.final_predictions):
        tests = structure(cast("Any", ch), ch.y - yh, yh, t=ch.exp.t[ch.kept])
        for test in tests:
            test["words"] = test["words"].replace("angle", "tendon path")
        out[(ch.exp_index, ch.quantity)] = _clean(tests)
    return out


def _joints(ident: Identification) -> list[dict[str, Any]]:
    """Per joint: the design model's largest and RMS angle error, the final RMSE, and the effects acting on it."""
    n = _model(ident).n
    des, fin = ident.design_predictions, ident.final_predictions
    out = []
    for j in range(n):
        chans = [(k, ch) for k, ch in enumerate(_channels(ident)) if ch.index == j]
        where: tuple[str, float] | None = None
        worst, sq, cnt, sqf = 0.0, 0.0, 0, 0.0
        for k, ch in chans:
            err = (des[k] - ch.y)[ch.valid]
            if len(err):
                i = int(np.argmax(np.abs(err)))
                if abs(err[i]) > abs(worst):
                    worst, where = float(err[i]), (ch.exp.file, float(ch.path[ch.valid][i]))
                sq += float(np.sum(err**2))
                sqf += float(np.sum((fin[k] - ch.y)[ch.valid] ** 2))
                cnt += len(err)
        moved: dict[str, tuple[float, float]] = {}
        for name in ident.final.names:
            if name.endswith(f"_j{j + 1}"):
                moved[name] = (ident.design.values[name], ident.final.values[name])
        out.append(
            {
                "joint": j + 1,
                "design_worst_error_deg": _r(worst),
                "design_worst_at": {"file": where[0], "tendon_mm": _r(where[1])} if where else None,
                "rmse_design_deg": _r(np.sqrt(sq / max(cnt, 1))),
                "rmse_final_deg": _r(np.sqrt(sqf / max(cnt, 1))),
                "own_parameters": {k: {"design": _r(a), "final": _r(b)} for k, (a, b) in moved.items()},
            }
        )
    return out


def _over_noise(ident: Identification) -> dict[str, float | None]:
    """{"file: quantity": final RMSE / noise σ} of every channel."""
    return {f"{ch.exp.file}: {ch.quantity}": _r(r / ch.sigma) for ch, r in zip(_channels(ident), ident.final.rmse())}


def to_json(ident: Identification, extension: Extension | None = None) -> dict[str, Any]:
    """effects, params, not_identifiable, experiments (per quantity), gain, ambiguous, joints, steps, candidates.

    With an ``extension`` (rjcad.identify.propose.extend with the finger's basis): ``proposed`` lists the terms
    outside the catalogue, the verdict keys and ``catalogue_only`` are the catalogue's alone on the data as
    measured, and the rest is fitted beside the proposed terms."""
    fin, des = ident.final, ident.design
    params = {n: fin.values[n] for n in fin.names if n not in ident.not_identifiable}
    rd = des.rmse()
    rf = fin.rmse()
    names = {e.id: e.name for e in _catalogue(ident)}
    exps = _per_exp(ident, (rd, rf))
    cat = ident if extension is None else extension.catalogue  # the catalogue's answer on the data as measured
    over = _over_noise(cat)
    structures = _structures(cat)
    for k, e in enumerate(exps):
        e["residual_structure"] = {q: structures[(k, q)] for q in e["quantities"]}
    notes = []
    if extension is not None:
        notes.append(
            "The catalogue alone leaves a residual that a term outside it explains (proposed): the effects, "
            "parameters and channels' final RMSE above are fitted beside that term."
        )
    return {
        "kind": "finger",
        **selection_json(ident, params, names),
        **verdict_json(over, ident.effects),
        "proposed": [] if extension is None else _clean(extension.json()),
        "catalogue_only": None
        if extension is None
        else {"effects": list(extension.catalogue.effects), "final_over_noise": over},
        "experiments": exps,
        "joints": _joints(ident),
        "notes": list(ident.campaign.notes) + list(ident.notes) + notes,
        "units": {
            "rmse": "each quantity's unit (theta*_deg: deg, tendon_force_n: N)",
            "heldout_rmse": "residual / noise σ, pooled over held-out whole cycles (1 = noise floor)",
        },
    }


def _catalogue(ident: Identification) -> tuple[FingerEffect, ...]:
    from rjcad.identify.finger.catalogue import catalogue

    return catalogue(_model(ident))


def joint_sentences(js: dict[str, Any]) -> list[str]:
    """Which joint the design model gets wrong, by how much, and what explains it (one line per joint)."""
    out = []
    for j in js["joints"]:
        w = j["design_worst_error_deg"] or 0.0
        at = j["design_worst_at"]
        line = (
            f"joint {j['joint']}: the design model is up to {abs(w):.1f}° too {'closed' if w > 0 else 'open'}"
            + (f" ({at['file']}, tendon at {at['tendon_mm']:.1f} mm)" if at else "")
            + f"; RMSE {fmt(j['rmse_design_deg'], 3)}° → {fmt(j['rmse_final_deg'], 3)}°"
        )
        own = [
            f"{k} {fmt(v['design'], 3)} → {fmt(v['final'], 3)}"
            for k, v in j["own_parameters"].items()
            if k in js["params"] and abs((v["final"] or 0) - (v["design"] or 0)) > 1e-9
        ]
        if own:
            line += "; its own parameters: " + ", ".join(own)
        out.append(line)
    return out


def render_markdown(js: dict[str, Any]) -> str:
    """report.md of a whole-finger identification."""
    cat = {c["effect"]: c for c in js["candidates"]}
    lines = [
        "# Identification report: whole finger",
        "",
        f"Finger: `{js['design']['finger']}`, {js['design']['joints']} joints; design model as designed "
        "(frictionless, inextensible tendon, no gravity).",
        "",
    ]
    if js["effects"]:
        lines += [
            "Found: " + ", ".join(f"`{e}`" for e in js["effects"]) + f" (RMSE shrinks {fmt(js['gain'], 3)}-fold, "
            "geometric mean over the measured quantities).",
            "",
        ]
    lines += [*verdict_sentences(js), ""] if verdict_sentences(js) else []
    if js.get("proposed"):
        lines += [*proposed_section(js)[1:], ""]
    lines += ["## Per joint", ""] + [f"- {s}" for s in joint_sentences(js)]
    if js["ambiguous"]:
        lines += [
            "",
            "## What the data cannot decide",
            "",
            "| other set | ΔBIC vs the answer | free parameters | only bounded | separate them by |",
            "|---|---|---|---|---|",
        ]
        lines += [
            f"| {', '.join(a['effects'])} | {fmt(a['delta_bic'], 3)} | {a['free_parameters']} | "
            f"{', '.join(a['only_bounded']) or 'none'} | {a['separate_by']} |"
            for a in js["ambiguous"]
        ]
    lines += ["", "## Parameters", "", "| parameter | value | 95 % interval |", "|---|---|---|"]
    for k, v in js["params"].items():
        ci = js["param_ci95"].get(k)
        lines.append(f"| {k} | {fmt(v)} | " + (f"{fmt(ci[0])} … {fmt(ci[1])}" if ci else "—") + " |")
    if js["not_identifiable"]:
        lines += ["", "## Not identifiable from this campaign", ""]
        lines += [f"- `{k}`: {why}" for k, why in js["not_identifiable_why"].items()]
    lines += [
        "",
        "## Experiments",
        "",
        "| file | quantity | RMSE design | RMSE final | noise σ | final / noise |",
        "|---|---|---|---|---|---|",
    ]
    for e in js["experiments"]:
        for q in e["quantities"]:
            lines.append(
                f"| {e['file']} | {q} | {fmt(e['rmse_design'][q])} | {fmt(e['rmse_final'][q])} | "
                f"{fmt(e['noise'][q], 3)} | {fmt(e['final_over_noise'][q], 3)} |"
            )
    tested = [(e["file"], q, t) for e in js["experiments"] for q, t in e.get("residual_structure", {}).items()]
    if tested:
        lines += ["", "What each channel's residual still follows (the tendon's path stands for the angle):", ""]
        lines += [f"- {f}, {q}: " + structure_line(t, bool(js.get("proposed")))[2:] for f, q, t in tested]
    rejected = [c for c in js["candidates"] if c["reason"] != "accepted"]
    if rejected:
        lines += ["", "## Candidates not accepted (last verdict)", ""]
        lines += [f"- `{k}`: {c['verdict']}" for k, c in cat.items() if c["reason"] != "accepted"]
    if js["notes"]:
        lines += ["", "## Notes", ""] + [f"- {n}" for n in js["notes"]]
    return "\n".join(lines) + "\n"


def write_report(js: dict[str, Any], out_dir: str | Path) -> list[Path]:
    from rjcad.io.outputs import write_set

    out = Path(out_dir)
    write_set(out, {"report.md": render_markdown(js)})
    return [out / "report.md"]
