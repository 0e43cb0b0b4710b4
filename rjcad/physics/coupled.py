"""One step of the finger with the links' weight, the joints coupled through the weight's full slope.

The weight's torque about joint i depends on every angle: turning joint j turns every link beyond it, so
∂τ_i/∂θ_j = S_max(i,j), S_k being joint k's own slope (``gravity_terms``). Linearised about the angles ``at``,
joint i's torque over the step is E_i + Σ_j H_ij (θ_j − prev_j), H = diag(B) + G with G_ij = S_max(i,j)
[N·mm/rad]. Each joint then sticks (θ = prev), slides closed on its band's upper edge
r_i·c_i·T − torque_i = f0 + γ⁺(θ + θ0), slides open on the lower edge (−f0 − γ⁻(θ + θ0)), or rests on a stop it
reached in this step; the tendon ties them: r·θ + T/k_t = t_d, or it is slack (T = 0, r·θ ≥ t_d). For a guess of
what each joint does, that is one linear system in the sliding joints' angles and T. The guess is corrected one
joint at a time (first a sliding joint that moved the wrong way or through its stop, then a fixed joint past its
band's edge, the lowest-numbered first) until every condition holds. Re-linearising the weight about the
result is Newton's method on the step.

Where the weight beats the springs (H not positive definite: the finger would snap), a step may have no solution
near the previous angles, and Newton's steps grow instead of shrinking. The step then adds λ(θ − at) to every
joint's torque, λ making H + λI positive definite (its smallest eigenvalue ``rjcad.physics.finger.GRAVITY_MARGIN``
× the joints' smallest B): each iteration is then a proximal step towards a stable equilibrium, and the added
torque vanishes once θ = at. A joint's own slope alone (a diagonal H, ``rjcad.physics.finger``'s fallback) misses
that joints sliding against softening weights trade angle at nearly no cost in weight: that iteration hands the
whole step to one joint, then to the other, and never settles. Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

import math


STICK, UP, DOWN, LOW, HIGH = 0, 1, -1, 2, 3
#: At most this many corrections of the joints' states in one linearised step (beyond: no solution found).
MAX_PIVOTS = 24
#: A fixed joint's torque may pass its band's edge by this much [N·mm] (the linear solve's rounding).
TORQUE_TOL = 1e-9
#: A sliding joint may move the wrong way by this much [rad] (the linear solve's rounding: a joint that the
#: tendon holds where it was moves by ±1e-17, and calling that a wrong way sends it back and forth between
#: sliding and sticking instead of letting the tendon go slack).
MOVE_TOL = 1e-12


class Step:
    """The linearised step's data as Python floats and lists (joints are few: scalar code beats small-array
    numpy): the torque E + H·(θ − prev), the previous angles and tension, the joints' constants, the tension
    factors r·c, the tendon's compliance 1/k_t and the tolerance on its length [mm]."""

    __slots__ = ("n", "t_d", "prev", "prev_T", "E", "H", "s", "th0", "thmax", "r", "rc", "f0", "gp", "gn", "comp",
                 "tol")

    def __init__(self, t_d, prev, prev_T, E, H, th0, thmax, r, rc, f0, gp, gn, comp, tol):
        self.n = len(prev)
        self.t_d, self.prev_T, self.comp, self.tol = t_d, prev_T, comp, tol
        self.prev, self.E, self.H, self.th0, self.thmax = prev, E, H, th0, thmax
        self.r, self.rc, self.f0, self.gp, self.gn = r, rc, f0, gp, gn
        self.s = [p + t for p, t in zip(prev, th0)]


def solve_linear(A: list, b: list) -> list | None:
    """x with A·x = b by Gaussian elimination with partial pivoting (A, b: small, copied), None if singular."""
    k = len(b)
    M = [row[:] + [bi] for row, bi in zip(A, b)]
    scale = max((abs(v) for row in A for v in row), default=0.0)
    for c in range(k):
        p = max(range(c, k), key=lambda i: abs(M[i][c]))
        if abs(M[p][c]) <= 1e-13 * scale or scale == 0.0:
            return None
        M[c], M[p] = M[p], M[c]
        piv = M[c]
        for i in range(c + 1, k):
            f = M[i][c] / piv[c]
            if f:
                row = M[i]
                for j in range(c, k + 1):
                    row[j] -= f * piv[j]
    x = [0.0] * k
    for c in range(k - 1, -1, -1):
        row = M[c]
        x[c] = (row[k] - sum(row[j] * x[j] for j in range(c + 1, k))) / row[c]
    return x


def solve_states(st: Step, state: list, slack: bool):
    """(θ − prev, T) for given joint states, T None where no joint slides on an inextensible tendon (the
    tension is then not set by the tendon), or None where the states leave the system singular."""
    n, prev, thmax = st.n, st.prev, st.thmax
    d = [0.0] * n
    for i in range(n):
        if state[i] == LOW:
            d[i] = -prev[i]
        elif state[i] == HIGH:
            d[i] = thmax[i] - prev[i]
    free = [i for i in range(n) if state[i] == UP or state[i] == DOWN]
    k = len(free)
    if k == 0 and (slack or st.comp == 0.0):
        return d, (0.0 if slack else None)
    H, E, s = st.H, st.E, st.s
    A, b = [], []
    for i in free:
        Hi = H[i]
        row = [-Hi[j] for j in free]
        fixed = E[i] + sum(Hi[j] * d[j] for j in range(n) if d[j])
        if state[i] == UP:
            row[len(A)] -= st.gp[i]
            b.append(fixed + st.f0[i] + st.gp[i] * s[i])
        else:
            row[len(A)] += st.gn[i]
            b.append(fixed - st.f0[i] - st.gn[i] * s[i])
        if not slack:
            row.append(st.rc[i])
        A.append(row)
    if not slack:
        A.append([st.r[j] for j in free] + [st.comp])
        b.append(st.t_d - sum(st.r[j] * (prev[j] + d[j]) for j in range(n)))
    x = solve_linear(A, b)
    if x is None or not all(map(math.isfinite, x)):
        return None
    for a, i in enumerate(free):
        d[i] = x[a]
    return d, (0.0 if slack else x[k])


def torques(st: Step, d: list) -> list:
    """Each joint's elastic torque with the weight, E + H·(θ − prev) [N·mm]."""
    return [e + sum(h * x for h, x in zip(row, d) if x) for e, row in zip(st.E, st.H)]


def first_violation(st: Step, state: list, slack: bool, d: list, T, torque: list):
    """(joint, its new state) for the first joint whose state's conditions fail (``torque``: ``torques(st, d)``),
    (n, slack) when the tendon's do, None when the step is consistent, False when no joint can close to take up
    the tendon (every one on its upper stop: the caller's fallback sets the tension there)."""
    n, prev, thmax, th0 = st.n, st.prev, st.thmax, st.th0
    for i in range(n):  # first a sliding joint that moved the wrong way or through its stop
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
    s, f0, gp, gn = st.s, st.f0, st.gp, st.gn
    if T is None:  # every joint fixed on an inextensible tendon: its length is set by the joints
        short = sum(st.r[j] * (prev[j] + d[j]) for j in range(n)) - st.t_d  # > 0: more tendon held than t_d
        if abs(short) <= st.tol:
            return None
        if short < 0:  # the tension rises until the first stuck joint starts to close
            edges = [((torque[i] + f0[i] + gp[i] * s[i]) / st.rc[i], i) for i in range(n)
                     if state[i] == STICK and prev[i] < thmax[i]]
            return (min(edges)[1], UP) if edges else False
        edges = [((torque[i] - f0[i] - gn[i] * s[i]) / st.rc[i], i) for i in range(n)
                 if state[i] == STICK and prev[i] > 0]
        edges = [e for e in edges if e[0] > 0]
        return (max(edges)[1], DOWN) if edges else (n, True)
    for i in range(n):  # then a fixed joint whose torque passes its band's edge
        rho = st.rc[i] * T - torque[i]  # the tension's torque beyond the elastic one
        if state[i] == STICK:
            if rho > f0[i] + gp[i] * s[i] + TORQUE_TOL and prev[i] < thmax[i]:
                return i, UP
            if rho < -f0[i] - gn[i] * s[i] - TORQUE_TOL and prev[i] > 0:
                return i, DOWN
        elif state[i] == HIGH:
            if rho < f0[i] + gp[i] * (thmax[i] + th0[i]) - TORQUE_TOL:
                return i, UP
        elif state[i] == LOW:
            if rho > -f0[i] - gn[i] * th0[i] + TORQUE_TOL:
                return i, DOWN
    if not slack and T < 0:
        return n, True
    if slack and sum(st.r[j] * (prev[j] + d[j]) for j in range(n)) < st.t_d - st.tol:
        return n, False
    return None


def flat_tension(st: Step, state: list, torque: list):
    """Every joint fixed on an inextensible tendon of the right length: (the tension nearest the previous step's
    at which each joint's state holds, None), or (None, (joint, UP)) where no tension holds them all: the joint
    that closes at the lowest tension then slides. ``torque``: ``torques(st, d)``."""
    n, prev, thmax, th0, s, f0, gp, gn, rc = st.n, st.prev, st.thmax, st.th0, st.s, st.f0, st.gp, st.gn, st.rc
    lo, hi, first = 0.0, math.inf, -1
    for i in range(n):
        up = math.inf
        if state[i] == STICK:
            if prev[i] > 0:
                lo = max(lo, (torque[i] - f0[i] - gn[i] * s[i]) / rc[i])
            if prev[i] < thmax[i]:
                up = (torque[i] + f0[i] + gp[i] * s[i]) / rc[i]
        elif state[i] == HIGH:
            lo = max(lo, (torque[i] + f0[i] + gp[i] * (thmax[i] + th0[i])) / rc[i])
        elif state[i] == LOW:
            up = (torque[i] - f0[i] - gn[i] * th0[i]) / rc[i]
        if up < hi:
            hi, first = up, i
    if lo > hi:
        return None, (first, UP if state[first] == STICK else DOWN)
    return min(max(st.prev_T, lo), hi), None


def coupled_solve(st: Step, state: list):
    """The linearised step from the joint states ``state`` (n joints, then the tendon's slack flag; corrected in
    place): (θ − prev, T, slack), or None when no consistent states were found within MAX_PIVOTS corrections."""
    n = st.n
    for _ in range(MAX_PIVOTS):
        slack = bool(state[n])
        got = solve_states(st, state, slack)
        if got is None:
            return None
        d, T = got
        torque = torques(st, d)
        bad = first_violation(st, state, slack, d, T, torque)
        if bad is False:
            return None
        if bad is not None:
            state[bad[0]] = bad[1]
            continue
        if T is None:
            T, bad = flat_tension(st, state, torque)
            if bad is not None:
                state[bad[0]] = bad[1]
                continue
        return d, float(T), slack
    return None
