"""One step of the finger with the links' weight, the joints coupled through the weight's full slope (compiled).

The weight's torque about joint i depends on every angle: turning joint j turns every link beyond it, so
∂τ_i/∂θ_j = S_max(i,j), S_k being joint k's own slope (``rjcad.physics.gravity.weight_torque``). Linearised about
the angles ``at``, joint i's torque over the step is E_i + Σ_j H_ij (θ_j − prev_j), H = diag(B) + G with
G_ij = S_max(i,j) [N·mm/rad]. Each joint then sticks (θ = prev), slides closed on its band's upper edge
r_i·c_i·T − torque_i = f0 + γ⁺(θ + θ0), slides open on the lower edge (−f0 − γ⁻(θ + θ0)), or rests on a stop it
reached in this step; the tendon ties them: r·θ + T/k_t = t_d, or it is slack (T = 0, r·θ ≥ t_d). For a guess of
what each joint does, that is one linear system in the sliding joints' angles and T. The guess is corrected one
joint at a time (first a sliding joint that moved the wrong way or through its stop, then a fixed joint past its
band's edge, the lowest-numbered first) until every condition holds. Re-linearising the weight about the
result is Newton's method on the step.

Where the weight beats the springs (H not positive definite: the finger would snap), a step may have no solution
near the previous angles, and Newton's steps grow instead of shrinking. The step then adds λ(θ − at) to every
joint's torque, λ making H + λI positive definite (its smallest eigenvalue GRAVITY_MARGIN × the joints' smallest
B): each iteration is then a proximal step towards a stable equilibrium, and the added torque vanishes once
θ = at. A joint's own slope alone (a diagonal H, ``rjcad.physics.finger_path``'s fallback) misses that joints
sliding against softening weights trade angle at nearly no cost in weight: that iteration hands the whole step
to one joint, then to the other, and never settles. Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rjcad.physics.gravity import Weight, weight_torque
from rjcad.physics.tendon_step import FLAT_MM, Joints

#: A joint's state in the step: sticking, sliding closed, sliding open, on its lower stop, on its upper stop.
STICK, UP, DOWN, LOW, HIGH = 0, 1, -1, 2, 3
#: ``first_violation``'s answers that are not a joint: the step is consistent; no joint can move.
CONSISTENT, STUCK = -1, -2
#: At most this many corrections of the joints' states in one linearised step (beyond: no solution found).
MAX_PIVOTS = 24
#: A fixed joint's torque may pass its band's edge by this much [N·mm] (the linear solve's rounding).
TORQUE_TOL = 1e-9
#: A sliding joint may move the wrong way by this much [rad] (the linear solve's rounding: a joint that the
#: tendon holds where it was moves by ±1e-17, and calling that a wrong way sends it back and forth between
#: sliding and sticking instead of letting the tendon go slack).
MOVE_TOL = 1e-12
#: Newton on the weight: up to COUPLED_ITERATIONS linearisations until no angle moves by more than GRAVITY_TOL
#: [rad]; once a move is not at most GRAVITY_CONTRACTION of the one before, proximal steps with H + λI's smallest
#: eigenvalue GRAVITY_MARGIN × min(B).
COUPLED_ITERATIONS = 200
GRAVITY_TOL = 1e-7
GRAVITY_CONTRACTION = 0.5
GRAVITY_MARGIN = 0.5
#: A pivot smaller than this × the matrix's largest entry counts as zero (a singular system).
SINGULAR = 1e-13


@njit(cache=True)
def gauss(A: np.ndarray, b: np.ndarray, x: np.ndarray) -> bool:
    """Solves A·x = b by Gaussian elimination with partial pivoting (A and b are overwritten); False if singular."""
    k = len(b)
    scale = 0.0
    for i in range(k):
        for j in range(k):
            scale = max(scale, abs(A[i, j]))
    for c in range(k):
        p = c
        for i in range(c + 1, k):
            if abs(A[i, c]) > abs(A[p, c]):
                p = i
        if scale == 0.0 or abs(A[p, c]) <= SINGULAR * scale:
            return False
        for j in range(k):
            A[c, j], A[p, j] = A[p, j], A[c, j]
        b[c], b[p] = b[p], b[c]
        for i in range(c + 1, k):
            f = A[i, c] / A[c, c]
            if f != 0.0:
                for j in range(c, k):
                    A[i, j] -= f * A[c, j]
                b[i] -= f * b[c]
    for c in range(k - 1, -1, -1):
        v = b[c]
        for j in range(c + 1, k):
            v -= A[c, j] * x[j]
        x[c] = v / A[c, c]
    return True


@njit(cache=True)
def joint_torque(E: np.ndarray, H: np.ndarray, d: np.ndarray, i: int) -> float:
    """Joint i's elastic torque with the weight after the moves d = θ − prev: E_i + Σ_j H_ij·d_j [N·mm]."""
    v: float = E[i]
    for j in range(len(d)):
        if d[j] != 0.0:
            v += H[i, j] * d[j]
    return v


@njit(cache=True)
def _up_edge(i: int, torque: float, s: np.ndarray, jt: Joints, rc: np.ndarray) -> float:
    """The tension [N] at which joint i, sticking with elastic torque ``torque``, starts closing."""
    edge: float = (torque + jt.f0[i] + jt.gp[i] * s[i]) / rc[i]
    return edge


@njit(cache=True)
def _down_edge(i: int, torque: float, s: np.ndarray, jt: Joints, rc: np.ndarray) -> float:
    """The tension [N] below which joint i, sticking with elastic torque ``torque``, starts opening."""
    edge: float = (torque - jt.f0[i] - jt.gn[i] * s[i]) / rc[i]
    return edge


@njit(cache=True)
def solve_states(
    state: np.ndarray,
    slack: bool,
    t_d: float,
    prev: np.ndarray,
    E: np.ndarray,
    H: np.ndarray,
    s: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    comp: float,
    d: np.ndarray,
) -> tuple[int, float]:
    """Fills d = θ − prev for the joints' states ``state``; returns (0, 0) where singular, (1, T) with the tension
    set, (2, 0) where no joint slides on an inextensible tendon (the tension is then not set by the tendon).

    Each sliding joint: −Σ_j H_ij·d_j ∓ γ·d_i + r_i·c_i·T = E_i ± (f0 + γ·s_i) (its band's edge); the tendon:
    Σ r_j·d_j + T/k_t = t_d − Σ r·prev (dropped when slack).
    """
    n = len(prev)
    free = np.empty(n, np.int64)  # the sliding joints
    k = 0
    for i in range(n):
        d[i] = -prev[i] if state[i] == LOW else (jt.thmax[i] - prev[i] if state[i] == HIGH else 0.0)
        if state[i] == UP or state[i] == DOWN:
            free[k] = i
            k += 1
    if k == 0 and (slack or comp == 0.0):
        return (1, 0.0) if slack else (2, 0.0)
    size = k if slack else k + 1
    A = np.zeros((size, size))
    b = np.zeros(size)
    x = np.zeros(size)
    for a in range(k):
        i = free[a]
        for c in range(k):
            A[a, c] = -H[i, free[c]]
        fixed = joint_torque(E, H, d, i)
        if state[i] == UP:
            A[a, a] -= jt.gp[i]
            b[a] = fixed + jt.f0[i] + jt.gp[i] * s[i]
        else:
            A[a, a] += jt.gn[i]
            b[a] = fixed - jt.f0[i] - jt.gn[i] * s[i]
        if not slack:
            A[a, k] = rc[i]
    if not slack:
        for c in range(k):
            A[k, c] = jt.r[free[c]]
        A[k, k] = comp
        v = t_d
        for j in range(n):
            v -= jt.r[j] * (prev[j] + d[j])
        b[k] = v
    if not gauss(A, b, x):
        return 0, 0.0
    for a in range(size):
        if not math.isfinite(x[a]):
            return 0, 0.0
    for a in range(k):
        d[free[a]] = x[a]
    return 1, (0.0 if slack else x[k])


@njit(cache=True)
def _wrong_move(state: np.ndarray, prev: np.ndarray, thmax: np.ndarray, d: np.ndarray) -> tuple[int, int]:
    """(joint, new state) for the first sliding joint that moved the wrong way or through its stop."""
    for i in range(len(prev)):
        if state[i] == UP:
            if d[i] < -MOVE_TOL:
                return i, STICK
            if prev[i] + d[i] > thmax[i]:
                return i, HIGH
        elif state[i] == DOWN:
            if d[i] > MOVE_TOL:
                return i, STICK
            if prev[i] + d[i] < 0:
                return i, LOW
    return CONSISTENT, 0


@njit(cache=True)
def _length_violation(
    state: np.ndarray,
    t_d: float,
    tol: float,
    prev: np.ndarray,
    E: np.ndarray,
    H: np.ndarray,
    s: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    d: np.ndarray,
) -> tuple[int, int]:
    """Every joint fixed on an inextensible tendon: its length is set by the joints. Too short a take-up: the
    tension rises until the first sticking joint starts to close; too long: the last one to open opens, or the
    tendon goes slack (joint n). (joint, new state), or (CONSISTENT, 0), or (STUCK, 0): nothing can close."""
    n = len(prev)
    short = -t_d  # > 0: more tendon held than t_d [mm]
    for j in range(n):
        short += jt.r[j] * (prev[j] + d[j])
    if abs(short) <= tol:
        return CONSISTENT, 0
    best, bi = 0.0, -1
    if short < 0:
        for i in range(n):
            if state[i] == STICK and prev[i] < jt.thmax[i]:
                e = _up_edge(i, joint_torque(E, H, d, i), s, jt, rc)
                if bi < 0 or e < best:
                    best, bi = e, i
        return (bi, UP) if bi >= 0 else (STUCK, 0)
    for i in range(n):
        if state[i] == STICK and prev[i] > 0:
            e = _down_edge(i, joint_torque(E, H, d, i), s, jt, rc)
            if e > 0 and (bi < 0 or e >= best):
                best, bi = e, i
    return (bi, DOWN) if bi >= 0 else (n, 1)


@njit(cache=True)
def first_violation(
    state: np.ndarray,
    slack: bool,
    T_set: bool,
    T: float,
    t_d: float,
    tol: float,
    prev: np.ndarray,
    E: np.ndarray,
    H: np.ndarray,
    s: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    d: np.ndarray,
) -> tuple[int, int]:
    """(joint, its new state) for the first joint whose state's conditions fail, (n, slack flag) when the
    tendon's do, (CONSISTENT, 0) when the step is consistent, (STUCK, 0) when nothing can move."""
    n = len(prev)
    j, new = _wrong_move(state, prev, jt.thmax, d)
    if j != CONSISTENT:
        return j, new
    if not T_set:
        return _length_violation(state, t_d, tol, prev, E, H, s, jt, rc, d)
    for i in range(n):  # a fixed joint whose torque passes its band's edge
        rho = rc[i] * T - joint_torque(E, H, d, i)  # the tension's torque beyond the elastic one [N·mm]
        if state[i] == STICK:
            if rho > jt.f0[i] + jt.gp[i] * s[i] + TORQUE_TOL and prev[i] < jt.thmax[i]:
                return i, UP
            if rho < -jt.f0[i] - jt.gn[i] * s[i] - TORQUE_TOL and prev[i] > 0:
                return i, DOWN
        elif state[i] == HIGH:
            if rho < jt.f0[i] + jt.gp[i] * (jt.thmax[i] + jt.th0[i]) - TORQUE_TOL:
                return i, UP
        elif state[i] == LOW and rho > -jt.f0[i] - jt.gn[i] * jt.th0[i] + TORQUE_TOL:
            return i, DOWN
    if not slack and T < 0:  # the tendon cannot push: slack
        return n, 1
    if slack:
        held = 0.0
        for j in range(n):
            held += jt.r[j] * (prev[j] + d[j])
        if held < t_d - tol:  # a slack tendon must hold at least t_d: taut again
            return n, 0
    return CONSISTENT, 0


@njit(cache=True)
def flat_tension(
    state: np.ndarray,
    prev: np.ndarray,
    prev_T: float,
    E: np.ndarray,
    H: np.ndarray,
    s: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    d: np.ndarray,
) -> tuple[float, int, int]:
    """Every joint fixed on an inextensible tendon of the right length: (T, CONSISTENT, 0) with T the tension
    nearest the previous step's at which each joint's state holds, or (0, joint, its new state) where none holds
    them all: the joint that gives way at the lowest tension then slides."""
    lo, hi, first = 0.0, math.inf, -1
    for i in range(len(prev)):
        torque = joint_torque(E, H, d, i)
        up = math.inf
        if state[i] == STICK:
            if prev[i] > 0:
                lo = max(lo, _down_edge(i, torque, s, jt, rc))
            if prev[i] < jt.thmax[i]:
                up = _up_edge(i, torque, s, jt, rc)
        elif state[i] == HIGH:
            lo = max(lo, (torque + jt.f0[i] + jt.gp[i] * (jt.thmax[i] + jt.th0[i])) / rc[i])
        elif state[i] == LOW:
            up = (torque - jt.f0[i] - jt.gn[i] * jt.th0[i]) / rc[i]
        if up < hi:
            hi, first = up, i
    if lo > hi:
        return 0.0, first, (UP if state[first] == STICK else DOWN)
    return min(max(prev_T, lo), hi), CONSISTENT, 0


@njit(cache=True)
def coupled_solve(
    state: np.ndarray,
    t_d: float,
    tol: float,
    prev: np.ndarray,
    prev_T: float,
    E: np.ndarray,
    H: np.ndarray,
    s: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    comp: float,
    d: np.ndarray,
) -> tuple[bool, float]:
    """The linearised step from the joints' states ``state`` (n joints, then the tendon's slack flag; corrected in
    place): (True, T) with d = θ − prev, or (False, 0) when no consistent states were found within MAX_PIVOTS."""
    n = len(prev)
    for _ in range(MAX_PIVOTS):
        slack = state[n] == 1
        code, T = solve_states(state, slack, t_d, prev, E, H, s, jt, rc, comp, d)
        if code == 0:
            return False, 0.0
        j, new = first_violation(state, slack, code == 1, T, t_d, tol, prev, E, H, s, jt, rc, d)
        if j == STUCK:
            return False, 0.0
        if j >= 0:
            state[j] = new
            continue
        if code == 2:
            T, j, new = flat_tension(state, prev, prev_T, E, H, s, jt, rc, d)
            if j >= 0:
                state[j] = new
                continue
        return True, T
    return False, 0.0


@njit(cache=True)
def _linearise(
    at: np.ndarray,
    prev: np.ndarray,
    E0: np.ndarray,
    B: np.ndarray,
    wt: Weight,
    tg: np.ndarray,
    slope: np.ndarray,
    E: np.ndarray,
    H: np.ndarray,
) -> None:
    """The step's torque E + H·(θ − prev) with the weight linearised about ``at``: the spring's E0 + B·(θ − prev)
    plus τ_g(at) + G·(θ − at), G_ij = S_max(i,j)."""
    n = len(prev)
    weight_torque(at, wt, tg, slope)
    for i in range(n):
        v = 0.0
        for j in range(n):
            H[i, j] = slope[max(i, j)]
            v += H[i, j] * (prev[j] - at[j])
        E[i] = E0[i] + tg[i] + v
        H[i, i] += B[i]


@njit(cache=True)
def coupled_step(
    t_d: float,
    prev: np.ndarray,
    prev_T: float,
    guess: np.ndarray,
    E0: np.ndarray,
    B: np.ndarray,
    jt: Joints,
    rc: np.ndarray,
    comp: float,
    wt: Weight,
    th: np.ndarray,
) -> tuple[bool, float, bool]:
    """The step with the joints coupled through the weight, by Newton from ``guess`` (proximal where the finger
    snaps): (True, T, slack) with the angles in ``th``, or (False, 0, False) where no equilibrium was found within
    COUPLED_ITERATIONS linearisations. ``E0``, ``B``: the spring's part of the step (``finger_path``)."""
    n = len(prev)
    tol = FLAT_MM * max(1.0, abs(t_d))
    state = np.zeros(n + 1, np.int64)  # each joint's state, then the tendon's slack flag
    for i in range(n):
        state[i] = UP if guess[i] > prev[i] + 1e-12 else (DOWN if guess[i] < prev[i] - 1e-12 else STICK)
    at = guess.copy()
    s = prev + jt.th0
    tg, slope, E, d = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    H = np.zeros((n, n))
    damped, last = False, math.inf
    bmin = np.min(B)
    for _ in range(COUPLED_ITERATIONS):
        _linearise(at, prev, E0, B, wt, tg, slope, E, H)
        if damped:  # proximal: + λ(θ − at), H + λI positive definite
            lam = GRAVITY_MARGIN * bmin - np.linalg.eigvalsh(H)[0]
            if lam > 0:
                for i in range(n):
                    H[i, i] += lam
                    E[i] += lam * (prev[i] - at[i])
        ok, T = coupled_solve(state, t_d, tol, prev, prev_T, E, H, s, jt, rc, comp, d)
        if not ok:
            if damped:
                return False, 0.0, False
            damped = True
            continue
        moved = 0.0
        for i in range(n):
            moved = max(moved, abs(prev[i] + d[i] - at[i]))
        if moved <= GRAVITY_TOL and not damped:
            for i in range(n):
                th[i] = min(max(prev[i] + d[i], 0.0), jt.thmax[i])
            return True, T, state[n] == 1
        # Newton while its moves contract; proximal steps while they do not (a snap: the joints run to another
        # equilibrium), back to Newton once they do
        damped = moved > GRAVITY_CONTRACTION * last
        last = moved
        for i in range(n):
            at[i] = prev[i] + d[i]
    return False, 0.0, False
