"""The identification as a human-readable report: report.md plus fit.png, residuals.png and steps.png.

Numbers in the text come from the JSON (``to_json``) so the report and the JSON agree; the plots
need the samples and the motion analysis, so they come from the Identification. Quantities are in
their units (torque N·mm, tendon force N); held-out RMSE is whitened (1 = the noise floor).
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from rjcad.config import write_atomic
from rjcad.errors import RjcadError
from rjcad.identify.catalogue import EFFECTS, PARAMS
from rjcad.identify.diagnose import angle_direction_fit
from rjcad.identify.select import BIC_GATE, Identification
from rjcad.identify.signal import runs

#: final RMSE / noise σ up to which an experiment counts as explained to the noise floor
FLOOR_RATIO = 1.2
#: at most this many samples per experiment are drawn (every k-th one beyond)
MAX_POINTS = 20_000

QUANTITY = {"torque_nmm": ("torque", "N·mm"), "tendon_force_n": ("tendon force", "N")}
#: JSON name suffix → unit, longest first
_SUFFIX_UNITS = (("_nmm_s_per_rad", "N·mm·s/rad"), ("_nmm_per_rad3", "N·mm/rad³"), ("_nmm_per_rad", "N·mm/rad"),
                 ("_deg", "deg"), ("_nmm", "N·mm"), ("_mm", "mm"), ("_n", "N"), ("_s", "s"))
#: what an effect needs in a campaign (catalogue ``needs``), in words
_NEEDS = {"normal_load": "an experiment with a transverse load F_n > 0", "tendon": "a tendon-driven experiment",
          "routed": "a tendon routed through the base link", "holds": "holds (the joint standing still)",
          "speeds": "moves at several speeds"}


# ---------------------------------------------------------------- formatting


def fmt(x, sig: int = 4) -> str:
    """``x`` with ``sig`` significant digits; integers from 10⁴ on, scientific below 10⁻³; '—' for None."""
    if x is None:
        return "—"
    x = float(x)
    if not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    if 1e4 <= abs(x) < 1e12:
        return f"{x:.0f}"
    if abs(x) < 1e-3:
        return f"{x:.{max(sig - 1, 1)}e}"
    return f"{x:.{sig}g}"


def unit_of(name: str) -> str:
    """Unit of a JSON parameter from its name (``mu_j_mm`` → mm); '–' for a ratio such as beta_pos."""
    for suffix, unit in _SUFFIX_UNITS:
        if name.endswith(suffix):
            return unit
    return "–"


def quantity_unit(quantity: str) -> str:
    """N·mm for torque_nmm, N for tendon_force_n."""
    return QUANTITY.get(quantity, (quantity, ""))[1]


def _cell(s) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ")


def _table(header: list[str], rows: list[list]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(_cell(c) for c in r) + " |" for r in rows]
    return out


def _short_cause(cause: str) -> str:
    """The cause's name: its wording up to the first colon."""
    return cause.split(":")[0].strip()


def _whitened(rmse: list, exps: list[dict]) -> float | None:
    """In-sample whitened RMSE pooled over experiments: √(Σ n_e·(rmse_e/σ_e)² / Σ n_e)."""
    num = den = 0.0
    for r, e in zip(rmse, exps):
        if r is None or not e["noise"]:
            continue
        n = e["samples_fitted"]
        num += n * (r / e["noise"]) ** 2
        den += n
    return math.sqrt(num / den) if den else None


def _step_labels(steps: list[dict]) -> list[str]:
    """'1', '2', … for forward steps; 'B1', 'B2', … for effects dropped in the backward pass."""
    out, f, b = [], 0, 0
    for s in steps:
        if s["action"] == "dropped":
            b += 1
            out.append(f"B{b}")
        else:
            f += 1
            out.append(str(f))
    return out


# ---------------------------------------------------------------- plots


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    """PNG bytes of ``fig`` (no version metadata, so reruns are byte-identical), written atomically."""
    plt = _pyplot()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return write_atomic(path, buf.getvalue())


def _stride(n: int) -> int:
    return max(1, -(-n // MAX_POINTS))


def _title(e: dict) -> str:
    q = quantity_unit(e["quantity"])
    route = "routed" if e["routed"] else "not routed"
    return (f"{e['file']}: {e['drive']}, F_n = {fmt(e['normal_load_n'], 3)} N, {route}\n"
            f"RMSE design {fmt(e['rmse_design'], 3)} → final {fmt(e['rmse_final'], 3)} {q}")


def _grid(plt, n: int, ncols: int, w: float, h: float):
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, axes


def plot_fit(ident: Identification, js: dict, path) -> Path:
    """Measured quantity vs joint angle [deg] per experiment: data (grey), design and final model."""
    plt = _pyplot()
    preds_d = ident.design_predictions
    preds_f = ident.final_predictions
    n = len(ident.prepared)
    fig, axes = _grid(plt, n, 1 if n == 1 else 2, 6.5, 4.2)
    for ax, p, e, yd, yf in zip(axes.flat, ident.prepared, js["experiments"], preds_d, preds_f):
        k = _stride(len(p.exp.t))
        th = np.degrees(p.motion.theta)[::k]
        y, ok = p.exp.y[::k], p.valid[::k]
        label, unit = QUANTITY.get(e["quantity"], (e["quantity"], ""))
        ax.scatter(th[ok], y[ok], s=2, color="0.55", lw=0, label="measured", zorder=1)
        if (~ok).any():
            ax.scatter(th[~ok], y[~ok], s=2, color="0.55", alpha=0.2, lw=0, zorder=1,
                       label="masked at reversals")
        ax.plot(th, yd[::k], color="C0", lw=1.0, label="design simulation", zorder=2)
        ax.plot(th, yf[::k], color="C3", lw=1.0, label="final model", zorder=3)
        ax.set_xlabel("joint angle [deg]")
        ax.set_ylabel(f"{label} [{unit}]")
        ax.set_title(_title(e), fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, markerscale=3, loc="best")
    fig.tight_layout()
    return _save(fig, Path(path))


def plot_residuals(ident: Identification, js: dict, path) -> Path:
    """Residual y − ŷ vs angle [deg], design (left) and final (right), by motion direction, ±σ noise band.

    Both panels of an experiment share the y-scale, so the shrink is visible; masked samples are left out.
    """
    plt = _pyplot()
    preds_d = ident.design_predictions
    preds_f = ident.final_predictions
    n = len(ident.prepared)
    fig, axes = plt.subplots(n, 2, figsize=(11, 2.8 * n), squeeze=False, sharey="row")
    for row, p, e, yd, yf in zip(axes, ident.prepared, js["experiments"], preds_d, preds_f):
        k = _stride(len(p.exp.t))
        ok = p.valid[::k]
        th = np.degrees(p.motion.theta)[::k][ok]
        s = p.motion.direction[::k][ok]
        unit = quantity_unit(e["quantity"])
        for ax, yh, name, rm in ((row[0], yd, "design", e["rmse_design"]), (row[1], yf, "final", e["rmse_final"])):
            r = (p.exp.y - yh)[::k][ok]
            ax.axhspan(-p.sigma, p.sigma, color="0.8", alpha=0.6, lw=0, label="± noise σ", zorder=0)
            ax.axhline(0.0, color="0.4", lw=0.6, zorder=1)
            ax.scatter(th[s > 0], r[s > 0], s=2, lw=0, color="C0", label="forward (θ rising)", zorder=2)
            ax.scatter(th[s < 0], r[s < 0], s=2, lw=0, color="C1", label="backward (θ falling)", zorder=2)
            ax.set_title(f"{e['file']}: {name}, RMSE {fmt(rm, 3)} {unit} (noise {fmt(e['noise'], 3)})", fontsize=9)
            ax.set_xlabel("joint angle [deg]")
            ax.grid(alpha=0.3)
        row[0].set_ylabel(f"residual [{unit}]")
        row[1].legend(fontsize=7, markerscale=3, loc="best")
    fig.tight_layout()
    return _save(fig, Path(path))


def plot_steps(js: dict, path) -> Path:
    """Whitened RMSE (1 = noise floor) per step, design first, log scale: held-out and in-sample."""
    plt = _pyplot()
    exps = js["experiments"]
    labels = ["design"] + [("− " if s["action"] == "dropped" else "+ ") + s["effect"] for s in js["steps"]]
    held = [js["heldout_rmse_design"]] + [s["heldout_rmse"] for s in js["steps"]]
    ins = [_whitened([e["rmse_design"] for e in exps], exps)] + [_whitened(s["rmse"], exps) for s in js["steps"]]
    x = np.arange(len(labels))
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(labels) + 2), 4.5))
    if any(h is not None for h in held):
        hx = [i for i, h in enumerate(held) if h is not None]
        ax.plot(hx, [held[i] for i in hx], "-o", color="C3", label="held-out whole cycles")
        for i in hx:
            ax.annotate(fmt(held[i], 3), (i, held[i]), textcoords="offset points", xytext=(6, 4), fontsize=8)
    ix = [i for i, v in enumerate(ins) if v is not None]
    ax.plot(ix, [ins[i] for i in ix], "--s", color="C0", mfc="none", label="in-sample (fitted cycles)")
    ax.axhline(1.0, color="k", lw=1, ls=":", label="noise floor")
    ax.set_yscale("log")
    ax.set_xticks(x, labels, rotation=20, ha="right", fontsize=9)
    ax.set_ylabel("RMSE / noise σ (pooled)")
    ax.set_title("error after each step of the selection (1 = noise floor)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, Path(path))


def plot_diagnostics(ident: Identification, js: dict, path) -> Path:
    """Design residual against velocity [rad/s] (left) and against time into each hold [s] (right), per experiment.

    Before plotting against velocity, the angle/direction part of the residual (the regression of
    ``diagnose``: [1, θ, θ², s, s·θ]) is removed, so a slope left there is damping; during holds the
    residual is drawn relative to its value at the start of the hold, so a decay is relaxation.
    """
    plt = _pyplot()
    preds_d = ident.design_predictions
    n = len(ident.prepared)
    fig, axes = plt.subplots(n, 2, figsize=(11, 2.8 * n), squeeze=False)
    for row, p, e, yd in zip(axes, ident.prepared, js["experiments"], preds_d):
        unit = quantity_unit(e["quantity"])
        ok = p.valid
        r = (p.exp.y - yd)
        s, v = p.motion.direction[ok], p.motion.velocity[ok]
        coef, X = angle_direction_fit(p, r)
        left = r[ok] - X @ coef
        k = _stride(len(v))
        ax = row[0]
        ax.axhspan(-p.sigma, p.sigma, color="0.8", alpha=0.6, lw=0, label="± noise σ", zorder=0)
        ax.scatter(v[::k][s[::k] > 0], left[::k][s[::k] > 0], s=2, lw=0, color="C0", label="forward")
        ax.scatter(v[::k][s[::k] < 0], left[::k][s[::k] < 0], s=2, lw=0, color="C1", label="backward")
        ax.set_xlabel("joint velocity [rad/s]")
        ax.set_ylabel(f"residual − angle/direction fit [{unit}]")
        ax.set_title(f"{e['file']}: design residual vs velocity", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, markerscale=3, loc="best")
        ax = row[1]
        for a, b in runs(p.motion.hold & ok):
            if b - a < 5:
                continue
            tt = p.exp.t[a:b] - p.exp.t[a]
            rr = r[a:b] - r[a:a + max((b - a) // 10, 1)].mean()
            col = "C0" if p.motion.direction[a] > 0 else "C1"
            ax.plot(tt, rr, lw=0.7, color=col, alpha=0.8)
        ax.axhline(0.0, color="0.4", lw=0.6)
        ax.set_xlabel("time into the hold [s]")
        ax.set_ylabel(f"residual change [{unit}]")
        ax.set_title(f"{e['file']}: holds (blue: after forward)", fontsize=9)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return _save(fig, Path(path))


# ---------------------------------------------------------------- report.md


def _summary(js: dict) -> list[str]:
    d, exps = js["design"], js["experiments"]
    design = (f"K = {fmt(d['stiffness_nmm_per_rad'])} N·mm/rad, θ₀ = {fmt(d['preload_deg'])}°, "
              f"r = {fmt(d['pulley_radius_mm'])} mm")
    worst = max(exps, key=lambda e: (e["rmse_design"] or 0) / (e["noise"] or 1))
    ratios = [(e["rmse_design"] or 0) / (e["noise"] or 1) for e in exps]
    q = quantity_unit(worst["quantity"])
    above = [e for e in exps if (e["final_over_noise"] or 0) > FLOOR_RATIO]
    out = []
    if not js["effects"] and not above:
        out.append(f"Nothing beyond the design simulation was needed: the design simulation ({design}) already "
                   f"explains the data to the noise floor (RMSE / noise {fmt(min(ratios), 3)}–{fmt(max(ratios), 3)} "
                   "per experiment"
                   + (f", held-out {fmt(js['heldout_rmse_design'], 3)}× noise" if js["heldout_rmse_design"] else "")
                   + "). No catalogue effect improved it enough to be accepted.")
        return out
    out.append(f"The design simulation ({design}) misses the measured data by up to {fmt(max(ratios), 3)}× the "
               f"noise. The largest error is in experiment {worst['file']} ({fmt(worst['rmse_design'])} {q} RMSE "
               f"against {fmt(worst['noise'], 3)} {q} noise).")
    if not js["effects"]:
        out.append("")
        out.append("No catalogue effect improved the fit enough to be accepted, yet the residual stays above the "
                   "noise floor: the cause is probably not in the catalogue (see the diagnostics below).")
    else:
        out += ["", "Found:", ""]
        for i, eid in enumerate(js["effects"], 1):
            vals = "; ".join(_param_text(js, n) for n in EFFECTS[eid].param_names if n in js["param_ci95"])
            out.append(f"{i}. `{eid}` — {EFFECTS[eid].cause}." + (f" Fitted: {vals}." if vals else ""))
        out.append("")
        ho = ""
        if js["heldout_rmse_design"] is not None and js["heldout_rmse_final"] is not None:
            ho = (f"the error on held-out whole cycles falls from {fmt(js['heldout_rmse_design'], 3)}× to "
                  f"{fmt(js['heldout_rmse_final'], 3)}× the noise floor, and ")
        out.append(f"With {'this effect' if len(js['effects']) == 1 else 'these effects'} {ho}the RMSE shrinks "
                   f"{fmt(js['gain'], 3)}-fold (geometric mean over the experiments).")
    if above:
        out.append("The final residual is still above the noise floor in "
                   + ", ".join(f"{e['file']} ({fmt(e['final_over_noise'], 3)}× noise)" for e in above)
                   + ": something there is not explained.")
    else:
        out.append("The final residual is at the noise floor" + (f" in all {len(exps)} experiments."
                                                                 if len(exps) > 1 else "."))
    return out


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
        eff = f"`{s['effect']}`" if s["action"] == "added" else f"`{s['effect']}` (dropped)"
        rows.append([lab, eff, s.get("name") or _short_cause(s["cause"]), fmt(s["delta_bic"]), fmt(s["heldout_rmse"], 3),
                     fmt(s["gain"], 3)])
    out = ["## Selection steps", ""]
    out += _table(["step", "effect", "named cause", "ΔBIC", "held-out RMSE (× noise)", "gain"], rows)
    out += ["", f"An effect is added when it lowers the BIC by more than {BIC_GATE:g} (ΔBIC < −{BIC_GATE:g}), "
                "lowers the error on held-out whole cycles and moves the prediction by more than 1% of the "
                "measured range. Gain: RMSE design / RMSE after the step, geometric mean over the experiments."]
    if any(s["action"] == "dropped" for s in js["steps"]):
        out += ["Steps B1, B2, … are the backward pass: an effect is dropped when, with the others refitted, "
                f"keeping it is worth no more than ΔBIC = −{BIC_GATE:g} (its ΔBIC is shown)."]
    if js["heldout_rmse_design"] is None:
        out += ["No held-out error: no experiment has two whole cycles."]
    return out


def _experiments_section(js: dict) -> list[str]:
    rows = []
    for e in js["experiments"]:
        label, unit = QUANTITY.get(e["quantity"], (e["quantity"], ""))
        dropped = sum(e["rows_dropped"].values())
        why = ", ".join(f"{v} {k}" for k, v in e["rows_dropped"].items())
        rows.append([e["file"], f"{label} [{unit}]", fmt(e["rmse_design"]), fmt(e["rmse_final"]), fmt(e["noise"]),
                     fmt(e["final_over_noise"], 3), f"{e['samples_masked_at_reversals']} of {e['samples']}",
                     f"{dropped} ({why})" if dropped else "0"])
    out = ["## Experiments", ""]
    out += _table(["file", "quantity", "RMSE design", "RMSE final", "noise σ", "final / noise",
                   "samples masked at reversals", "rows dropped"], rows)
    out += ["", "RMSE and noise in the experiment's unit, on the samples fitted (masked samples, where the "
                "motion direction is ambiguous around a reversal, are left out)."]
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
    out += ["", "Intervals from the Gauss–Newton covariance, widened for residual autocorrelation. "
                "'design / absent': the value in the design simulation (the effect absent)."]
    return out


def _not_identifiable_section(js: dict) -> list[str]:
    why = js["not_identifiable_why"]
    if not why:
        return []
    out = ["## Not identifiable from this campaign", "",
           "These parameters were **not fitted**: the campaign cannot determine them, so they stay at their "
           "design (or effect-absent) value.", ""]
    for n, r in why.items():
        eff = PARAMS[n][0] if n in PARAMS else None
        hint = ""
        if eff is not None and "do not depend" in r and eff.needs in _NEEDS:
            hint = f" — it needs {_NEEDS[eff.needs]}"
        out.append(f"- `{n}` ({f'`{eff.id}`' if eff else '?'}): {r}{hint}.")
    for acc, others in _stand_ins(js).items():
        what = " and ".join(f"{', '.join(ns)} (`{e}`)" for e, ns in others.items())
        out += ["", f"The parameters of `{acc}` are confounded with {what}: in this campaign these cannot be told "
                    f"apart, so `{acc}` may stand in for part of what they describe. An experiment that changes "
                    "one without the other would separate them."]
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
        for other in r[len("confounded with"):].split(","):
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
    out += ["", f"Step {last} is the last forward step (what was left when the selection stopped); earlier steps "
                "are listed only where a candidate failed the held-out or relevance check."]
    return out


def _diagnostics_section(js: dict) -> list[str]:
    out = ["## Diagnostics", "",
           "What the residual of the design simulation points to (direction band, centre line, velocity, hold drift), "
           "and whether the final residual is at the noise floor.", ""]
    for e in js["experiments"]:
        q = quantity_unit(e["quantity"])
        dd, df = e["diagnostics_design"], e["diagnostics_final"]
        out.append(f"**{e['file']}** — design RMSE {fmt(e['rmse_design'])} {q} "
                   f"({fmt((e['rmse_design'] or 0) / (e['noise'] or 1), 3)}× noise):")
        hints = dd.get("hints", [])
        if hints:
            for h in hints:
                out.append(f"- {h['evidence']} → {', '.join(f'`{x}`' for x in h['effects'])}")
        else:
            out.append("- no systematic pattern above the noise")
        ratio = e["final_over_noise"] or 0
        if ratio <= FLOOR_RATIO:
            fin = f"at the noise floor ({fmt(ratio, 3)}× noise)"
        else:
            fin = f"still {fmt(ratio, 3)}× the noise"
        left = df.get("hints", [])
        out.append(f"- final model: RMSE {fmt(e['rmse_final'])} {q}, {fin}"
                   + ("; it still points to: " + "; ".join(f"{h['evidence']} → "
                                                            + ", ".join(f"`{x}`" for x in h["effects"])
                                                            for h in left) if left else ""))
        out.append("")
    return out[:-1]


def render_markdown(js: dict, plots: dict[str, str] | None = None) -> str:
    """The text of report.md from the JSON dict; ``plots``: 'fit', 'steps', 'residuals' → relative PNG link."""
    plots = plots or {}

    def img(key, caption):
        return ["", f"![{caption}]({plots[key]})"] if key in plots else []

    out = ["# Identification report", ""]
    out += _summary(js)
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
    """Write report.md, fit.png, residuals.png, steps.png and diagnostics.png into ``out_dir``; return their paths."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise RjcadError(f"{out}: exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    paths = [plot_fit(ident, js, out / "fit.png"),
             plot_residuals(ident, js, out / "residuals.png"),
             plot_steps(js, out / "steps.png"),
             plot_diagnostics(ident, js, out / "diagnostics.png")]
    md = render_markdown(js, {p.stem: p.name for p in paths})
    paths.append(write_atomic(out / "report.md", md))
    return paths
