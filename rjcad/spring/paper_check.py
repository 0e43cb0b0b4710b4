"""The paper's joint through the rod model: the only stiffness measurement there is (issue #14).

The paper designed its joint's springs with the clamped formula K = E·b·t³/(12L) for 5.2 N·mm/rad
(two springs of 2.6), b = 4.8 mm, ABSplus-P430, on a Dimension Elite, and measured 5.19. It does
not give t, the pitch or the inner radius: :func:`paper_spring` takes them from rjcad's optimiser on
that printer with b held at 4.8 mm, and the length from the paper's formula. The rod model then
gives the joint's stiffness (both springs) with either end: the slope over the measured joint's
working range (70° preload, 90° rotation, in the designer's unwinding sense) and at small wind-up.
:func:`table_i_spread` repeats it for the pitch/thickness pairs of the paper's Table I (r_in 3 mm).
Units: mm, N·mm/rad, rad.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from rjcad.materials import get_material, get_printer
from rjcad.paper import JOINT
from rjcad.spring import rod
from rjcad.spring.factors import JOINT_SENSE
from rjcad.spring.formulas import turns_for_length

#: The paper's joint: width [mm], material, printer, rotation of the stiffness test [rad].
WIDTH, MATERIAL, PRINTER, ROTATION = 4.8, "absplus-p430", "dimension-elite", math.radians(90.0)
#: Table I's (pitch, thickness) pairs [mm].
TABLE_I_PAIRS = ((1.6, 1.0), (1.0, 0.8), (1.67, 0.8), (1.67, 1.0), (1.0, 0.5))


def paper_length(t: float) -> float:
    """L = E·b·t³/(12·K) for one spring of K = 5.2/2 (the paper's clamped formula) [mm]."""
    E = get_material(MATERIAL).youngs_modulus_mpa
    return E * WIDTH * t**3 / (12.0 * JOINT.designed_stiffness / 2.0)


@functools.lru_cache(maxsize=1)
def paper_spring() -> dict:
    """The paper's spring: t, r_in and pitch as rjcad's optimiser picks them (b held at 4.8 mm), L by formula."""
    from rjcad.spring.optimise import optimise_arrays  # the optimiser imports rjcad.life, which imports factors

    res = optimise_arrays(
        JOINT.designed_stiffness / 2,
        JOINT.preload + ROTATION,
        material=get_material(MATERIAL),
        printer=get_printer(PRINTER),
        allowed_stress=get_material(MATERIAL).yield_strength_mpa / 1.5,
        width_min=WIDTH,
        width_max=WIDTH + 0.1,
        rotation=ROTATION,
    )
    t, r_in, p = (float(res[k][0]) for k in ("thickness", "inner_radius", "pitch"))
    L = paper_length(t)
    return dict(t=t, r_in=r_in, pitch=p, length=L, turns=float(turns_for_length(L, r_in, p)), b=WIDTH)


def joint_stiffness(r_in, pitch, t, end: str, preload=JOINT.preload, rotation=ROTATION) -> tuple[float, float]:
    """(working-range slope, small-wind-up stiffness) of the joint (two springs), rod model [N·mm/rad]."""
    E = get_material(MATERIAL).youngs_modulus_mpa
    L = paper_length(t)
    n = float(turns_for_length(L, r_in, pitch))
    res = rod.spiral_windup(
        r_in,
        pitch,
        n,
        WIDTH,
        t,
        E,
        end=end,
        sense=JOINT_SENSE,
        theta_max=preload + rotation,
        steps=max(8, math.ceil((preload + rotation) / math.radians(5.0))),
    )
    slope = (res.torque[-1] - np.interp(preload, res.theta, res.torque)) / rotation
    small = rod.stiffness_ratio(r_in, pitch, n, t, end=end) * E * WIDTH * t**3 / (12.0 * L)
    return 2.0 * float(slope), 2.0 * float(small)


def paper_check() -> dict:
    """The paper's spring per end: joint stiffness (slope, small wind-up) and the error against 5.19 measured."""
    s = paper_spring()
    out = {"measured": JOINT.stiffness, "designed": JOINT.designed_stiffness, "spring": s}
    for end in ("clamped", "pinned"):
        slope, small = joint_stiffness(s["r_in"], s["pitch"], s["t"], end)
        out[end] = dict(
            slope=slope,
            small=small,
            slope_error=slope / JOINT.stiffness - 1.0,
            small_error=small / JOINT.stiffness - 1.0,
        )
    return out


def table_i_spread(r_in: float = 3.0) -> list[dict]:
    """The same check for each of Table I's (pitch, t) pairs, L from the paper's formula."""
    rows = []
    for pitch, t in TABLE_I_PAIRS:
        row: dict[str, Any] = dict(pitch=pitch, t=t, length=paper_length(t))
        for end in ("clamped", "pinned"):
            slope, small = joint_stiffness(r_in, pitch, t, end)
            row[end] = dict(slope_error=slope / JOINT.stiffness - 1.0, small_error=small / JOINT.stiffness - 1.0)
        rows.append(row)
    return rows
