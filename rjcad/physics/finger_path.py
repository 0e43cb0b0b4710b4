"""The finger's quasi-static closure along a tendon path, one compiled loop over its steps.

Each step starts from the previous angles ``prev`` and builds each joint's elastic torque over the step,
E_i + B_i·(θ_i − prev_i) [N·mm] (``spring_terms``): the spring K·(θ + θ0) with its preload θ0, a cubic stiffening
k3·(θ + θ0)³, viscous damping c·θ̇ and a Maxwell relaxation arm (dτ_M/dt = K_M·θ̇ − τ_M/T_r), the rate terms
linearised about ``prev`` over the step's Δt. The links' weight is then added:
1. coupled (``rjcad.physics.coupled.coupled_step``): the joints tied through the weight's full slope, Newton;
2. where that finds no equilibrium, each joint's own slope only (``own_slope_step``: the exact tendon solve of
   ``rjcad.physics.tendon_step`` re-linearised up to GRAVITY_ITERATIONS times), and Newton once more from there.
Without weight a step is one exact tendon solve. Units: mm, N, N·mm, rad, s.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rjcad.physics.coupled import GRAVITY_CONTRACTION, GRAVITY_TOL, coupled_step
from rjcad.physics.gravity import Weight, weight_torque
from rjcad.physics.tendon_step import Joints, solve_tendon

#: The weight's slope enters a step's linearisation down to −this × the joint's own step stiffness B (a weight
#: that softens a joint more than that tips it over: the step stays a step, the snap takes a few).
GRAVITY_SOFTENING = 0.9
#: Re-linearisations of the weight with each joint's own slope (the fallback), at most.
GRAVITY_ITERATIONS = 40


class Springs(NamedTuple):
    """The joints' elastic and rate constants as the compiled solver reads them: stiffness K [N·mm/rad], cubic
    stiffening k3 [N·mm/rad³], viscous damping c [N·mm·s/rad], Maxwell arm stiffness K_M [N·mm/rad] and its time
    constant T_r [s]."""

    K: np.ndarray
    k3: np.ndarray
    c: np.ndarray
    km: np.ndarray
    tr: float


@njit(cache=True, inline="always")
def spring_terms(
    prev: np.ndarray,
    tau_m: np.ndarray,
    a: float,
    b: float,
    inv_dt: float,
    K: np.ndarray,
    k3: np.ndarray,
    c: np.ndarray,
    km: np.ndarray,
    th0: np.ndarray,
    E: np.ndarray,
    B: np.ndarray,
) -> None:
    """The spring's part of the step: E = K·s + k3·s³ + a·τ_M [N·mm] and B = K + 3·k3·s² + c/Δt + K_M·b
    [N·mm/rad] with s = prev + θ0 (spring and preload, stiffening, damping, the Maxwell arm's exact update for a
    constant rate over the step: a = exp(−Δt/T_r), b = T_r(1 − a)/Δt; all rate terms 0 without times)."""
    for i in range(len(prev)):
        s = prev[i] + th0[i]
        E[i] = K[i] * s + k3[i] * s**3 + a * tau_m[i]
        B[i] = K[i] + 3.0 * k3[i] * s**2 + inv_dt * c[i] + km[i] * b


@njit(cache=True)
def own_slope_step(
    t_d: float,
    prev: np.ndarray,
    prev_T: float,
    at: np.ndarray,
    Es: np.ndarray,
    Bs: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    comp: float,
    wt: Weight,
    th: np.ndarray,
    E: np.ndarray,
    B: np.ndarray,
    tg: np.ndarray,
    slope: np.ndarray,
    bps: np.ndarray,
) -> tuple[float, bool]:
    """The step with each joint's own slope of the weight k_g = max(S_i, −GRAVITY_SOFTENING·B_i): the weight
    tg + k_g·(θ − at) re-linearised about the result (damped by half once the moves stop contracting) until no
    angle moves by more than GRAVITY_TOL, at most GRAVITY_ITERATIONS times: (T, slack), angles in ``th``; ``at``
    is overwritten. ``E``, ``B``, ``tg``, ``slope``, ``bps``: the path's scratch arrays (no allocation per step)."""
    n = len(prev)
    T, slack = 0.0, False
    last, w = math.inf, 1.0
    for _ in range(GRAVITY_ITERATIONS):
        weight_torque(at, wt, tg, slope)
        for i in range(n):
            kg = max(slope[i], -GRAVITY_SOFTENING * Bs[i])
            E[i] = Es[i] + tg[i] - kg * (at[i] - prev[i])
            B[i] = Bs[i] + kg
        T, slack = solve_tendon(t_d, prev, prev_T, E, B, jt, rc, comp, th, bps)
        moved = 0.0
        for i in range(n):
            moved = max(moved, abs(th[i] - at[i]))
        if moved <= GRAVITY_TOL:
            break
        if moved > GRAVITY_CONTRACTION * last:
            w = 0.5
        last = moved
        for i in range(n):
            at[i] = at[i] + w * (th[i] - at[i])
    return T, slack


@njit(cache=True)
def weighted_step(
    t_d: float,
    prev: np.ndarray,
    prev_T: float,
    at: np.ndarray,
    Es: np.ndarray,
    Bs: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    comp: float,
    wt: Weight,
    th: np.ndarray,
    coupled: bool,
    E: np.ndarray,
    B: np.ndarray,
    tg: np.ndarray,
    slope: np.ndarray,
    bps: np.ndarray,
) -> tuple[float, bool]:
    """A step with the links' weight: (T, slack), angles in ``th``. The joints coupled through the weight
    (``coupled_step``, Newton from ``at``) first; where that finds no equilibrium, each joint's own slope
    (``own_slope_step``), then Newton once more from its answer. ``coupled`` False: the own slope only."""
    if coupled:
        done, T, slack = coupled_step(t_d, prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th)
        if done:
            return T, slack
    T, slack = own_slope_step(t_d, prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th, E, B, tg, slope, bps)
    if coupled:  # near an equilibrium now: Newton from there again
        ok, T2, slack2 = coupled_step(t_d, prev, prev_T, th.copy(), Es, Bs, jt, rc, comp, wt, th)
        if ok:
            return T2, slack2
    return T, slack


@njit(cache=True, inline="always")
def _rate_factors(t: np.ndarray, k: int, tr: float) -> tuple[float, float, float]:
    """(a, b, 1/Δt) of step k (``spring_terms``), zeros without times or at the first step."""
    if len(t) == 0 or k == 0:
        return 0.0, 0.0, 0.0
    dt = t[k] - t[k - 1]
    a = math.exp(-dt / tr)
    return a, tr * (1.0 - a) / dt, 1.0 / dt


@njit(cache=True, nogil=True)
def closure_path(
    td: np.ndarray,
    t: np.ndarray,
    springs: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float],
    joints: tuple[np.ndarray, ...],
    c_pull: np.ndarray,
    c_release: np.ndarray,
    comp: float,
    weight: tuple[np.ndarray, np.ndarray, np.ndarray, float, float, bool],
    coupled: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(θ (steps, n) [rad], actuator tension (steps,) [N], slack (steps,)) along the tendon path ``td`` [mm] at
    times ``t`` [s] (empty: no rate terms). ``springs``, ``joints``, ``weight``: the fields of ``Springs``,
    ``Joints``, ``Weight`` as plain tuples (a plain tuple's type is found faster at each call); ``c_pull``,
    ``c_release``: the capstan factors reaching each joint while pulling and while releasing; ``comp`` = 1/k_t
    [mm/N]; ``coupled`` False: each joint's own slope of the weight only (a check value)."""
    sp, jt, wt = Springs(*springs), Joints(*joints), Weight(*weight)
    n_steps, n = len(td), len(sp.K)
    theta, tension = np.zeros((n_steps, n)), np.zeros(n_steps)
    slack = np.zeros(n_steps, np.bool_)
    prev, tau_m, at, th, rc = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    Es, Bs = np.zeros(n), np.zeros(n)
    E, B, tg, slope, bps = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(4 * n + 1)  # scratch
    r, thmax, km, gravity = jt.r, jt.thmax, sp.km, wt.on  # read once: the loop below runs per step
    pulling = True
    for k in range(n_steps):
        if k > 0 and td[k] != td[k - 1]:  # a hold keeps the direction
            pulling = td[k] > td[k - 1]
        for i in range(n):  # the tension reaching each joint: capstan losses one way or the other
            rc[i] = r[i] * (c_pull[i] if pulling else c_release[i])
        prev_T = tension[k - 1] if k > 0 else 0.0
        a, b, inv_dt = _rate_factors(t, k, sp.tr)
        spring_terms(prev, tau_m, a, b, inv_dt, sp.K, sp.k3, sp.c, km, jt.th0, Es, Bs)
        if not gravity:  # without weight: one exact tendon solve
            T, sl = solve_tendon(td[k], prev, prev_T, Es, Bs, jt, rc, comp, th, bps)
        else:  # the weight: the joints coupled through it (Newton) first, each joint's own slope as the fallback
            for i in range(n):  # Newton's first guess: the last two readings' extrapolation
                at[i] = min(max(2.0 * prev[i] - theta[k - 2, i], 0.0), thmax[i]) if k >= 2 else prev[i]
            T, sl = weighted_step(td[k], prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th, coupled, E, B, tg, slope, bps)
        for i in range(n):  # the Maxwell arm after the step, exact for a constant rate
            tau_m[i] = a * tau_m[i] + km[i] * b * (th[i] - prev[i])
            theta[k, i] = th[i]
            prev[i] = th[i]
        tension[k], slack[k] = T, sl
    return theta, tension, slack
