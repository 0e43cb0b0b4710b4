"""The full rod model's verdict on a design, and its bounded corrections (used by ``design_spring``).

:func:`verify` winds the design with the rod model (``SpringDesign.rod``) and, if the surrogate search
was optimistic, corrects it at most MAX_ADJUST times: a wider strip for stress (or, with a life
constraint, stress amplitude), a retuned length for stiffness, a coarser pitch for the coil gap, a
larger hub for the pin gap. What still fails is refused with one line naming the constraint.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from rjcad.errors import InfeasibleDesign
from rjcad.life.constraint import amplitude_limit
from rjcad.spring.design import STIFFNESS_TOLERANCE, SpringDesign
from rjcad.spring.formulas import turns_for_length
from rjcad.spring.messages import REPORT_NAMES, infeasible_message
from rjcad.spring.rod import RodSolveError

#: Rounds of adjustment after the rod model's verdict.
MAX_ADJUST = 3
#: Stiffness error the verification corrects (a fraction of the 0.5 % tolerance, leaving room).
RETUNE = 0.8 * STIFFNESS_TOLERANCE


def snap_up(x, step):
    """x rounded up to a whole multiple of ``step``."""
    return np.round(np.ceil(x / step - 1e-9) * step, 9)


def snap_down(x, step):
    """x rounded down to a whole multiple of ``step``."""
    return np.round(np.floor(x / step + 1e-9) * step, 9)


class RodRefusal(InfeasibleDesign):
    """The full rod model's check refused a design: ``value`` and ``limit`` of the failed constraint."""

    def __init__(self, constraint: str, message: str, value: float, limit: float):
        super().__init__(constraint, message)
        self.value, self.limit = float(value), float(limit)


def _retuned_length(L, k_ratio, prev):
    """Length that brings the rod's K to the target: K ∝ L^−e, e from the previous round (same b, p, r_in) or 1.

    e is not always 1: a pinned end's stiffness also moves with the fraction of a turn the length adds.
    """
    e = 1.0
    if prev is not None and prev[0] != L and prev[1] != k_ratio:
        e = float(np.clip(-math.log(k_ratio / prev[1]) / math.log(L / prev[0]), 0.3, 5.0))
    return L * k_ratio ** (1.0 / e)


def _adjusted(d: SpringDesign, prev):
    """One round of corrections from the rod model's verdict: (design, (L, K ratio)), or None if none is needed.

    Stress (or, with --min-cycles, stress amplitude) short: widen b (in layers, ≤ width_max) and
    lengthen L with it (K kept). Stiffness off by > RETUNE:
    retune L (:func:`_retuned_length`). Coil gap short: raise the pitch by 1.5× the shortfall.
    Pin gap short: raise r_in by 1.5× the shortfall.
    """
    req, rod = d.requirement, d.rod
    pr = req.printer_spec
    b, L, p, r_in = d.width, d.length, d.pitch, d.inner_radius
    k_ratio = rod.stiffness / req.spring_stiffness
    if not k_ratio > 0:  # the torque falls over the rotation: no length makes it a spring (refused by verify)
        return None
    if rod.peak_stress > req.allowed_stress * (1 + 1e-9):
        b_max = max(float(snap_down(req.width_max, pr.layer_height_mm)), b)
        b_new = min(float(snap_up(b * rod.peak_stress / req.allowed_stress, pr.layer_height_mm)), b_max)
        L, b = L * b_new / b, b_new
    if req.min_cycles is not None and d.predicted_life()[1] < req.min_cycles:  # σ_a ∝ 1/b at fixed K
        amp_max = float(amplitude_limit(req.min_cycles, d.thickness, req.backlash)[0])
        if 0 < amp_max < d.stress_amplitude:
            b_max = max(float(snap_down(req.width_max, pr.layer_height_mm)), b)
            b_new = min(float(snap_up(b * d.stress_amplitude / amp_max, pr.layer_height_mm)), b_max)
            L, b = L * b_new / b, b_new
    if abs(k_ratio - 1.0) > RETUNE:
        L = _retuned_length(L, k_ratio, prev if b == d.width else None)
    g = req.gap_min
    gap = d.min_coil_gap if d.min_key_gap is None else min(d.min_coil_gap, d.min_key_gap)
    if gap < g:
        p += 1.5 * (g - gap) + 1e-3
    if d.min_pin_gap is not None and d.min_pin_gap < g:
        r_in += 1.5 * (g - d.min_pin_gap) + 1e-3
    if (b, L, p, r_in) == (d.width, d.length, d.pitch, d.inner_radius):
        return None
    same = (b, p, r_in) == (d.width, d.pitch, d.inner_radius)
    return (
        replace(d, width=b, length=L, pitch=p, inner_radius=r_in, turns=float(turns_for_length(L, r_in, d.arms * p))),
        (d.length, k_ratio) if same else None,
    )


def verify(d: SpringDesign, adjust: bool = True) -> SpringDesign:
    """The design after the full rod model's verdict, or InfeasibleDesign naming the failed constraint.

    ``adjust``: correct it first, at most MAX_ADJUST times (:func:`_adjusted`); else judge it as it is.
    """
    prev = None
    try:
        for _ in range(MAX_ADJUST if adjust else 0):
            nxt = _adjusted(d, prev)
            if nxt is None:
                break
            d, prev = nxt
        report = d.constraint_report()
    except RodSolveError as e:
        raise RodRefusal("stiffness", _unstable_message(d, e.fraction), math.nan, STIFFNESS_TOLERANCE) from None
    failed = [k for k, (_, _, met) in report.items() if not met]
    if failed:
        name = min(failed, key=list(REPORT_NAMES).index)
        value, limit, _ = report[name]
        rod = d.rod
        if name == "stiffness_error" and not rod.stiffness > 0:
            raise RodRefusal("stiffness", _unstable_message(d, None), value, limit)
        raise RodRefusal(
            REPORT_NAMES[name],
            "rod-model check: "
            + infeasible_message(
                REPORT_NAMES[name],
                value,
                limit,
                d.thickness,
                d.width,
                d.requirement.backlash,
                contact_deg=_deg(rod.first_contact),
                gap_low_deg=_deg(rod.below(d.requirement.gap_min)),
                windup_deg=math.degrees(d.requirement.max_windup),
                end=d.end,
                rod=True,
            ),
            value,
            limit,
        )
    return d


def _unstable_message(d: SpringDesign, fraction: float | None) -> str:
    """One line: the rod model finds the strip snapping through (no equilibrium at ``fraction`` of the wind-up,
    or, with None, a torque that falls over the rotation)."""
    req = d.requirement
    windup = math.degrees(req.max_windup)
    where = (
        f"finds no equilibrium at {fraction * windup:.0f}° of the {windup:.0f}° wind-up"
        if fraction is not None
        else f"finds its torque falling over the rotation (K = {d.rod.stiffness:.3g} N·mm/rad)"
    )
    return (
        f"rod-model check: stiffness: the rod model {where} at t = {d.thickness:g} mm, b = {d.width:g} mm, "
        f"{d.turns:.2f} turns: the strip snaps through; lower the preload or the rotation, or raise --min-turns"
    )


def _deg(x):
    return math.nan if x is None else math.degrees(x)
