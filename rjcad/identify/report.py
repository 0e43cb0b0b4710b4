"""The identification as a human-readable report: report.md plus fit.png, residuals.png and steps.png.

Numbers in the text come from the JSON (``to_json``) so the report and the JSON agree; the plots
(rjcad.identify.plots) need the samples and the motion analysis, so they come from the Identification.
Quantities are in their units (torque N·mm, tendon force N); held-out RMSE is whitened (1 = the noise floor).
"""

from __future__ import annotations

from pathlib import Path

from rjcad.identify.catalogue import EFFECTS, PARAMS
from rjcad.identify.formatting import QUANTITY, fmt, quantity_unit, unit_of
from rjcad.identify.plots import plot_diagnostics, plot_fit, plot_residuals, plot_steps
from rjcad.identify.select import BIC_GATE, Identification
from rjcad.identify.structure import P_FOUND, SIZE_FOUND
from rjcad.identify.verdict import FLOOR_RATIO, NOTHING_NEEDED, verdict_sentences
from rjcad.io.config import write_atomic
from rjcad.io.outputs import output_set

__all__ = [
    "FLOOR_RATIO",
    "QUANTITY",
    "fmt",
    "plot_diagnostics",
    "plot_fit",
    "plot_residuals",
    "plot_steps",
    "quantity_unit",
    "render_markdown",
    "unit_of",
    "write_report",
]


# ---------------------------------------------------------------- tables


def _cell(s) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ")


def _table(header: list[str], rows: list[list]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(_cell(c) for c in r) + " |" for r in rows]
    return out


def _short_cause(cause: str) -> str:
    """The cause's name: its wording up to the first colon."""
    return cause.split(":")[0].strip()


def _step_labels(steps: list[dict]) -> list[str]:
    """'1', '2', … for forward steps; 'B1', 'B2', … for effects dropped in the backward pass; 'S' for the swap to
    the simpler set."""
    out, f, b = [], 0, 0
    for s in steps:
        if s["action"] == "swapped":
            out.append("S")
        elif s["action"] == "replaced":
            out.append("R")
        elif s["action"] == "dropped":
            b += 1
            out.append(f"B{b}")
        else:
            f += 1
            out.append(str(f))
    return out


# ---------------------------------------------------------------- report.md


def _summary(js: dict) -> list[str]:
    d, exps = js["design"], js["experiments"]
    design = (
        f"K = {fmt(d['stiffness_nmm_per_rad'])} N·mm/rad, θ₀ = {fmt(d['preload_deg'])}°, "
        f"r = {fmt(d['pulley_radius_mm'])} mm"
    )
    worst = max(exps, key=lambda e: (e["rmse_design"] or 0) / (e["noise"] or 1))
    ratios = [(e["rmse_design"] or 0) / (e["noise"] or 1) for e in exps]
    q = quantity_unit(worst["quantity"])
    above = js["unexplained_over_noise"]
    out = []
    if not js["effects"] and not above:
        out.append(
            f"{NOTHING_NEEDED} The design simulation ({design}) gives RMSE / noise "
            f"{fmt(min(ratios), 3)}–{fmt(max(ratios), 3)} per experiment"
            + (f", held-out {fmt(js['heldout_rmse_design'], 3)}× noise" if js["heldout_rmse_design"] else "")
            + ". No catalogue effect improved it enough to be accepted."
        )
        return out
    data = "the measured data less the proposed term below" if js.get("proposed") else "the measured data"
    out.append(
        f"The design simulation ({design}) misses {data} by up to {fmt(max(ratios), 3)}× the "
        f"noise. The largest error is in experiment {worst['file']} ({fmt(worst['rmse_design'])} {q} RMSE "
        f"against {fmt(worst['noise'], 3)} {q} noise)."
    )
    if not js["effects"]:
        out += ["", "No catalogue effect improved the fit enough to be accepted (see the diagnostics below)."]
    else:
        out += ["", "Found:", ""]
        for i, eid in enumerate(js["effects"], 1):
            vals = "; ".join(_param_text(js, n) for n in EFFECTS[eid].param_names if n in js["param_ci95"])
            out.append(f"{i}. `{eid}` — {EFFECTS[eid].cause}." + (f" Fitted: {vals}." if vals else ""))
        out.append("")
        ho = ""
        if js["heldout_rmse_design"] is not None and js["heldout_rmse_final"] is not None:
            ho = (
                f"the error on held-out whole cycles falls from {fmt(js['heldout_rmse_design'], 3)}× to "
                f"{fmt(js['heldout_rmse_final'], 3)}× the noise floor, and "
            )
        out.append(
            f"With {'this effect' if len(js['effects']) == 1 else 'these effects'} {ho}the RMSE shrinks "
            f"{fmt(js['gain'], 3)}-fold (geometric mean over the experiments)."
        )
    if above:
        out += verdict_sentences(js)
        out += proposed_section(js)
    else:
        out.append(
            "The final residual is at the noise floor" + (f" in all {len(exps)} experiments." if len(exps) > 1 else ".")
        )
    return out


def proposed_section(js: dict) -> list[str]:
    """The terms outside the catalogue that explain the residual (``proposed``), kept apart from the effects."""
    terms = js.get("proposed") or []
    if not terms:
        return []
    out = ["", "Proposed, outside the catalogue (a term the catalogue does not hold; not an accepted effect):", ""]
    for t in terms:
        lo, hi = t["ci95"]
        out.append(
            f"- {t['words']}: `{t['expression']}`, c = {fmt(t['coefficient'], 3)} [{fmt(lo, 3)}, {fmt(hi, 3)}] "
            f"({t['unit']})."
        )
    first, last = terms[0], terms[-1]
    out += [
        "",
        f"With {'it' if len(terms) == 1 else 'them'} the error on held-out whole cycles falls from "
        f"{fmt(first['heldout_rmse_before'], 3)}× to {fmt(last['heldout_rmse_after'], 3)}× the noise floor"
        + (
            "; the catalogue effects above are those still needed beside it."
            if js["effects"]
            else "; no catalogue effect is needed beside it."
        ),
    ]
    return out


def _ambiguous_section(js: dict) -> list[str]:
    """The effect sets the data cannot tell from the answer, and the experiment that would."""
    amb = js.get("ambiguous") or []
    if not amb:
        return []
    out = [
        "## What the data cannot decide",
        "",
        f"The answer above (`{'`, `'.join(js['effects'])}`) is the simplest of the sets below, which explain "
        "this campaign about as well (|ΔBIC| < 10, or one needs a parameter the data only bound while the other "
        "fits to within 10 % of the noise). Do not trust the choice between them; the last column names the "
        "experiment that would settle it.",
        "",
    ]
    rows = [
        [
            ", ".join(f"`{e}`" for e in a["effects"]),
            fmt(a["delta_bic"], 3),
            a["free_parameters"],
            ", ".join(a["only_bounded"]) or "none",
            a["separate_by"],
        ]
        for a in amb
    ]
    return out + _table(
        ["other set", "ΔBIC vs the answer", "free parameters", "only bounded", "separate them by"], rows
    )


def _param_text(js: dict, name: str) -> str:
    """'mu_j_mm = 6.919 mm (95%: 6.917–6.921)'."""
    u = unit_of(name)
    u = "" if u == "–" else f" {u}"
    ci = js["param_ci95"].get(name)
    iv = f" (95%: {fmt(ci[0])} to {fmt(ci[1])})" if ci else ""
    return f"{name} = {fmt(js['params'][name])}{u}{iv}"


def _steps_section(js: dict) -> list[str]:
    rows = [["0", "design simulation", "—", "—", fmt(js["heldout_rmse_design"], 3), "1"]]
    for lab, s in zip(_step_labels(js["steps"]), js["steps"]):
        eff = {
            "added": f"`{s['effect']}`",
            "dropped": f"`{s['effect']}` (dropped)",
            "replaced": f"`{s['effect']}` in the place of `{s.get('replaces')}`",
        }.get(s["action"], f"swapped to `{s['effect']}`")
        rows.append(
            [
                lab,
                eff,
                s.get("name") or _short_cause(s["cause"]),
                fmt(s["delta_bic"]),
                fmt(s["heldout_rmse"], 3),
                fmt(s["gain"], 3),
            ]
        )
    out = ["## Selection steps", ""]
    out += _table(["step", "effect", "named cause", "ΔBIC", "held-out RMSE (× noise)", "gain"], rows)
    out += [
        "",
        f"An effect is added when it lowers the BIC by more than {BIC_GATE:g} (ΔBIC < −{BIC_GATE:g}), "
        "lowers the error on held-out whole cycles and moves the prediction by more than 1% of the "
        "measured range. Gain: RMSE design / RMSE after the step, geometric mean over the experiments.",
    ]
    if any(s["action"] == "dropped" for s in js["steps"]):
        out += [
            "Steps B1, B2, … are the backward pass: an effect is dropped when, with the others refitted, "
            f"keeping it is worth no more than ΔBIC = −{BIC_GATE:g} (its ΔBIC is shown)."
        ]
    if any(s["action"] == "replaced" for s in js["steps"]):
        out += [
            "Step R replaces an effect the forward pass took by one with fewer parameters, tried beside it, that, "
            "in its place and with the "
            f"others refitted, lowers the BIC by more than {BIC_GATE:g} (its ΔBIC is against the set before it): "
            "an effect with more parameters can win a forward step by taking up part of one not yet added."
        ]
    if any(s["action"] == "swapped" for s in js["steps"]):
        out += [
            "Step S swaps the selected set for a simpler one that the data cannot tell from it (see below): "
            "its ΔBIC is against the selected set."
        ]
    if js["heldout_rmse_design"] is None:
        out += ["No held-out error: no experiment has two whole cycles."]
    return out


def _experiments_section(js: dict) -> list[str]:
    rows = []
    for e in js["experiments"]:
        label, unit = QUANTITY.get(e["quantity"], (e["quantity"], ""))
        dropped = sum(e["rows_dropped"].values())
        why = ", ".join(f"{v} {k}" for k, v in e["rows_dropped"].items())
        rows.append(
            [
                e["file"],
                f"{label} [{unit}]",
                fmt(e["rmse_design"]),
                fmt(e["rmse_final"]),
                fmt(e["noise"]),
                fmt(e["final_over_noise"], 3),
                f"{e['samples_masked_at_reversals']} of {e['samples']}",
                f"{dropped} ({why})" if dropped else "0",
            ]
        )
    out = ["## Experiments", ""]
    out += _table(
        [
            "file",
            "quantity",
            "RMSE design",
            "RMSE final",
            "noise σ",
            "final / noise",
            "samples masked at reversals",
            "rows dropped",
        ],
        rows,
    )
    out += [
        "",
        "RMSE and noise in the experiment's unit, on the samples fitted (masked samples, where the "
        "motion direction is ambiguous around a reversal, are left out).",
    ]
    return out


def _params_section(js: dict) -> list[str]:
    d = js["design"]
    rows = []
    for n, v in js["params"].items():
        eff = PARAMS[n][0] if n in PARAMS else None
        absent = eff.neutral(d).get(n) if eff is not None else None
        ci = js["param_ci95"].get(n)
        if ci:
            iv = f"[{fmt(ci[0])}, {fmt(ci[1])}]"
        elif n in js["not_identifiable_why"]:
            iv = "not fitted (not identifiable)"
        else:
            iv = "not fitted (design value)"
        rows.append([f"`{n}`", f"`{eff.id}`" if eff is not None else "—", fmt(v), iv, unit_of(n), fmt(absent)])
    out = ["## Fitted parameters", ""]
    out += _table(["parameter", "effect", "value", "95% interval", "unit", "design / absent"], rows)
    out += [
        "",
        "Intervals from the Gauss–Newton covariance, widened for residual autocorrelation. "
        "'design / absent': the value in the design simulation (the effect absent).",
    ]
    return out


def _not_identifiable_section(js: dict) -> list[str]:
    why = js["not_identifiable_why"]
    if not why:
        return []
    out = [
        "## Not identifiable from this campaign",
        "",
        "These parameters were **not fitted**: the campaign cannot determine them, so they stay at their "
        "design (or effect-absent) value.",
        "",
    ]
    for n, r in why.items():
        eff = PARAMS[n][0] if n in PARAMS else None
        hint = ""
        if eff is not None and "do not depend" in r and eff.needs_text:
            hint = f" — it needs {eff.needs_text}"
        out.append(f"- `{n}` ({f'`{eff.id}`' if eff else '?'}): {r}{hint}.")
    for acc, others in _stand_ins(js).items():
        what = " and ".join(f"{', '.join(ns)} (`{e}`)" for e, ns in others.items())
        out += [
            "",
            f"The parameters of `{acc}` are confounded with {what}: in this campaign these cannot be told "
            f"apart, so `{acc}` may stand in for part of what they describe. An experiment that changes "
            "one without the other would separate them.",
        ]
    return out


def _stand_ins(js: dict) -> dict[str, dict[str, list[str]]]:
    """Accepted effect → {other effect: its parameters confounded with the accepted effect's parameters}."""
    out: dict[str, dict[str, list[str]]] = {}
    for n, r in js["not_identifiable_why"].items():
        if not r.startswith("confounded with") or n not in PARAMS:
            continue
        mine = PARAMS[n][0].id
        if mine in js["effects"]:
            continue
        for other in r[len("confounded with") :].split(","):
            other = other.strip()
            if other in PARAMS and PARAMS[other][0].id in js["effects"]:
                lst = out.setdefault(PARAMS[other][0].id, {}).setdefault(mine, [])
                if n not in lst:
                    lst.append(n)
    return out


def _rejected_section(js: dict) -> list[str]:
    cands = js["candidates"]
    if not cands:
        return []
    last = max(c["step"] for c in cands)
    frozen = set(js["not_identifiable"])
    rows = []
    for c in cands:
        if c.get("reason") in ("accepted", "not_needed", "not_identifiable"):
            continue
        if all(n in frozen for n in EFFECTS[c["effect"]].param_names):
            continue  # nothing left to fit: listed under "not identifiable"
        v = c["verdict"]
        special = c.get("reason") in ("heldout", "relevance")
        if c["step"] != last and not special:
            continue
        if c.get("reason") == "bic":
            v = f"too small an improvement for its parameters ({v})"
        elif c.get("reason") == "relevance":
            v = f"statistically supported but practically irrelevant: it {v}"
        rows.append([f"`{c['effect']}`", str(c["step"]), fmt(c["delta_bic"]), v])
    if not rows:
        return []
    out = ["## Rejected candidates", ""]
    out += _table(["effect", "step", "ΔBIC", "why not"], rows)
    out += [
        "",
        f"Step {last} is the last forward step (what was left when the selection stopped); earlier steps "
        "are listed only where a candidate failed the held-out or relevance check.",
    ]
    return out


def _diagnostics_section(js: dict) -> list[str]:
    out = [
        "## Diagnostics",
        "",
        "What the residual of the design simulation points to (direction band, centre line, velocity, hold drift), "
        "and whether the final residual is at the noise floor.",
        "",
    ]
    for e in js["experiments"]:
        q = quantity_unit(e["quantity"])
        dd, df = e["diagnostics_design"], e["diagnostics_final"]
        out.append(
            f"**{e['file']}** — design RMSE {fmt(e['rmse_design'])} {q} "
            f"({fmt((e['rmse_design'] or 0) / (e['noise'] or 1), 3)}× noise):"
        )
        hints = dd.get("hints", [])
        if hints:
            for h in hints:
                out.append(f"- {h['evidence']} → {', '.join(f'`{x}`' for x in h['effects'])}")
        else:
            out.append("- no catalogue effect's pattern above the noise")
        ratio = e["final_over_noise"] or 0
        if ratio <= FLOOR_RATIO:
            fin = f"at the noise floor ({fmt(ratio, 3)}× noise)"
        else:
            fin = f"still {fmt(ratio, 3)}× the noise"
        left = df.get("hints", [])
        out.append(
            f"- final model: RMSE {fmt(e['rmse_final'])} {q}, {fin}"
            + (
                "; it still points to: "
                + "; ".join(f"{h['evidence']} → " + ", ".join(f"`{x}`" for x in h["effects"]) for h in left)
                if left
                else ""
            )
        )
        out.append(structure_line(e.get("residual_structure") or [], bool(js.get("proposed"))))
        out.append("")
    return out[:-1]


def structure_line(tests: list[dict], proposed: bool) -> str:
    """One line: what the catalogue's final residual still follows (rjcad.identify.structure), with sizes."""
    whose = "the catalogue's final residual (on the data as measured)" if proposed else "the final residual"
    found = [t for t in tests if t["found"]]
    if not tests:
        return f"- {whose}: too few samples to test its structure"
    if not found:
        names = ", ".join(t["against"].replace("_x_", " × ") for t in tests)
        return f"- {whose} follows none of: {names} (each p > {P_FOUND:g} or < {SIZE_FOUND:g}× noise)"
    parts = [
        f"{t['words']} (p {'≤' if t['p_value'] <= P_FOUND else '='} {fmt(max(t['p_value'], P_FOUND), 2)}, "
        f"{fmt(t['size_over_noise'], 2)}× noise)"
        for t in found
    ]
    return f"- {whose} follows: " + "; ".join(parts)


def render_markdown(js: dict, plots: dict[str, str] | None = None) -> str:
    """The text of report.md from the JSON dict; ``plots``: 'fit', 'steps', 'residuals' → relative PNG link."""
    plots = plots or {}

    def img(key, caption):
        return ["", f"![{caption}]({plots[key]})"] if key in plots else []

    out = ["# Identification report", ""]
    out += _summary(js)
    amb = _ambiguous_section(js)
    if amb:
        out += [""] + amb
    out += img("fit", "measured data, design simulation and final model")
    out += [""] + _steps_section(js)
    out += img("steps", "error after each step")
    out += [""] + _experiments_section(js)
    out += [""] + _params_section(js)
    for section in (_not_identifiable_section(js), _rejected_section(js)):
        if section:
            out += [""] + section
    out += [""] + _diagnostics_section(js)
    out += img("residuals", "residuals before and after, by motion direction")
    out += img("diagnostics", "design residual against velocity and during holds")
    if js["notes"]:
        out += ["", "## Notes", ""] + [f"- {n}" for n in js["notes"]]
    return "\n".join(out) + "\n"


def write_report(ident: Identification, js: dict, out_dir) -> list[Path]:
    """Write report.md, fit.png, residuals.png, steps.png and diagnostics.png into ``out_dir`` as one set
    (all or none; an earlier report untouched); return their paths."""
    out = Path(out_dir)
    with output_set(out) as stage:
        plots = [
            plot_fit(ident, js, stage / "fit.png"),
            plot_residuals(ident, js, stage / "residuals.png"),
            plot_steps(js, stage / "steps.png"),
            plot_diagnostics(ident, js, stage / "diagnostics.png"),
        ]
        md = render_markdown(js, {p.stem: p.name for p in plots})
        write_atomic(stage / "report.md", md)
    return [out / p.name for p in plots] + [out / "report.md"]
