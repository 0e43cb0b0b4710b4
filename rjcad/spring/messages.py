"""The optimiser's constraint names and its one-line refusals: which constraint binds and what to change.

Shared by ``rjcad spring`` (:func:`rjcad.spring.optimise.design_spring`) and the analytic sweep, so
that both say the same words. A coil-gap refusal says where the coils touch (rod-model surrogate,
or the full rod model when its check refused the design).
"""

from __future__ import annotations

import math

import numpy as np

from rjcad.life.constraint import remedy
from rjcad.spring import factors as fx
from rjcad.spring.design import MIN_RADIUS_TO_THICKNESS, MIN_WIDTH_TO_THICKNESS

#: Constraint names, in the order of the ``binding`` codes of ``optimise_arrays``.
CONSTRAINTS = ("stress", "turns", "outer_radius", "inner_radius", "coil_gap", "width", "life", "pin_gap", "stiffness")

#: ``SpringDesign.constraint_report`` keys → constraint names, in the order a refusal names them.
REPORT_NAMES = {
    "coil_gap_mm": "coil_gap",
    "pin_gap_mm": "pin_gap",
    "stress_mpa": "stress",
    "stiffness_error": "stiffness",
    "outer_radius_mm": "outer_radius",
    "turns": "turns",
    "width_max_mm": "width",
    "width_min_mm": "width",
    "inner_radius_max_mm": "inner_radius",
    "inner_radius_min_mm": "inner_radius",
    "life_lower_cycles": "life",
    "min_wall_mm": "width",
    "thickness_steps": "width",
    "key_gap_mm": "coil_gap",
    "hub_force_ratio": "balance",
}

#: One line per binding constraint: its value and limit at thickness t, width b, and what to change.
_INFEASIBLE = {
    "stress": "stress {value:.1f} MPa > {limit:.1f} MPa allowed at t = {t:g} mm (width b = {b:g} mm, its maximum "
    "--width-max): lower the stiffness or the rotation, or choose a stronger material",
    "turns": "turns {value:.2f} < {limit:g} minimum at t = {t:g} mm (width b = {b:g} mm, its maximum): the strip is "
    "too short to coil; lower the stiffness or allow a wider spring (--width-max)",
    "outer_radius": "outer radius {value:.1f} mm > {limit:g} mm allowed (smallest spring: t = {t:g} mm, b = {b:g} mm, "
    "its pitch kept the coils apart over the whole wind-up): raise the limit (--max-outer-radius), "
    "lower the stiffness, the rotation or the preload, or choose a material with a higher yield/E "
    "ratio",
    "inner_radius": "inner radius {value:.2f} mm > {limit:g} mm allowed at t = {t:g} mm (thin-strip theory needs "
    "r_in >= {r_to_t:g}·t): raise --inner-radius-max",
    "life": "predicted life {value:.3g} cycles (lower 90 % bound at backlash {backlash:g} mm, t = {t:g} mm) < "
    "--min-cycles {limit:.3g}: {remedy}",
    "width": "width {value:g} mm needed (>= width_min and >= {b_to_t:g}·t at t = {t:g} mm, in whole layers) > "
    "--width-max {limit:g} mm: raise --width-max",
    "pin_gap": "pin gap {value:.3f} mm < {limit:g} mm printer minimum at t = {t:g} mm: the strip nears the pin "
    "under wind-up; raise --inner-radius-min",
    "balance": "net hub force {value:.1%} of one arm's reaction > {limit:.0%} (two arms, rod model) at t = {t:g} mm "
    "(b = {b:g} mm): the arms do not balance; use one arm (--arms 1)",
    "stiffness": "stiffness error {value:.2%} > {limit:.1%} (rod model) at t = {t:g} mm (b = {b:g} mm): the "
    "spring is at the edge of what the model's table resolves; change the stiffness or the bounds a "
    "little",
}


def _coil_gap_message(value, limit, t, b, contact_deg, gap_low_deg, windup_deg, end, rod) -> str:
    """Where the coils touch (or the gap drops below the minimum) and what to change."""
    if windup_deg > math.degrees(fx.THETA_MAX) + 1e-6:
        return (
            f"coil gap: preload + rotation = {windup_deg:.0f}° of wind-up is beyond the 360° the spring model "
            "covers: lower the preload or the rotation"
        )
    fix = (
        "lower the preload or the rotation"
        + (", or use --end clamped (its coils close far later)" if end == "pinned" else "")
        + (", or raise --inner-radius-min (a larger hub allows a coarser pitch)")
    )
    if not math.isfinite(value):
        return (
            f"coil gap: the rod model's table has no value for this spring (t = {t:g} mm, b = {b:g} mm) at "
            f"{windup_deg:.0f}° of wind-up; rjcad spring winds it with the full rod model instead"
        )
    scope = "" if rod else ", even at the coarsest pitch the model covers"
    total = f"preload + rotation = {windup_deg:.0f}°"
    if value < 0 or math.isfinite(contact_deg):
        touch = f"at {contact_deg:.0f}° of wind-up" if math.isfinite(contact_deg) else "within the wind-up"
        return (
            f"coil gap: coils touch {touch} ({total}; the printer needs {limit:g} mm) at t = {t:g} mm, "
            f"b = {b:g} mm{scope}; {fix}"
        )
    where = f" at {gap_low_deg:.0f}° of wind-up" if math.isfinite(gap_low_deg) else ""
    return (
        f"coil gap {value:.3f} mm < {limit:g} mm printer minimum at t = {t:g} mm, b = {b:g} mm{scope}: the gap "
        f"falls below {limit:g} mm{where} ({total}); {fix}"
    )


def infeasible_message(
    constraint: str,
    value: float,
    limit: float,
    t: float,
    b: float,
    backlash: float = 0.25,
    *,
    contact_deg: float = math.nan,
    gap_low_deg: float = math.nan,
    windup_deg: float = 0.0,
    end: str = "clamped",
    rod: bool = False,
) -> str:
    """One line: which constraint binds (its value and limit at thickness t, width b) and what to change.

    Coil gap: ``contact_deg`` / ``gap_low_deg`` where the coils touch / the gap drops below ``limit``,
    ``windup_deg`` the preload + rotation; ``rod``: the full rod model's check refused the design.
    """
    if constraint == "coil_gap" or constraint not in _INFEASIBLE:
        return _coil_gap_message(value, limit, t, b, contact_deg, gap_low_deg, windup_deg, end, rod)
    return _INFEASIBLE[constraint].format(
        value=value,
        limit=limit,
        t=t,
        b=b,
        backlash=backlash,
        r_to_t=MIN_RADIUS_TO_THICKNESS,
        b_to_t=MIN_WIDTH_TO_THICKNESS,
        remedy=remedy() if constraint == "life" else "",
    )


def row_message(res: dict, k: int, backlash: float, end: str) -> str:
    """The refusal of row ``k`` of an ``optimise_arrays`` result."""
    name = CONSTRAINTS[int(res["binding"][k])]
    return infeasible_message(
        name,
        float(res["binding_value"][k]),
        float(res["binding_limit"][k]),
        float(res["thickness"][k]),
        float(res["width"][k]),
        backlash,
        contact_deg=float(res["contact_deg"][k]),
        gap_low_deg=float(res["gap_low_deg"][k]),
        windup_deg=float(res["windup_deg"][k]),
        end=end,
    )


def contact_angles(res: dict, code: int, g_min: float, end: str, sense: str, step_deg: float = 0.5, arms: int = 1):
    """(contact, low) [deg] per row whose binding code is ``code``: the first wind-up at which the surrogate's
    coil gap closes / falls below ``g_min`` at the row's geometry (NaN elsewhere or never)."""
    contact = np.full(len(res["binding"]), np.nan)
    low = contact.copy()
    rows = np.nonzero(res["binding"] == code)[0]
    if rows.size == 0:
        return contact, low
    top = np.minimum(res["windup"][rows], fx.THETA_MAX)
    frac = np.linspace(0.0, 1.0, int(math.degrees(float(top.max())) / step_deg) + 2)
    theta = top[:, None] * frac[None, :]
    col = {k: res[k][rows][:, None] for k in ("inner_radius", "pitch", "turns", "thickness")}
    gap = fx.coil_gap(theta, col["inner_radius"], col["pitch"], col["turns"], col["thickness"], end, sense, arms)
    for out, lim in ((contact, 0.0), (low, g_min)):
        below = np.nan_to_num(gap, nan=np.inf) < lim
        hit = below.any(axis=1)
        out[rows[hit]] = np.degrees(theta[hit, np.argmax(below[hit], axis=1)])
    return contact, low
