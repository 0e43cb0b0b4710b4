"""One quasi-static step of the finger with each joint on its own: the tendon tension that meets the tendon's
length, solved exactly (compiled).

Each joint's elastic torque over the step is E_i + B_i·(θ_i − prev_i) [N·mm] (spring, preload, rate terms and
the weight linearised about the previous angles: ``rjcad.physics.finger_path``). Joint i feels the tension
r_i·c_i·T [N·mm] (c_i: the capstan factor of the tendon's path before it, ``rjcad.physics.finger``) and
- sticks (θ = prev) while r·c·T lies inside its friction band E − f0 − γ⁻·s … E + f0 + γ⁺·s (s = prev + θ0);
- slides closed on the band's upper edge, r·c·T = E + B·(θ − prev) + f0 + γ⁺·(θ + θ0), above it;
- slides open on the lower edge, r·c·T = E + B·(θ − prev) − f0 − γ⁻·(θ + θ0), below it;
- stays within its stops 0 ≤ θ ≤ θmax.
So every θ_i(T) is non-decreasing and piecewise linear in T, and so is the take-up S(T) = Σ r_i·θ_i(T) + T/k_t:
S(T) = t_d is solved exactly between its breakpoints. When even T = 0 takes up more than t_d, the tendon is slack.
Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rjcad.physics.kernel import inline_kernel

#: Σ r·θ within this of t_d [mm] (× max(1, t_d)) counts as meeting it: where every joint sticks, S(T) is flat and
#: the tension anywhere on that flat stretch solves the constraint.
FLAT_MM = 1e-7


class Joints(NamedTuple):
    """The joints' constants as the compiled solver reads them (arrays, proximal first): preload θ0 and range
    θmax [rad], tendon moment arm r [mm], constant friction f0 [N·mm] and tendon-induced friction γ⁺ (closing),
    γ⁻ (opening) [N·mm/rad]."""

    th0: np.ndarray
    thmax: np.ndarray
    r: np.ndarray
    f0: np.ndarray
    gp: np.ndarray
    gn: np.ndarray


@inline_kernel
def angles_at_tension(
    T: float, prev: np.ndarray, E: np.ndarray, B: np.ndarray, jt: Joints, rc: np.ndarray, out: np.ndarray
) -> None:
    """Fills ``out`` with θ_i(T) [rad]: stick inside the band, slide on its edge beyond it, clipped to the stops.

    Closing edge: θ = (r·c·T − E − f0 − γ⁺·θ0 + B·prev) / (B + γ⁺); opening edge: the same with −f0, +γ⁻·θ0,
    B − γ⁻.
    """
    th0, thmax, f0, gp, gn = jt.th0, jt.thmax, jt.f0, jt.gp, jt.gn
    for i in range(len(E)):
        s = prev[i] + th0[i]  # the spring's wind-up at the step's start [rad]
        up_T = (E[i] + f0[i] + gp[i] * s) / rc[i]  # the tension that starts the joint closing [N]
        dn_T = (E[i] - f0[i] - gn[i] * s) / rc[i]  # ... and below which it opens [N]
        if T >= up_T:
            th = max((rc[i] * T - E[i] - f0[i] - gp[i] * th0[i] + B[i] * prev[i]) / (B[i] + gp[i]), prev[i])
        elif T <= dn_T:
            th = min((rc[i] * T - E[i] + f0[i] + gn[i] * th0[i] + B[i] * prev[i]) / (B[i] - gn[i]), prev[i])
        else:  # sticking: friction holds the joint where it was
            th = prev[i]
        out[i] = min(max(th, 0.0), thmax[i])


@inline_kernel
def take_up(
    T: float, prev: np.ndarray, E: np.ndarray, B: np.ndarray, jt: Joints, rc: np.ndarray, comp: float, th: np.ndarray
) -> float:
    """S(T) = T/k_t + Σ r·θ(T): the tendon displacement the tendon's stretch and the joints take up at tension T
    [mm] (``comp`` = 1/k_t [mm/N]); leaves θ(T) in ``th``."""
    angles_at_tension(T, prev, E, B, jt, rc, th)
    r = jt.r
    S = comp * T
    for i in range(len(E)):
        S += r[i] * th[i]
    return S


@inline_kernel
def _sort_prefix(a: np.ndarray, m: int) -> None:
    """Insertion sort of a[:m] in place (a dozen breakpoints: no allocation; duplicates are harmless)."""
    for i in range(1, m):
        v = a[i]
        j = i - 1
        while j >= 0 and a[j] > v:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = v


@inline_kernel
def tension_breakpoints(
    prev: np.ndarray, E: np.ndarray, B: np.ndarray, jt: Joints, rc: np.ndarray, bps: np.ndarray
) -> int:
    """Writes 0 and the tensions [N] where some θ_i(T) changes slope (starts closing, starts opening, reaches its
    upper stop, its lower stop; clipped at 0) into ``bps``, sorted; returns how many."""
    th0, thmax, f0, gp, gn = jt.th0, jt.thmax, jt.f0, jt.gp, jt.gn
    m = 1
    bps[0] = 0.0
    for i in range(len(E)):
        s = prev[i] + th0[i]
        cand = (
            (E[i] + f0[i] + gp[i] * s) / rc[i],  # starts closing
            (E[i] - f0[i] - gn[i] * s) / rc[i],  # starts opening
            (E[i] + B[i] * (thmax[i] - prev[i]) + f0[i] + gp[i] * (thmax[i] + th0[i])) / rc[i],  # upper stop
            (E[i] - B[i] * prev[i] - f0[i] - gn[i] * th0[i]) / rc[i],
        )  # lower stop
        for v in cand:
            if math.isfinite(v):
                bps[m] = max(v, 0.0)
                m += 1
    _sort_prefix(bps, m)
    return m


@inline_kernel
def solve_tendon(
    t_d: float,
    prev: np.ndarray,
    prev_T: float,
    E: np.ndarray,
    B: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    comp: float,
    th: np.ndarray,
    bps: np.ndarray,
) -> tuple[float, bool]:
    """(T [N], slack) with S(T) = t_d (``take_up``); fills ``th`` with the angles. ``bps``: scratch of 4n + 1.

    Slack (T = 0) where the joints at T = 0 already take up t_d. Beyond the last breakpoint only the tendon
    stretches (or, inextensible, the finger is on its stops). On a flat stretch of S (every joint sticking) the
    tension stays as close to ``prev_T`` as the stretch allows: nothing moved, so nothing changed.
    """
    if not take_up(0.0, prev, E, B, jt, rc, 0.0, th) < t_d:
        return 0.0, True
    grid = bps[: tension_breakpoints(prev, E, B, jt, rc, bps)]
    tol = FLAT_MM * max(1.0, abs(t_d))
    # the first grid tension whose take-up reaches t_d − tol: S never decreases, so bisect
    g_lo, g_hi = 0, len(grid)  # S(grid[g]) < t_d − tol for g < g_lo; ≥ for g ≥ g_hi
    S_hi = 0.0
    while g_lo < g_hi:
        mid = (g_lo + g_hi) // 2
        S_mid = take_up(grid[mid], prev, E, B, jt, rc, comp, th)
        if S_mid >= t_d - tol:
            g_hi, S_hi = mid, S_mid
        else:
            g_lo = mid + 1
    if g_lo == len(grid):  # past every breakpoint
        S_last = take_up(grid[-1], prev, E, B, jt, rc, comp, th)
        T = grid[-1] if comp == 0.0 else grid[-1] + (t_d - S_last) / comp
    elif S_hi <= t_d + tol:  # met at grid[k], and on along a flat stretch: keep the previous tension if on it
        k = g_lo
        hi = grid[k]
        for g in range(k + 1, len(grid)):
            if take_up(grid[g], prev, E, B, jt, rc, comp, th) > t_d + tol:
                break
            hi = grid[g]
        T = min(max(prev_T, grid[k]), hi)
    else:  # passed between grid[k − 1] and grid[k]: S is linear there
        k = g_lo
        S_lo = take_up(grid[k - 1], prev, E, B, jt, rc, comp, th)
        T = grid[k - 1] + (t_d - S_lo) * (grid[k] - grid[k - 1]) / (S_hi - S_lo)
    angles_at_tension(T, prev, E, B, jt, rc, th)
    return T, False
