"""The rod model's factors for the optimiser and the life table: vectorised surrogate lookups.

One printed spiral (one arm), loaded in the joint's sense ``JOINT_SENSE`` (``unwind``: preload and
flexion open the printed spiral, issue #14). Every value comes from :mod:`rjcad.spring.surrogate`,
the table fitted to the large-rotation rod model :mod:`rjcad.spring.rod`:

* c = K / (E·b·t³/12L): small-wind-up stiffness ratio (1.009 clamped, 0.787 pinned, default spring);
* τ(θ) = T(θ)/(K·θ): how the torque curve bends at large wind-up;
* m = max|M|/T, the worst over 0..θ: peak stress σ = 6·m·T/(b·t²);
* the coil gap p·h(θ) − t and the pin gap, each the minimum over 0..θ.

``arms=2``: two interleaved arms 180° apart (rjcad.spring.rod); ``pitch`` is then each ARM's pitch (twice the
coil-to-coil pitch the table is indexed by), turns and factors are per arm, and the coil gap is between the
two arms' coils. Lengths in mm, angles in rad, stresses in MPa. Outside the table (r_in/p in [0.707, 16], turns in
[1, 20], θ in [0, 2π]) c, τ and m are taken at the nearest table edge (they vary slowly there) and
a spring of fewer than one turn is looked up as one turn (it has no neighbouring coil; the rod
model verifies it); the coil gap is NaN beyond 20 turns, outside the r_in/p range or beyond 2π.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from rjcad.spring import surrogate as sg

#: The sense in which the joint loads its printed springs (preload and flexion alike).
JOINT_SENSE = "unwind"
#: Spring arms per spiral the optimiser designs by default (one spiral per spring).
ARMS = 1
#: The table's domain: r_in/p (p the coil-to-coil pitch), turns per arm (one arm; a pair: PAIR_TURNS_RANGE), θ.
RHO_RANGE = (2.0**-0.5, 16.0)
TURNS_RANGE = (1.0, 20.0)
PAIR_TURNS_RANGE = (0.5, 10.0)
THETA_MAX = 2.0 * math.pi
#: Stress factor m taken where the table has a hole (the rod model then checks the design): above the
#: worst the table holds for one arm (clamped 1.09–1.20, pinned ≈ 1.95–2.1).
FALLBACK_M = {"clamped": 1.3, "pinned": 2.3}


@functools.cache
def use_margin(end: str, sense: str = JOINT_SENSE, arms: int = ARMS) -> bool:
    """Whether the table carries its fitted error margins for (end, sense): the shipped one does.

    A trial table written by ``tools/make_spring_surrogate.py`` on part of the grid may not; its raw
    lookup is then used (the rod model still verifies every design).
    """
    try:
        sg.gap_ratio_min(0.5, 4.0, 5.0, end=end, sense=sense, arms=arms)
    except KeyError:
        return False
    return True


def turns_range(arms: int = ARMS) -> tuple[float, float]:
    """The table's turns per arm: (1, 20) for one arm, (0.5, 10) for a pair."""
    return TURNS_RANGE if arms == 1 else PAIR_TURNS_RANGE


def _clip(rho, turns, arms=ARMS):
    return np.clip(rho, *RHO_RANGE), np.clip(turns, *turns_range(arms))


def _rho(r_in, pitch, arms):
    """r_in over the coil-to-coil pitch (the arm's pitch over the arms)."""
    return np.asarray(r_in) / (np.asarray(pitch) / arms)


def stiffness_ratio(r_in, pitch, turns, end: str, arms: int = ARMS):
    """c = K_rod / (arms·E·b·t³/12L_arm) at small wind-up (either sense)."""
    rho, n = _clip(_rho(r_in, pitch, arms), turns, arms)
    return sg.stiffness_ratio(rho, n, end=end, arms=arms)


def torque_ratio(theta, r_in, pitch, turns, end: str, sense: str = JOINT_SENSE, arms: int = ARMS):
    """τ(θ) = T(θ) / (K·θ) (1 at small θ)."""
    rho, n = _clip(_rho(r_in, pitch, arms), turns, arms)
    return sg.torque_ratio(np.clip(theta, 0.0, THETA_MAX), rho, n, end=end, sense=sense, arms=arms)


def stress_factor(theta, r_in, pitch, turns, end: str, sense: str = JOINT_SENSE, arms: int = ARMS):
    """m: the worst max|M|/T of one arm over 0..θ (conservative margin included)."""
    rho, n = _clip(_rho(r_in, pitch, arms), turns, arms)
    return sg.stress_factor(
        rho, n, np.clip(theta, 0.0, THETA_MAX), end=end, sense=sense, arms=arms, margin=use_margin(end, sense, arms)
    )


def coil_gap(theta, r_in, pitch, turns, t, end: str, sense: str = JOINT_SENSE, arms: int = ARMS):
    """Smallest coil gap over 0..θ [mm], p·h − t; NaN outside the table (fewer than 1 turn: as 1 turn)."""
    n = np.maximum(turns, turns_range(arms)[0])
    p = np.asarray(pitch) / arms
    return sg.coil_gap(theta, r_in, p, n, t, end=end, sense=sense, arms=arms, margin=use_margin(end, sense, arms))


def pin_gap(theta, r_in, pitch, turns, t, pin_radius, end: str, sense: str = JOINT_SENSE, arms: int = ARMS):
    """Smallest gap between the strip and the pin over 0..θ [mm] (NaN outside the table)."""
    n = np.maximum(turns, turns_range(arms)[0])
    p = np.asarray(pitch) / arms
    return sg.pin_gap(
        theta, r_in, p, n, t, pin_radius, end=end, sense=sense, arms=arms, margin=use_margin(end, sense, arms)
    )


def effective_factor(preload, rotation, r_in, pitch, turns, end: str, sense: str = JOINT_SENSE, arms: int = ARMS):
    """g = (θ_max·τ(θ_max) − θ_p·τ(θ_p)) / rotation: the working-range slope over the small-wind-up K."""
    theta = preload + rotation
    tp = torque_ratio(preload, r_in, pitch, turns, end, sense, arms)
    tm = torque_ratio(theta, r_in, pitch, turns, end, sense, arms)
    return (theta * tm - preload * tp) / rotation


def cycle_stresses(
    E,
    b,
    t,
    L,
    r_in,
    pitch,
    turns,
    preload,
    rotation,
    end: str,
    sense: str = JOINT_SENSE,
    fill: bool = False,
    arms: int = ARMS,
):
    """(K_eff, peak, amplitude) of one arm cycled preload → preload + rotation [N·mm/rad, MPa, MPa].

    K = c·E·b·t³/(12L); T(θ) = K·θ·τ(θ); σ(θ) = 6·m·T(θ)/(b·t²) with m the worst factor over the
    cycle; K_eff = (T(θ_max) − T(θ_p))/rotation; peak σ(θ_max); amplitude (σ(θ_max) − σ(θ_p))/2.
    ``fill``: where the table has a hole, τ = 1 and m = FALLBACK_M (else NaN there).
    """
    theta = preload + rotation
    tau_max = torque_ratio(theta, r_in, pitch, turns, end, sense, arms)
    tau_pre = torque_ratio(preload, r_in, pitch, turns, end, sense, arms)
    m = stress_factor(theta, r_in, pitch, turns, end, sense, arms)
    if fill:
        tau_max, tau_pre = np.nan_to_num(tau_max, nan=1.0), np.nan_to_num(tau_pre, nan=1.0)
        m = np.nan_to_num(m, nan=FALLBACK_M[end])
    K = stiffness_ratio(r_in, pitch, turns, end, arms) * E * b * t**3 / (12.0 * L)
    T_max = K * theta * tau_max
    T_pre = K * preload * tau_pre
    unit = 6.0 * m / (b * t**2)
    return (T_max - T_pre) / rotation, unit * T_max, unit * (T_max - T_pre) / 2.0


__all__ = [
    "ARMS",
    "FALLBACK_M",
    "JOINT_SENSE",
    "PAIR_TURNS_RANGE",
    "RHO_RANGE",
    "THETA_MAX",
    "TURNS_RANGE",
    "coil_gap",
    "cycle_stresses",
    "effective_factor",
    "pin_gap",
    "stiffness_ratio",
    "stress_factor",
    "torque_ratio",
    "turns_range",
    "use_margin",
]
