"""``rjcad spring --plot``: what a designer wants to see before printing a spring.

Left: the joint's torque against the wind-up from the printed shape, the rod model against the closed
form, with the working range shaded. Right: the strip as printed and wound to preload + rotation
(rod model, hub frame, both edges drawn), the tightest coil gap at that wind-up marked.
"""

from __future__ import annotations

import math

import numpy as np

from rjcad.plotting import pyplot, save_png
from rjcad.spring import rod as rodmodel


def _edges(X, t):
    """The strip's two edges: the centreline X (N, 2) offset by ±t/2 along its normals [mm]."""
    d = np.gradient(X, axis=0)
    n = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.hypot(d[:, 0], d[:, 1])[:, None]
    return X + 0.5 * t * n, X - 0.5 * t * n


def _torque_panel(ax, design) -> None:
    rod, req = design.rod, design.requirement
    n = req.springs  # the joint's springs in parallel: its torque is n × one spring's
    deg = np.degrees(rod.theta)
    ax.plot(deg, n * rod.torque, "C0-", lw=2, label=f"rod model: K = {design.joint_stiffness:.3f} N·mm/rad")
    ax.plot(
        deg,
        n * design.formula_stiffness * rod.theta,
        "k--",
        lw=1,
        label=f"formula c·E·b·t³/12L: K = {n * design.formula_stiffness:.3f} N·mm/rad",
    )
    ax.axvspan(
        math.degrees(req.preload),
        math.degrees(req.max_windup),
        color="C2",
        alpha=0.12,
        label=f"working range (asked K = {req.joint_stiffness:g})",
    )
    if rod.first_contact is not None:
        ax.axvline(math.degrees(rod.first_contact), color="C3", label="coils touch")
    ax.set_xlabel("wind-up from the printed shape [deg]")
    ax.set_ylabel("joint torque, both springs [N·mm]" if n == 2 else "joint torque, one spring [N·mm]")
    ax.set_title(
        f"{req.end} outer end, loaded unwinding; peak stress {design.max_stress:.1f} of "
        f"{req.allowed_stress:.1f} MPa allowed",
        fontsize=10,
    )
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)


def _tightest_at_end(design):
    """(gap, point on the strip) of the smallest coil gap in the wound shape at preload + rotation."""
    X, t = design.rod.wound, design.thickness
    a = np.linspace(0.0, 2 * math.pi * design.turns, len(X))
    tang = rodmodel.polyline_tangents(X)
    pin = design.requirement.pin_radius
    coil, hub = rodmodel.node_gaps(X, tang, a, t, pin_radius=pin)
    g = coil if hub is None else np.minimum(coil, hub)
    i = int(np.argmin(g))
    return float(g[i]), X[i]


def _shape_panel(ax, design) -> None:
    rod, req, t = design.rod, design.requirement, design.thickness
    for X, color, alpha, label in (
        (rod.printed, "0.55", 0.35, "as printed"),
        (rod.wound, "C0", 0.85, f"wound {math.degrees(req.max_windup):g}° (rod model)"),
    ):
        a, b = _edges(X, t)
        outline = np.concatenate([a, b[::-1]])
        ax.fill(outline[:, 0], outline[:, 1], color=color, alpha=alpha, lw=0, label=label)
    if req.pin_radius is not None:
        ax.add_patch(pyplot().Circle((0, 0), req.pin_radius, color="0.5", alpha=0.5, label="pin"))
    gap, xy = _tightest_at_end(design)
    ax.plot(
        *xy, "o", ms=12, mfc="none", mec="C3", mew=2, label=f"tightest gap here: {gap:.3f} mm (minimum {req.gap_min:g})"
    )
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (hub frame)")
    ax.set_ylabel("y [mm]")
    ax.set_title(
        f"smallest gap over the wind-up {rod.min_gap:.3f} mm at {math.degrees(rod.min_gap_theta):.0f}°; "
        f"end force {rod.pin_force:.2f} N",
        fontsize=10,
    )
    ax.margins(0.08, 0.3)
    ax.legend(fontsize=8, loc="lower center", ncol=2, framealpha=0.9)


def write_plot(design, path) -> None:
    """Write the torque curve and the wound shape of ``design`` (a SpringDesign) as a PNG at ``path``."""
    fig, (ax1, ax2) = pyplot().subplots(1, 2, figsize=(14, 7))
    _torque_panel(ax1, design)
    _shape_panel(ax2, design)
    d = design
    fig.suptitle(
        f"spring b {d.width:g} × t {d.thickness:g} mm, L {d.length:.1f} mm, r_in {d.inner_radius:g} mm, "
        f"pitch {d.pitch:.3f} mm, {d.turns:.2f} turns ({d.requirement.material}, {d.requirement.printer})",
        fontsize=11,
    )
    fig.tight_layout()
    save_png(fig, path, dpi=100)
