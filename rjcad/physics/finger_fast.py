"""The finger's quasi-static closure (rjcad.physics.finger) compiled for fitting: the same equations, the same
exact piecewise-linear tendon solve, one compiled loop over the path.

``rjcad.physics.finger.simulate_path`` is the reference (readable, checked step by step against the
equilibrium and stick–slip conditions in tests/test_physics_finger.py); this module must give the same
angles and tensions to 1e-9 (tests/test_finger_fast.py). It exists because identification evaluates the
model thousands of times: ~80 µs per step in numpy, ~1 µs compiled (benchmarks/identify.py).
Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rjcad.physics import coupled as cp
from rjcad.physics.coupled import MAX_PIVOTS, MOVE_TOL, TORQUE_TOL
from rjcad.physics.finger import (COUPLED_ITERATIONS, FLAT_MM, GRAVITY_CONTRACTION, GRAVITY_ITERATIONS, GRAVITY_MARGIN,
                                  GRAVITY_SOFTENING, GRAVITY_TOL, FingerModel, path_times)


@njit(cache=True)
def _theta_of_T(T, prev, E, B, th0, thmax, rc, f0, gp, gn, out):
    for i in range(len(E)):
        s = prev[i] + th0[i]
        up_T = (E[i] + f0[i] + gp[i] * s) / rc[i]
        dn_T = (E[i] - f0[i] - gn[i] * s) / rc[i]
        if T >= up_T:
            th = max((rc[i] * T - E[i] - f0[i] - gp[i] * th0[i] + B[i] * prev[i]) / (B[i] + gp[i]), prev[i])
        elif T <= dn_T:
            th = min((rc[i] * T - E[i] + f0[i] + gn[i] * th0[i] + B[i] * prev[i]) / (B[i] - gn[i]), prev[i])
        else:
            th = prev[i]
        out[i] = min(max(th, 0.0), thmax[i])


@njit(cache=True)
def _gravity(prev, length, com, weight, gx, gy, out, slope):
    """As rjcad.physics.finger.gravity_terms: the weight's torque about each joint and its slope."""
    n = len(prev)
    ang = 0.0
    x = np.zeros(n + 1)
    y = np.zeros(n + 1)
    c = np.zeros(n)
    s = np.zeros(n)
    for i in range(n):
        ang += prev[i]
        c[i], s[i] = math.cos(ang), math.sin(ang)
        x[i + 1] = x[i] + length[i] * math.cos(ang)
        y[i + 1] = y[i] + length[i] * math.sin(ang)
    for i in range(n):
        tau = 0.0
        k = 0.0
        for j in range(i, n):
            rx = x[j] + com[j, 0] * c[j] - com[j, 1] * s[j] - x[i]
            ry = y[j] + com[j, 0] * s[j] + com[j, 1] * c[j] - y[i]
            tau -= weight[j] * (rx * gy - ry * gx)
            k += weight[j] * (rx * gx + ry * gy)
        out[i] = tau
        slope[i] = k


@njit(cache=True)
def _sort(a, m):
    """Insertion sort of a[:m] in place (a dozen breakpoints: no allocation; duplicates are harmless)."""
    for i in range(1, m):
        v = a[i]
        j = i - 1
        while j >= 0 and a[j] > v:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = v


@njit(cache=True)
def _sum(T, prev, E, B, th0, thmax, r, rc, f0, gp, gn, th, comp):
    """Σ r·θ(T) + T/k_t: the tendon displacement the joints and the tendon take up at tension T [mm]."""
    _theta_of_T(T, prev, E, B, th0, thmax, rc, f0, gp, gn, th)
    S = comp * T
    for i in range(len(E)):
        S += r[i] * th[i]
    return S


@njit(cache=True)
def _step(t_d, prev, prev_T, E, B, th0, thmax, r, rc, f0, gp, gn, comp, th, bps):
    """One step of the tendon solve (``rjcad.physics.finger.equilibrium``): fills ``th``, returns T."""
    n = len(E)
    _theta_of_T(0.0, prev, E, B, th0, thmax, rc, f0, gp, gn, th)
    s0 = 0.0
    for i in range(n):
        s0 += r[i] * th[i]
    T = 0.0
    if s0 < t_d:
        m = 1
        bps[0] = 0.0
        for i in range(n):
            s = prev[i] + th0[i]
            cand = ((E[i] + f0[i] + gp[i] * s) / rc[i], (E[i] - f0[i] - gn[i] * s) / rc[i],
                    (E[i] + B[i] * (thmax[i] - prev[i]) + f0[i] + gp[i] * (thmax[i] + th0[i])) / rc[i],
                    (E[i] - B[i] * prev[i] - f0[i] - gn[i] * th0[i]) / rc[i])
            for v in cand:
                if math.isfinite(v):
                    bps[m] = max(v, 0.0)
                    m += 1
        _sort(bps, m)  # ascending in place; 0 is the first
        grid = bps[:m]
        tol = FLAT_MM * max(1.0, abs(t_d))
        # the first grid tension whose take-up meets t_d - tol: S(T) never decreases, so bisect (about 4 sums of
        # a dozen, where a scan from 0 took half of them)
        g_lo, g_hi = 0, len(grid)  # S(grid[g]) < t_d - tol for g < g_lo; >= for g >= g_hi
        S_hi = 0.0
        while g_lo < g_hi:
            mid = (g_lo + g_hi) // 2
            Sm = _sum(grid[mid], prev, E, B, th0, thmax, r, rc, f0, gp, gn, th, comp)
            if Sm >= t_d - tol:
                g_hi, S_hi = mid, Sm
            else:
                g_lo = mid + 1
        k = g_lo if g_lo < len(grid) else -1
        S = S_hi
        S_prev = -1.0
        if k > 0:
            S_prev = _sum(grid[k - 1], prev, E, B, th0, thmax, r, rc, f0, gp, gn, th, comp)
        elif k < 0:
            S_prev = _sum(grid[len(grid) - 1], prev, E, B, th0, thmax, r, rc, f0, gp, gn, th, comp)
        if k < 0:
            T = grid[-1] if comp == 0.0 else grid[-1] + (t_d - S_prev) / comp
        elif S <= t_d + tol:  # met at grid[k], and on along a flat stretch: keep the previous tension if on it
            hi = grid[k]
            for g2 in range(k + 1, len(grid)):
                if _sum(grid[g2], prev, E, B, th0, thmax, r, rc, f0, gp, gn, th, comp) > t_d + tol:
                    break
                hi = grid[g2]
            T = min(max(prev_T, grid[k]), hi)
        else:
            T = grid[k - 1] + (t_d - S_prev) * (grid[k] - grid[k - 1]) / (S - S_prev)
        _theta_of_T(T, prev, E, B, th0, thmax, rc, f0, gp, gn, th)
    return T


STICK, UP, DOWN, LOW, HIGH = cp.STICK, cp.UP, cp.DOWN, cp.LOW, cp.HIGH


@njit(cache=True)
def _gauss(A, b, x):
    """x with A·x = b (partial pivoting; A and b are overwritten), False if singular (as coupled.solve_linear)."""
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
        if scale == 0.0 or abs(A[p, c]) <= 1e-13 * scale:
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
def _torque(E, H, d, i):
    v = E[i]
    for j in range(len(d)):
        if d[j] != 0.0:
            v += H[i, j] * d[j]
    return v


@njit(cache=True)
def _solve_states(state, slack, t_d, prev, E, H, s, thmax, r, rc, f0, gp, gn, comp, d):
    """As coupled.solve_states: fills d (θ − prev); returns (0 singular | 1 T set | 2 T not set by the tendon, T)."""
    n = len(prev)
    free = np.empty(n, np.int64)
    k = 0
    for i in range(n):
        d[i] = -prev[i] if state[i] == LOW else (thmax[i] - prev[i] if state[i] == HIGH else 0.0)
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
        fixed = _torque(E, H, d, i)
        if state[i] == UP:
            A[a, a] -= gp[i]
            b[a] = fixed + f0[i] + gp[i] * s[i]
        else:
            A[a, a] += gn[i]
            b[a] = fixed - f0[i] - gn[i] * s[i]
        if not slack:
            A[a, k] = rc[i]
    if not slack:
        for c in range(k):
            A[k, c] = r[free[c]]
        A[k, k] = comp
        v = t_d
        for j in range(n):
            v -= r[j] * (prev[j] + d[j])
        b[k] = v
    if not _gauss(A, b, x):
        return 0, 0.0
    for a in range(size):
        if not math.isfinite(x[a]):
            return 0, 0.0
    for a in range(k):
        d[free[a]] = x[a]
    return 1, (0.0 if slack else x[k])


@njit(cache=True)
def _first_violation(state, slack, T_set, T, t_d, tol, prev, E, H, s, th0, thmax, r, rc, f0, gp, gn, d):
    """As coupled.first_violation: (joint or n for the tendon, its new state), joint −1 when consistent,
    −2 when nothing can move."""
    n = len(prev)
    for i in range(n):
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
    if not T_set:
        short = -t_d
        for j in range(n):
            short += r[j] * (prev[j] + d[j])
        if abs(short) <= tol:
            return -1, 0
        best, bi = 0.0, -1
        if short < 0:
            for i in range(n):
                if state[i] == STICK and prev[i] < thmax[i]:
                    e = (_torque(E, H, d, i) + f0[i] + gp[i] * s[i]) / rc[i]
                    if bi < 0 or e < best:
                        best, bi = e, i
            return (bi, UP) if bi >= 0 else (-2, 0)
        for i in range(n):
            if state[i] == STICK and prev[i] > 0:
                e = (_torque(E, H, d, i) - f0[i] - gn[i] * s[i]) / rc[i]
                if e > 0 and (bi < 0 or e >= best):
                    best, bi = e, i
        return (bi, DOWN) if bi >= 0 else (n, 1)
    for i in range(n):
        rho = rc[i] * T - _torque(E, H, d, i)
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
        return n, 1
    if slack:
        held = 0.0
        for j in range(n):
            held += r[j] * (prev[j] + d[j])
        if held < t_d - tol:
            return n, 0
    return -1, 0


@njit(cache=True)
def _flat_tension(state, prev, prev_T, E, H, s, th0, thmax, rc, f0, gp, gn, d):
    """As coupled.flat_tension: (T, −1, 0), or (0, joint, its new state) where no tension holds every joint."""
    n = len(prev)
    lo, hi, first = 0.0, math.inf, -1
    for i in range(n):
        torque = _torque(E, H, d, i)
        up = math.inf
        if state[i] == STICK:
            if prev[i] > 0:
                lo = max(lo, (torque - f0[i] - gn[i] * s[i]) / rc[i])
            if prev[i] < thmax[i]:
                up = (torque + f0[i] + gp[i] * s[i]) / rc[i]
        elif state[i] == HIGH:
            lo = max(lo, (torque + f0[i] + gp[i] * (thmax[i] + th0[i])) / rc[i])
        elif state[i] == LOW:
            up = (torque - f0[i] - gn[i] * th0[i]) / rc[i]
        if up < hi:
            hi, first = up, i
    if lo > hi:
        return 0.0, first, (UP if state[first] == STICK else DOWN)
    return min(max(prev_T, lo), hi), -1, 0


@njit(cache=True)
def _coupled_solve(state, t_d, tol, prev, prev_T, E, H, s, th0, thmax, r, rc, f0, gp, gn, comp, d):
    """As coupled.coupled_solve: (ok, T); d holds θ − prev and state[n] the slack flag."""
    n = len(prev)
    for _ in range(MAX_PIVOTS):
        slack = state[n] == 1
        code, T = _solve_states(state, slack, t_d, prev, E, H, s, thmax, r, rc, f0, gp, gn, comp, d)
        if code == 0:
            return False, 0.0
        j, new = _first_violation(state, slack, code == 1, T, t_d, tol, prev, E, H, s, th0, thmax, r, rc, f0, gp,
                                  gn, d)
        if j == -2:
            return False, 0.0
        if j >= 0:
            state[j] = new
            continue
        if code == 2:
            T, j, new = _flat_tension(state, prev, prev_T, E, H, s, th0, thmax, rc, f0, gp, gn, d)
            if j >= 0:
                state[j] = new
                continue
        return True, T
    return False, 0.0


@njit(cache=True)
def _coupled_step(t_d, prev, prev_T, guess, E0, B, th0, thmax, r, rc, f0, gp, gn, comp, length, com, weight, gx, gy,
                  th):
    """As rjcad.physics.finger.coupled_step: fills th, returns (ok, T, slack)."""
    n = len(prev)
    tol = FLAT_MM * max(1.0, abs(t_d))
    state = np.zeros(n + 1, np.int64)
    for i in range(n):
        state[i] = UP if guess[i] > prev[i] + 1e-12 else (DOWN if guess[i] < prev[i] - 1e-12 else STICK)
    at = guess.copy()
    s = prev + th0
    tg = np.zeros(n)
    slope = np.zeros(n)
    E = np.zeros(n)
    H = np.zeros((n, n))
    d = np.zeros(n)
    damped, last = False, math.inf
    bmin = np.min(B)
    for _ in range(COUPLED_ITERATIONS):
        _gravity(at, length, com, weight, gx, gy, tg, slope)
        for i in range(n):
            v = 0.0
            for j in range(n):
                H[i, j] = slope[max(i, j)]
                v += H[i, j] * (prev[j] - at[j])
            E[i] = E0[i] + tg[i] + v
            H[i, i] += B[i]
        if damped:
            lam = GRAVITY_MARGIN * bmin - np.linalg.eigvalsh(H)[0]
            if lam > 0:
                for i in range(n):
                    H[i, i] += lam
                    E[i] += lam * (prev[i] - at[i])
        ok, T = _coupled_solve(state, t_d, tol, prev, prev_T, E, H, s, th0, thmax, r, rc, f0, gp, gn, comp, d)
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
                th[i] = min(max(prev[i] + d[i], 0.0), thmax[i])
            return True, T, state[n] == 1
        damped = moved > GRAVITY_CONTRACTION * last
        last = moved
        for i in range(n):
            at[i] = prev[i] + d[i]
    return False, 0.0, False


@njit(cache=True, nogil=True)
def _path(td, t, K, th0, thmax, r, c_pull, c_rel, f0, gp, gn, comp, length, com, weight, gx, gy, gravity, k3, c, km,
          tr):
    n_steps, n = len(td), len(K)
    theta = np.zeros((n_steps, n))
    tension = np.zeros(n_steps)
    prev = np.zeros(n)
    tg = np.zeros(n)
    tk = np.zeros(n)
    at = np.zeros(n)
    th = np.zeros(n)
    rc = np.zeros(n)
    E = np.zeros(n)
    B = np.zeros(n)
    Es = np.zeros(n)
    Bs = np.zeros(n)
    tau = np.zeros(n)
    bps = np.zeros(4 * n + 1)
    pulling = True
    timed = len(t) == n_steps
    for k in range(n_steps):
        if k > 0 and td[k] != td[k - 1]:
            pulling = td[k] > td[k - 1]
        for i in range(n):
            rc[i] = r[i] * (c_pull[i] if pulling else c_rel[i])
        prev_T = tension[k - 1] if k > 0 else 0.0
        a, b, inv_dt = 0.0, 0.0, 0.0  # as rjcad.physics.finger.step_terms
        if timed and k > 0:
            dt = t[k] - t[k - 1]
            a = math.exp(-dt / tr)
            b = tr * (1.0 - a) / dt
            inv_dt = 1.0 / dt
        for i in range(n):  # the last two readings' extrapolation (as rjcad.physics.finger.simulate_path)
            at[i] = min(max(2.0 * prev[i] - theta[k - 2, i], 0.0), thmax[i]) if gravity and k >= 2 else prev[i]
        T = 0.0
        done = False
        for i in range(n):  # the spring's part of the step's terms (the weight's is added below)
            s = prev[i] + th0[i]
            Es[i] = K[i] * s + k3[i] * s**3 + a * tau[i]
            Bs[i] = K[i] + 3.0 * k3[i] * s**2 + inv_dt * c[i] + km[i] * b
        if gravity:  # as rjcad.physics.finger.path_step: the joints coupled through the weight first
            done, T, _ = _coupled_step(td[k], prev, prev_T, at, Es, Bs, th0, thmax, r, rc, f0, gp, gn, comp, length,
                                       com, weight, gx, gy, th)
        last, w = math.inf, 1.0
        for _ in range(0 if done else (GRAVITY_ITERATIONS if gravity else 1)):  # the fallback: each joint's own slope
            if gravity:
                _gravity(at, length, com, weight, gx, gy, tg, tk)
            for i in range(n):
                E[i] = Es[i] + tg[i]
                B[i] = Bs[i]
                if gravity:
                    kg = max(tk[i], -GRAVITY_SOFTENING * B[i])
                    E[i] -= kg * (at[i] - prev[i])
                    B[i] += kg
            T = _step(td[k], prev, prev_T, E, B, th0, thmax, r, rc, f0, gp, gn, comp, th, bps)
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
        if gravity and not done:  # as path_step: Newton again from the joints' own slopes' answer
            ok, T2, _ = _coupled_step(td[k], prev, prev_T, th.copy(), Es, Bs, th0, thmax, r, rc, f0, gp, gn, comp,
                                      length, com, weight, gx, gy, th)
            if ok:
                T = T2
        for i in range(n):
            tau[i] = a * tau[i] + km[i] * b * (th[i] - prev[i])
            theta[k, i] = th[i]
            prev[i] = th[i]
        tension[k] = T
    return theta, tension


def simulate_angles(m: FingerModel, tendon_mm, t_s=None) -> tuple[np.ndarray, np.ndarray]:
    """θ (steps, N) [rad] and the actuator tension (steps,) [N] along a tendon path [mm] at times ``t_s`` [s]
    (needed when the model has damping or relaxation): as ``rjcad.physics.finger.simulate_path`` (its ``theta``
    and ``tension``)."""
    K, th0, thmax, r, wrap, f0, (gp, gn) = m.arrays()
    k3, c, km, tr = m.rate_arrays()
    td = np.ascontiguousarray(tendon_mm, dtype=float)
    t = path_times(m, td, t_s)
    cum = np.cumsum(wrap)
    comp = 0.0 if math.isinf(m.tendon_stiffness) else 1.0 / m.tendon_stiffness
    length, _, _, weight = m.link_arrays()
    gx, gy = m.gravity if m.gravity is not None else (0.0, 0.0)
    return _path(td, np.zeros(0) if t is None else np.ascontiguousarray(t), K, th0, thmax, r,
                 np.exp(-m.mu_t * cum), np.exp(m.mu_t * cum), f0, gp, gn, comp, length,
                 np.ascontiguousarray(m.link_com, dtype=float), weight, float(gx), float(gy), m.has_gravity,
                 k3, c, km, tr)
