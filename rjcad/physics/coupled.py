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
from typing import NamedTuple

import numpy as np

from rjcad.physics.gravity import Weight, weight_frame, weight_torque
from rjcad.physics.kernel import kernel
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


#: One joint in a coupled step, a record of ``coupled_step``'s record array J (read as ``J[i].name``): its
#: constants, where the step starts, the linearised torque and the step's answer. One array for the joints
#: rather than a dozen: numba counts the references to each array a kernel is given (two atomic operations per
#: array per call), and these kernels run several times a step.
JOINT_STEP = np.dtype(
    [
        ("th0", np.float64),  # preload θ0 [rad]
        ("thmax", np.float64),  # range θmax [rad]
        ("r", np.float64),  # tendon moment arm [mm]
        ("f0", np.float64),  # constant friction [N·mm]
        ("gp", np.float64),  # tendon-induced friction while closing, γ⁺ [N·mm/rad] ...
        ("gn", np.float64),  # ... and while opening, γ⁻ [N·mm/rad]
        ("prev", np.float64),  # the angle at the step's start [rad]
        ("s", np.float64),  # prev + θ0: the spring's wind-up there [rad]
        ("rc", np.float64),  # r·c: the actuator tension's moment arm about the joint [mm]
        ("E", np.float64),  # the linearised torque at prev [N·mm] (H holds its slope)
        ("d", np.float64),  # the move θ − prev [rad]: the step's answer
    ]
)


class LinearSystem(NamedTuple):
    """Scratch for a step's linear system (``solve_states``): at most n + 1 unknowns, the sliding joints' moves
    and the tension."""

    free: np.ndarray  # (n,) int64: the sliding joints, in order
    A: np.ndarray  # (n + 1, n + 1)
    b: np.ndarray  # (n + 1,)
    x: np.ndarray  # (n + 1,)


class CoupledWork(NamedTuple):
    """What ``coupled_step`` writes, made once per path by ``coupled_work``: a step allocates nothing."""

    J: np.ndarray  # (n,) JOINT_STEP records
    H: np.ndarray  # (n, n) the linearised torque's slope [N·mm/rad]
    state: np.ndarray  # (n + 1,) int64: each joint's state, then the tendon's slack flag
    at: np.ndarray  # (n,) the angles the weight is linearised about [rad]
    tg: np.ndarray  # (n,) the weight's torque at ``at`` [N·mm] ...
    slope: np.ndarray  # (n,) ... and its slope in each joint's own angle [N·mm/rad]
    frame: np.ndarray  # (4, n + 1): ``weight_torque``'s scratch
    system: LinearSystem


@kernel
def linear_system(n: int) -> LinearSystem:
    """A ``LinearSystem`` for n joints."""
    return LinearSystem(np.zeros(n, np.int64), np.zeros((n + 1, n + 1)), np.zeros(n + 1), np.zeros(n + 1))


@kernel
def coupled_work(n: int) -> CoupledWork:
    """A ``CoupledWork`` for n joints."""
    return CoupledWork(
        np.zeros(n, JOINT_STEP),
        np.zeros((n, n)),
        np.zeros(n + 1, np.int64),
        np.zeros(n),
        np.zeros(n),
        np.zeros(n),
        weight_frame(n),
        linear_system(n),
    )


@kernel
def gauss(A: np.ndarray, b: np.ndarray, x: np.ndarray, k: int) -> bool:
    """Solves the leading k × k system A·x = b by Gaussian elimination with partial pivoting (A and b are
    overwritten, x[:k] set); False if singular."""
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


@kernel
def joint_torque(J: np.ndarray, H: np.ndarray, i: int) -> float:
    """Joint i's elastic torque with the weight after the moves d: E_i + Σ_j H_ij·d_j [N·mm]."""
    v: float = J[i].E
    for j in range(len(J)):
        if J[j].d != 0.0:
            v += H[i, j] * J[j].d
    return v


@kernel
def _up_edge(J: np.ndarray, i: int, torque: float) -> float:
    """The tension [N] at which joint i, sticking with elastic torque ``torque``, starts closing."""
    edge: float = (torque + J[i].f0 + J[i].gp * J[i].s) / J[i].rc
    return edge


@kernel
def _down_edge(J: np.ndarray, i: int, torque: float) -> float:
    """The tension [N] below which joint i, sticking with elastic torque ``torque``, starts opening."""
    edge: float = (torque - J[i].f0 - J[i].gn * J[i].s) / J[i].rc
    return edge


@kernel
def solve_states(
    J: np.ndarray, H: np.ndarray, state: np.ndarray, slack: bool, t_d: float, comp: float, sy: LinearSystem
) -> tuple[int, float]:
    """Fills J.d = θ − prev for the joints' states ``state``; returns (0, 0) where singular, (1, T) with the
    tension set, (2, 0) where no joint slides on an inextensible tendon (the tension is then not set by the tendon).

    Each sliding joint: −Σ_j H_ij·d_j ∓ γ·d_i + r_i·c_i·T = E_i ± (f0 + γ·s_i) (its band's edge); the tendon:
    Σ r_j·d_j + T/k_t = t_d − Σ r·prev (dropped when slack). ``sy``: the system's scratch.
    """
    n = len(J)
    k = 0
    for i in range(n):
        J[i].d = -J[i].prev if state[i] == LOW else (J[i].thmax - J[i].prev if state[i] == HIGH else 0.0)
        if state[i] == UP or state[i] == DOWN:
            sy.free[k] = i
            k += 1
    if k == 0 and (slack or comp == 0.0):
        return (1, 0.0) if slack else (2, 0.0)
    size = k if slack else k + 1
    for a in range(k):
        i = sy.free[a]
        for c in range(k):
            sy.A[a, c] = -H[i, sy.free[c]]
        fixed = joint_torque(J, H, i)
        if state[i] == UP:
            sy.A[a, a] -= J[i].gp
            sy.b[a] = fixed + J[i].f0 + J[i].gp * J[i].s
        else:
            sy.A[a, a] += J[i].gn
            sy.b[a] = fixed - J[i].f0 - J[i].gn * J[i].s
        if not slack:
            sy.A[a, k] = J[i].rc
    if not slack:
        for c in range(k):
            sy.A[k, c] = J[sy.free[c]].r
        sy.A[k, k] = comp
        v = t_d
        for j in range(n):
            v -= J[j].r * (J[j].prev + J[j].d)
        sy.b[k] = v
    if not gauss(sy.A, sy.b, sy.x, size):
        return 0, 0.0
    for a in range(size):
        if not math.isfinite(sy.x[a]):
            return 0, 0.0
    for a in range(k):
        J[sy.free[a]].d = sy.x[a]
    return 1, (0.0 if slack else sy.x[k])


@kernel
def _wrong_move(J: np.ndarray, state: np.ndarray) -> tuple[int, int]:
    """(joint, new state) for the first sliding joint that moved the wrong way or through its stop."""
    for i in range(len(J)):
        if state[i] == UP:
            if J[i].d < -MOVE_TOL:
                return i, STICK
            if J[i].prev + J[i].d > J[i].thmax:
                return i, HIGH
        elif state[i] == DOWN:
            if J[i].d > MOVE_TOL:
                return i, STICK
            if J[i].prev + J[i].d < 0:
                return i, LOW
    return CONSISTENT, 0


@kernel
def _length_violation(J: np.ndarray, H: np.ndarray, state: np.ndarray, t_d: float, tol: float) -> tuple[int, int]:
    """Every joint fixed on an inextensible tendon: its length is set by the joints. Too short a take-up: the
    tension rises until the first sticking joint starts to close; too long: the last one to open opens, or the
    tendon goes slack (joint n). (joint, new state), or (CONSISTENT, 0), or (STUCK, 0): nothing can close."""
    n = len(J)
    short = -t_d  # > 0: more tendon held than t_d [mm]
    for j in range(n):
        short += J[j].r * (J[j].prev + J[j].d)
    if abs(short) <= tol:
        return CONSISTENT, 0
    best, bi = 0.0, -1
    if short < 0:
        for i in range(n):
            if state[i] == STICK and J[i].prev < J[i].thmax:
                e = _up_edge(J, i, joint_torque(J, H, i))
                if bi < 0 or e < best:
                    best, bi = e, i
        return (bi, UP) if bi >= 0 else (STUCK, 0)
    for i in range(n):
        if state[i] == STICK and J[i].prev > 0:
            e = _down_edge(J, i, joint_torque(J, H, i))
            if e > 0 and (bi < 0 or e >= best):
                best, bi = e, i
    return (bi, DOWN) if bi >= 0 else (n, 1)


@kernel
def first_violation(
    J: np.ndarray, H: np.ndarray, state: np.ndarray, slack: bool, T_set: bool, T: float, t_d: float, tol: float
) -> tuple[int, int]:
    """(joint, its new state) for the first joint whose state's conditions fail, (n, slack flag) when the
    tendon's do, (CONSISTENT, 0) when the step is consistent, (STUCK, 0) when nothing can move."""
    n = len(J)
    j, new = _wrong_move(J, state)
    if j != CONSISTENT:
        return j, new
    if not T_set:
        return _length_violation(J, H, state, t_d, tol)
    for i in range(n):  # a fixed joint whose torque passes its band's edge
        rho = J[i].rc * T - joint_torque(J, H, i)  # the tension's torque beyond the elastic one [N·mm]
        if state[i] == STICK:
            if rho > J[i].f0 + J[i].gp * J[i].s + TORQUE_TOL and J[i].prev < J[i].thmax:
                return i, UP
            if rho < -J[i].f0 - J[i].gn * J[i].s - TORQUE_TOL and J[i].prev > 0:
                return i, DOWN
        elif state[i] == HIGH:
            if rho < J[i].f0 + J[i].gp * (J[i].thmax + J[i].th0) - TORQUE_TOL:
                return i, UP
        elif state[i] == LOW and rho > -J[i].f0 - J[i].gn * J[i].th0 + TORQUE_TOL:
            return i, DOWN
    if not slack and T < 0:  # the tendon cannot push: slack
        return n, 1
    if slack:
        held = 0.0
        for j in range(n):
            held += J[j].r * (J[j].prev + J[j].d)
        if held < t_d - tol:  # a slack tendon must hold at least t_d: taut again
            return n, 0
    return CONSISTENT, 0


@kernel
def flat_tension(J: np.ndarray, H: np.ndarray, state: np.ndarray, prev_T: float) -> tuple[float, int, int]:
    """Every joint fixed on an inextensible tendon of the right length: (T, CONSISTENT, 0) with T the tension
    nearest the previous step's at which each joint's state holds, or (0, joint, its new state) where none holds
    them all: the joint that gives way at the lowest tension then slides."""
    lo, hi, first = 0.0, math.inf, -1
    for i in range(len(J)):
        torque = joint_torque(J, H, i)
        up = math.inf
        if state[i] == STICK:
            if J[i].prev > 0:
                lo = max(lo, _down_edge(J, i, torque))
            if J[i].prev < J[i].thmax:
                up = _up_edge(J, i, torque)
        elif state[i] == HIGH:
            lo = max(lo, (torque + J[i].f0 + J[i].gp * (J[i].thmax + J[i].th0)) / J[i].rc)
        elif state[i] == LOW:
            up = (torque - J[i].f0 - J[i].gn * J[i].th0) / J[i].rc
        if up < hi:
            hi, first = up, i
    if lo > hi:
        return 0.0, first, (UP if state[first] == STICK else DOWN)
    return min(max(prev_T, lo), hi), CONSISTENT, 0


@kernel
def coupled_solve(
    J: np.ndarray,
    H: np.ndarray,
    state: np.ndarray,
    t_d: float,
    tol: float,
    prev_T: float,
    comp: float,
    sy: LinearSystem,
) -> tuple[bool, float]:
    """The linearised step (J, H) from the joints' states ``state`` (n joints, then the tendon's slack flag;
    corrected in place): (True, T) with J.d = θ − prev, or (False, 0) when no consistent states were found within
    MAX_PIVOTS. ``sy``: the linear system's scratch (``linear_system``)."""
    n = len(J)
    for _ in range(MAX_PIVOTS):
        slack = state[n] == 1
        code, T = solve_states(J, H, state, slack, t_d, comp, sy)
        if code == 0:
            return False, 0.0
        j, new = first_violation(J, H, state, slack, code == 1, T, t_d, tol)
        if j == STUCK:
            return False, 0.0
        if j >= 0:
            state[j] = new
            continue
        if code == 2:
            T, j, new = flat_tension(J, H, state, prev_T)
            if j >= 0:
                state[j] = new
                continue
        return True, T
    return False, 0.0


@kernel
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
    w: CoupledWork,
) -> tuple[bool, float, bool]:
    """The step with the joints coupled through the weight, by Newton from ``guess`` (proximal where the finger
    snaps): (True, T, slack) with the angles in ``th``, or (False, 0, False) where no equilibrium was found within
    COUPLED_ITERATIONS linearisations. ``E0``, ``B``: the spring's part of the step (``finger_path``); ``w``: the
    scratch (``coupled_work``).

    Each linearisation about ``at``: E_i = E0_i + τ_g(at)_i + Σ_j G_ij·(prev_j − at_j) and H = diag(B) + G,
    G_ij = S_max(i,j): the spring's E0 + B·(θ − prev) plus the weight's τ_g(at) + G·(θ − at).
    """
    n = len(prev)
    tol = FLAT_MM * max(1.0, abs(t_d))
    J, H, state, at, slope = w.J, w.H, w.state, w.at, w.slope
    for i in range(n):
        J[i].th0, J[i].thmax, J[i].r = jt.th0[i], jt.thmax[i], jt.r[i]
        J[i].f0, J[i].gp, J[i].gn = jt.f0[i], jt.gp[i], jt.gn[i]
        J[i].prev, J[i].s, J[i].rc = prev[i], prev[i] + jt.th0[i], rc[i]
        state[i] = UP if guess[i] > prev[i] + 1e-12 else (DOWN if guess[i] < prev[i] - 1e-12 else STICK)
        at[i] = guess[i]
    state[n] = 0  # taut
    damped, last = False, math.inf
    for _ in range(COUPLED_ITERATIONS):
        weight_torque(at, wt, w.tg, slope, w.frame)
        for i in range(n):
            v = 0.0
            for j in range(n):
                H[i, j] = slope[max(i, j)]
                v += H[i, j] * (prev[j] - at[j])
            J[i].E = E0[i] + w.tg[i] + v
            H[i, i] += B[i]
        if damped:  # proximal: + λ(θ − at), H + λI positive definite
            lam = GRAVITY_MARGIN * np.min(B) - np.linalg.eigvalsh(H)[0]
            if lam > 0:
                for i in range(n):
                    H[i, i] += lam
                    J[i].E += lam * (prev[i] - at[i])
        ok, T = coupled_solve(J, H, state, t_d, tol, prev_T, comp, w.system)
        if not ok:
            if damped:
                return False, 0.0, False
            damped = True
            continue
        moved = 0.0
        for i in range(n):
            moved = max(moved, abs(prev[i] + J[i].d - at[i]))
        if moved <= GRAVITY_TOL and not damped:
            for i in range(n):
                th[i] = min(max(prev[i] + J[i].d, 0.0), jt.thmax[i])
            return True, T, state[n] == 1
        # Newton while its moves contract; proximal steps while they do not (a snap: the joints run to another
        # equilibrium), back to Newton once they do
        damped = moved > GRAVITY_CONTRACTION * last
        last = moved
        for i in range(n):
            at[i] = prev[i] + J[i].d
    return False, 0.0, False
