"""The identification report's plots: fit.png, residuals.png, steps.png, diagnostics.png.

The plots need the samples and the motion analysis, so they come from the Identification; their
labels come from the JSON (``to_json``). Quantities in their units (torque N·mm, tendon force N).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rjcad.identify.diagnose import angle_direction_fit
from rjcad.identify.formatting import QUANTITY, fmt, quantity_unit
from rjcad.identify.select import Identification
from rjcad.identify.signal import runs
from rjcad.plotting import pyplot, save_png

#: at most this many samples per experiment are drawn (every k-th one beyond)
MAX_POINTS = 20_000


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


def _stride(n: int) -> int:
    return max(1, -(-n // MAX_POINTS))


def _title(e: dict) -> str:
    q = quantity_unit(e["quantity"])
    route = "routed" if e["routed"] else "not routed"
    return (
        f"{e['file']}: {e['drive']}, F_n = {fmt(e['normal_load_n'], 3)} N, {route}\n"
        f"RMSE design {fmt(e['rmse_design'], 3)} → final {fmt(e['rmse_final'], 3)} {q}"
    )


def _grid(plt, n: int, ncols: int, w: float, h: float):
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, axes


def plot_fit(ident: Identification, js: dict, path) -> Path:
    """Measured quantity vs joint angle [deg] per experiment: data (grey), design and final model."""
    plt = pyplot()
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
            ax.scatter(th[~ok], y[~ok], s=2, color="0.55", alpha=0.2, lw=0, zorder=1, label="masked at reversals")
        ax.plot(th, yd[::k], color="C0", lw=1.0, label="design simulation", zorder=2)
        ax.plot(th, yf[::k], color="C3", lw=1.0, label="final model", zorder=3)
        ax.set_xlabel("joint angle [deg]")
        ax.set_ylabel(f"{label} [{unit}]")
        ax.set_title(_title(e), fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, markerscale=3, loc="best")
    fig.tight_layout()
    return save_png(fig, Path(path))


def plot_residuals(ident: Identification, js: dict, path) -> Path:
    """Residual y − ŷ vs angle [deg], design (left) and final (right), by motion direction, ±σ noise band.

    Both panels of an experiment share the y-scale, so the shrink is visible; masked samples are left out.
    """
    plt = pyplot()
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
    return save_png(fig, Path(path))


def plot_steps(js: dict, path) -> Path:
    """Whitened RMSE (1 = noise floor) per step, design first, log scale: held-out and in-sample."""
    plt = pyplot()
    exps = js["experiments"]
    sign = {"dropped": "− ", "added": "+ ", "swapped": "→ ", "replaced": "⇄ "}
    labels = ["design"] + [sign[s["action"]] + s["effect"] for s in js["steps"]]
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
    return save_png(fig, Path(path))


def plot_diagnostics(ident: Identification, js: dict, path) -> Path:
    """Design residual against velocity [rad/s] (left) and against time into each hold [s] (right), per experiment.

    Before plotting against velocity, the angle/direction part of the residual (the regression of
    ``diagnose``: [1, θ, θ², s, s·θ]) is removed, so a slope left there is damping; during holds the
    residual is drawn relative to its value at the start of the hold, so a decay is relaxation.
    """
    plt = pyplot()
    preds_d = ident.design_predictions
    n = len(ident.prepared)
    fig, axes = plt.subplots(n, 2, figsize=(11, 2.8 * n), squeeze=False)
    for row, p, e, yd in zip(axes, ident.prepared, js["experiments"], preds_d):
        unit = quantity_unit(e["quantity"])
        ok = p.valid
        r = p.exp.y - yd
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
            rr = r[a:b] - r[a : a + max((b - a) // 10, 1)].mean()
            col = "C0" if p.motion.direction[a] > 0 else "C1"
            ax.plot(tt, rr, lw=0.7, color=col, alpha=0.8)
        ax.axhline(0.0, color="0.4", lw=0.6)
        ax.set_xlabel("time into the hold [s]")
        ax.set_ylabel(f"residual change [{unit}]")
        ax.set_title(f"{e['file']}: holds (blue: after forward)", fontsize=9)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return save_png(fig, Path(path))
