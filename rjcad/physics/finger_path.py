"""The finger's quasi-static closure along a tendon path, one compiled loop over its steps.

Each step starts from the previous angles ``prev`` and builds each joint's elastic torque over the step,
E_i + B_i·(θ_i − prev_i) [N·mm] (``spring_terms``): the spring K·(θ + θ0) with its preload θ0, a cubic stiffening
k3·(θ + θ0)³, viscous damping c·θ̇ and a Maxwell relaxation arm (dτ_M/dt = K_M·θ̇ − τ_M/T_r), the rate terms
linearised about ``prev`` over the step's Δt. The links' weight is then added:
1. coupled (``rjcad.physics.coupled.coupled_step``): the joints tied through the weight's full slope, Newton;
2. where that finds no equilibrium (``fallback_step``), each joint's own slope only (``own_slope_step``: the exact
   tendon solve of ``rjcad.physics.tendon_step`` re-linearised up to GRAVITY_ITERATIONS times), and Newton once
   more from there.
Without weight a step is one exact tendon solve. Units: mm, N, N·mm, rad, s.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rjcad.physics.coupled import GRAVITY_CONTRACTION, GRAVITY_TOL, CoupledWork, coupled_step, coupled_work
from rjcad.physics.gravity import Weight, weight_frame, weight_torque
from rjcad.physics.kernel import inline_kernel, kernel, path_kernel
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


class StepWork(NamedTuple):
    """A step's scratch, made once per path by ``step_work``: a step allocates nothing."""

    E: np.ndarray  # (n,) the step's torque at prev with the weight (each joint's own slope) [N·mm] ...
    B: np.ndarray  # (n,) ... and its slope [N·mm/rad]
    tg: np.ndarray  # (n,) the weight's torque [N·mm] ...
    slope: np.ndarray  # (n,) ... and its slope in each joint's own angle [N·mm/rad]
    frame: np.ndarray  # (4, n + 1): ``weight_torque``'s scratch
    bps: np.ndarray  # (4n + 1,): the tendon solve's breakpoints
    coupled: CoupledWork


@kernel
def step_work(n: int) -> StepWork:
    """A ``StepWork`` for n joints."""
    return StepWork(
        np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), weight_frame(n), np.zeros(4 * n + 1), coupled_work(n)
    )


@inline_kernel
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


@kernel
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
    w: StepWork,
) -> tuple[float, bool]:
    """The step with each joint's own slope of the weight k_g = max(S_i, −GRAVITY_SOFTENING·B_i): the weight
    tg + k_g·(θ − at) re-linearised about the result (damped by half once the moves stop contracting) until no
    angle moves by more than GRAVITY_TOL, at most GRAVITY_ITERATIONS times: (T, slack), angles in ``th``; ``at``
    is overwritten. ``w``: the path's scratch."""
    n = len(prev)
    E, B, tg, slope = w.E, w.B, w.tg, w.slope
    T, slack = 0.0, False
    last, step = math.inf, 1.0
    for _ in range(GRAVITY_ITERATIONS):
        weight_torque(at, wt, tg, slope, w.frame)
        for i in range(n):
            kg = max(slope[i], -GRAVITY_SOFTENING * Bs[i])
            E[i] = Es[i] + tg[i] - kg * (at[i] - prev[i])
            B[i] = Bs[i] + kg
        T, slack = solve_tendon(t_d, prev, prev_T, E, B, jt, rc, comp, th, w.bps)
        moved = 0.0
        for i in range(n):
            moved = max(moved, abs(th[i] - at[i]))
        if moved <= GRAVITY_TOL:
            break
        if moved > GRAVITY_CONTRACTION * last:
            step = 0.5
        last = moved
        for i in range(n):
            at[i] = at[i] + step * (th[i] - at[i])
    return T, slack


@kernel
def fallback_step(
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
    w: StepWork,
) -> tuple[float, bool]:
    """A step with the links' weight where ``coupled_step`` found no equilibrium from ``at``: each joint's own slope
    (``own_slope_step``), then Newton once more from its answer (``coupled`` False: the own slope only). (T, slack),
    angles in ``th``; ``at`` is overwritten; ``w``: the path's scratch."""
    T, slack = own_slope_step(t_d, prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th, w)
    if coupled:  # near an equilibrium now: Newton from there again
        at[:] = th
        ok, T2, slack2 = coupled_step(t_d, prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th, w.coupled)
        if ok:
            return T2, slack2
    return T, slack


@inline_kernel
def _rate_factors(t: np.ndarray, k: int, tr: float) -> tuple[float, float, float]:
    """(a, b, 1/Δt) of step k (``spring_terms``), zeros without times or at the first step."""
    if len(t) == 0 or k == 0:
        return 0.0, 0.0, 0.0
    dt = t[k] - t[k - 1]
    a = math.exp(-dt / tr)
    return a, tr * (1.0 - a) / dt, 1.0 / dt


@path_kernel
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
    w = step_work(n)
    cw, bps = w.coupled, w.bps  # read once: a field read per step costs a reference count per array in it
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
            done, T, sl = False, 0.0, False
            if coupled:
                done, T, sl = coupled_step(td[k], prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th, cw)
            if not done:
                T, sl = fallback_step(td[k], prev, prev_T, at, Es, Bs, jt, rc, comp, wt, th, coupled, w)
        for i in range(n):  # the Maxwell arm after the step, exact for a constant rate
            tau_m[i] = a * tau_m[i] + km[i] * b * (th[i] - prev[i])
            theta[k, i] = th[i]
            prev[i] = th[i]
        tension[k], slack[k] = T, sl
    return theta, tension, slack
