"""Quasi-static closure of a single-tendon finger with N joints, with stick–slip friction.

Per joint i (proximal first): stiffness K_i, preload θ0_i, range [0, θmax_i],
tendon moment arm r_i, Coulomb band f_i = f0_i + γ_i·(θ_i + θ0_i) (pin friction
from an external load, and from the tendon's own load as in paper Eq. 4; γ_i = γ⁺_i while the
joint closes, γ⁻_i while it opens: the paper measured γ⁺ 1.89 and γ⁻ 3.15 N·mm/rad),
capstan wrap α_i of the tendon before joint i (in the channel that feeds it)
with coefficient μ_t, and optionally gravity on the links.

Tension reaching joint i: T_i = T·c_i with c_i = exp(−μ_t·Σ_{k≤i} α_k) while
pulling and exp(+μ_t·Σ α_k) while releasing (T at the actuator).

Joint i is in equilibrium when |r_i·T_i − K_i(θ_i + θ0_i) − τg_i| ≤ f_i (stick);
beyond the band it slips to the band's edge. For a given T every θ_i(T) is a
non-decreasing, piecewise-linear function, so the tendon constraint
Σ r_i·θ_i(T) + T/k_t = t_d (k_t: tendon stiffness) is solved exactly on its breakpoints. When even T = 0 leaves
the finger more closed than t_d allows, the tendon is slack: T = 0.
Rate and wind-up effects (each optional, per joint): viscous damping c_i·θ̇_i, a cubic stiffening k3_i·(θ_i + θ0_i)³
and a Maxwell relaxation arm (dτ_M/dt = K_M·θ̇ − τ_M/T_r). Within a step of duration Δt they are linearised about
the previous angle, so each joint's elastic torque is E_i + B_i·(θ_i − θ_prev,i) and the solve stays exact and
piecewise linear: B_i = K_i + 3k3_i·s² + c_i/Δt + K_M,i·b, E_i = K_i·s + k3_i·s³ + a·τ_M,i + τg_i (s = θ_prev + θ0,
a = exp(−Δt/T_r), b = T_r(1 − a)/Δt: the arm's exact update for a constant rate over the step).
With the links' weight, each reading is an equilibrium of the weight's torque at its own angles: the step is
solved with the joints coupled through the weight's full slope and re-linearised (Newton; rjcad.physics.coupled),
with proximal steps where the finger snaps, and each joint's own slope as the fallback (see COUPLED_ITERATIONS).
Where every joint sticks the tension is not unique (any T on a flat stretch of Σ r·θ(T) meets the tendon
constraint): it stays as close to the previous step's as that stretch allows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rjcad.errors import ParameterError
from rjcad.physics import coupled as cp
from rjcad.physics.finger_model import FingerModel  # noqa: F401  (re-exported)
from rjcad.physics.gravity import G, gravity_terms, gravity_torques, weight_terms  # noqa: F401  (re-exported)
from rjcad import DEG


@dataclass
class Closure:
    """A simulated stroke: per step the tendon displacement, phase, angles, tensions and joint states."""

    tendon_mm: np.ndarray
    phase: list[str]
    theta: np.ndarray  # (steps, N) [rad]
    tension: np.ndarray  # (steps,) at the actuator [N]
    joint_tension: np.ndarray  # (steps, N) reaching each joint [N]
    state: np.ndarray  # (steps, N): 0 stick, +1 slip closing, −1 slip opening, 2 at a limit
    slack: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def to_dict(self) -> dict:
        return {
            "tendon_mm": self.tendon_mm.tolist(),
            "phase": self.phase,
            "theta_deg": np.degrees(self.theta).T.tolist(),
            "tension_n": self.tension.tolist(),
            "joint_tension_n": self.joint_tension.T.tolist(),
            "state": self.state.T.astype(int).tolist(),
        }


#: The weight's slope enters a step's linearisation down to −this × the joint's own step stiffness B (a weight
#: that softens a joint more than that tips it over: the step stays a step, the snap takes a few).
GRAVITY_SOFTENING = 0.9
#: With gravity, a step is first solved with the joints coupled through the weight's full slope
#: (rjcad.physics.coupled), re-linearised about its result (Newton) up to COUPLED_ITERATIONS times until no angle
#: moves by more than GRAVITY_TOL [rad]: each reading is an equilibrium. Once a move is not at most
#: GRAVITY_CONTRACTION of the one before, each joint's torque gets λ(θ − at) with H + λI's smallest eigenvalue
#: GRAVITY_MARGIN × min(B) (proximal steps towards a stable equilibrium: where the finger snaps they take most of
#: the budget). Where that finds none either, the step falls back to each joint's own slope (a diagonal H,
#: ``step_terms``), re-linearised the same way up to GRAVITY_ITERATIONS times, and the coupled step starts once
#: more from that answer (which is returned only where that finds no equilibrium either).
COUPLED_ITERATIONS = 200
GRAVITY_ITERATIONS = 40
GRAVITY_TOL = 1e-7
GRAVITY_CONTRACTION = 0.5
GRAVITY_MARGIN = 0.5


def step_terms(m: FingerModel, prev, tg, dt: float, tau_m, tg_slope=None, at=None):
    """(E, B, a, b) of a step of ``dt`` s from the angles ``prev``: each joint's elastic torque is E + B·(θ − prev)
    [N·mm]; the Maxwell arm's torque after the step is a·τ_M + K_M·b·(θ − prev). ``dt`` = inf: no rate terms
    (a first step, or a rate-independent model).

    ``tg``, ``tg_slope``: the weight's torque and its slope (``gravity_terms``) at the angles ``at`` (default
    ``prev``); the weight enters as tg + k_g·(θ − at), k_g = max(tg_slope, −GRAVITY_SOFTENING·B). The slope makes
    the weight implicit in the step: an explicit weight stiffer than the spring flips the joint step to step.
    """
    K, th0 = m.arrays()[:2]
    k3, c, km, tr = m.rate_arrays()
    s = prev + th0
    a = 0.0 if math.isinf(dt) else math.exp(-dt / tr)
    b = 0.0 if math.isinf(dt) else tr * (1.0 - a) / dt
    E = K * s + k3 * s**3 + a * tau_m + tg
    B = K + 3.0 * k3 * s**2 + (0.0 if math.isinf(dt) else 1.0 / dt) * c + km * b
    if tg_slope is not None:
        kg = np.maximum(tg_slope, -GRAVITY_SOFTENING * B)
        if at is not None:
            E = E - kg * (np.asarray(at) - prev)
        B = B + kg
    return E, B, a, b


def path_step(m: FingerModel, t_d: float, prev, pulling: bool, prev_T: float, dt: float, tau_m, guess=None):
    """One step of ``simulate_path``: (θ, T, joint tensions, slack, a, b) at t_d from ``prev``. With gravity the
    weight is re-linearised about the step's result until it is an equilibrium (see COUPLED_ITERATIONS), starting
    from ``guess`` (default ``prev``; the path passes the last two readings' extrapolation)."""
    if m.has_gravity:
        got = coupled_step(m, t_d, prev, pulling, prev_T, dt, tau_m, guess)
        if got is not None:
            return got
    at, last, w = (prev if guess is None else guess), math.inf, 1.0
    for _ in range(GRAVITY_ITERATIONS if m.has_gravity else 1):
        tg, tg_slope = gravity_terms(m, at)
        E, B, a, b = step_terms(m, prev, tg, dt, tau_m, tg_slope, at)
        th, T, ti, slack = equilibrium(m, t_d, prev, pulling, None, prev_T, (E, B))
        moved = float(np.max(np.abs(th - at), initial=0.0))
        if moved <= GRAVITY_TOL:
            break
        if moved > GRAVITY_CONTRACTION * last:
            w = 0.5
        last = moved
        at = at + w * (th - at)
    if m.has_gravity:  # the joints' own slopes found an answer near an equilibrium: Newton from there again
        got = coupled_step(m, t_d, prev, pulling, prev_T, dt, tau_m, th)
        if got is not None:
            return got
    return th, T, ti, slack, a, b


def coupled_step(m: FingerModel, t_d: float, prev, pulling: bool, prev_T: float, dt: float, tau_m, guess=None):
    """``path_step`` with the joints coupled through the weight's full slope (rjcad.physics.coupled), or None
    where no equilibrium was found within COUPLED_ITERATIONS linearisations."""
    n = m.n
    K, th0, thmax, r, wrap, f0, (gp, gn) = m.arrays()
    cum = np.cumsum(wrap)
    c = np.exp(-m.mu_t * cum) if pulling else np.exp(m.mu_t * cum)
    comp = 0.0 if math.isinf(m.tendon_stiffness) else 1.0 / m.tendon_stiffness
    tol = FLAT_MM * max(1.0, abs(t_d))
    E0, B, a, b = step_terms(m, prev, np.zeros(n), dt, tau_m)  # the spring's part: the weight's is added below
    E0, B, pl = E0.tolist(), B.tolist(), prev.tolist()
    consts = (th0.tolist(), thmax.tolist(), r.tolist(), (r * c).tolist(), f0.tolist(), gp.tolist(), gn.tolist())
    at = pl if guess is None else guess.tolist()
    state = [cp.UP if x > p + 1e-12 else (cp.DOWN if x < p - 1e-12 else cp.STICK) for x, p in zip(at, pl)] + [False]
    damped, last = False, math.inf
    for _ in range(COUPLED_ITERATIONS):
        tg, slope = weight_terms(m, at)
        # the weight's torque over the step: tg + G·(θ − at), G_ij = slope_max(i,j)
        H = [[slope[max(i, j)] for j in range(n)] for i in range(n)]
        E = [E0[i] + tg[i] + sum(H[i][j] * (pl[j] - at[j]) for j in range(n)) for i in range(n)]
        for i in range(n):
            H[i][i] += B[i]
        if damped:  # proximal: + λ(θ − at), H + λI positive definite
            lam = GRAVITY_MARGIN * min(B) - float(np.linalg.eigvalsh(np.array(H))[0])
            if lam > 0:
                for i in range(n):
                    H[i][i] += lam
                    E[i] += lam * (pl[i] - at[i])
        got = cp.coupled_solve(cp.Step(t_d, pl, prev_T, E, H, *consts, comp, tol), state)
        if got is None:
            if damped:
                return None
            damped = True
            continue
        d, T, slack = got
        th = [p + x for p, x in zip(pl, d)]
        moved = max(abs(x - y) for x, y in zip(th, at))
        if moved <= GRAVITY_TOL and not damped:
            return np.clip(th, 0.0, thmax), T, T * c, slack, a, b
        # Newton while its moves contract; proximal steps while they do not (a snap: the joints run to another
        # equilibrium), back to Newton once they do
        damped = moved > GRAVITY_CONTRACTION * last
        last = moved
        at = th
    return None


def _theta_of_T(T, prev, E, B, th0, thmax, rc, f0, gam):
    """θ_i(T) for every joint given the previous angles (vectorised over joints; T may be a column of tensions).

    The joint closes once r·c·T passes E + f0 + γ⁺·s, opens below E − f0 − γ⁻·s (s = θ_prev + θ0), and moves
    along the band's edge with its torque E + B·(θ − θ_prev).
    """
    gp, gn = gam
    s = prev + th0
    up_T = (E + f0 + gp * s) / rc
    dn_T = (E - f0 - gn * s) / rc
    up = (rc * T - E - f0 - gp * th0 + B * prev) / (B + gp)
    dn = (rc * T - E + f0 + gn * th0 + B * prev) / (B - gn)
    th = np.where(T >= up_T, np.maximum(up, prev), np.where(T <= dn_T, np.minimum(dn, prev), prev))
    return np.clip(th, 0.0, thmax)


def _breakpoints(prev, E, B, th0, thmax, rc, f0, gam):
    gp, gn = gam
    s = prev + th0
    return np.concatenate([
        (E + f0 + gp * s) / rc,
        (E - f0 - gn * s) / rc,
        (E + B * (thmax - prev) + f0 + gp * (thmax + th0)) / rc,
        (E - B * prev - f0 - gn * th0) / rc,
    ])


#: Σ r·θ within this of t_d [mm] counts as meeting it: where every joint sticks, S(T) is flat and the tension
#: anywhere on that flat stretch solves the constraint.
FLAT_MM = 1e-7


def equilibrium(m: FingerModel, t_d: float, prev: np.ndarray, pulling: bool, tg: np.ndarray | None = None,
                prev_T: float = 0.0, terms=None):
    """Angles, actuator tension and joint tensions at tendon displacement t_d, from the previous angles.

    ``terms``: (E, B) of the step (``step_terms``), which already hold any weight; without them, the spring
    alone plus ``tg`` (the weight's torque at ``prev``, held constant over the step). Giving both is an error.
    Where the tendon constraint holds for a range of tensions (every joint sticking, the tendon inextensible),
    the tension stays as close to ``prev_T`` as that range allows: nothing moved, so nothing changed.
    """
    if terms is not None and tg is not None:
        raise ValueError("equilibrium: give the weight's torque in `terms` (step_terms) or as `tg`, not both")
    K, th0, thmax, r, wrap, f0, gam = m.arrays()
    tg = np.zeros(m.n) if tg is None else tg
    E, B = terms if terms is not None else step_terms(m, prev, tg, math.inf, np.zeros(m.n))[:2]
    cum = np.cumsum(wrap)
    c = np.exp(-m.mu_t * cum) if pulling else np.exp(m.mu_t * cum)
    rc = r * c
    comp = 0.0 if math.isinf(m.tendon_stiffness) else 1.0 / m.tendon_stiffness
    args = (prev, E, B, th0, thmax, rc, f0, gam)
    theta0 = _theta_of_T(0.0, *args)
    if float(r @ theta0) >= t_d:
        return theta0, 0.0, np.zeros(m.n), True
    bps = _breakpoints(*args)
    bps = np.unique(np.clip(bps[np.isfinite(bps)], 0.0, None))
    grid = np.concatenate([[0.0], bps])
    S = _theta_of_T(grid[:, None], *args) @ r + comp * grid  # all at once
    tol = FLAT_MM * max(1.0, abs(t_d))
    if S[-1] < t_d - tol:
        if comp == 0.0:  # every joint at its limit: the tendon cannot be pulled further
            T = float(grid[-1])
            return _theta_of_T(T, *args), T, T * c, False
        T = float(grid[-1]) + (t_d - S[-1]) / comp  # only the tendon stretches beyond that
        return _theta_of_T(T, *args), T, T * c, False
    k = int(np.searchsorted(S, t_d - tol))  # the first grid tension that meets t_d (to within tol) or passes it
    if S[k] <= t_d + tol:  # met at grid[k], and on along a flat stretch: keep the previous tension if on it
        j = k + int(np.searchsorted(S[k:], t_d + tol, side="right")) - 1
        T = min(max(prev_T, float(grid[k])), float(grid[j]))
    else:  # passed between grid[k-1] and grid[k]: S is linear there
        T0, T1, S0, S1 = grid[k - 1], grid[k], S[k - 1], S[k]
        T = T0 + (t_d - S0) * (T1 - T0) / (S1 - S0)
    return _theta_of_T(T, *args), float(T), T * c, False


def simulate_stroke(m: FingerModel, stroke: float, steps: int = 500, hold: int = 0) -> Closure:
    """Pull the tendon from 0 to ``stroke`` mm, then release back to 0, in ``steps`` steps each way."""
    up = np.linspace(0.0, stroke, steps + 1)
    td = np.concatenate([up, np.full(hold, stroke), up[-2::-1]])
    phase = ["pull"] * (steps + 1) + ["hold"] * hold + ["release"] * steps
    return simulate_path(m, td, phase)


def simulate_path(m: FingerModel, tendon_mm, phase: list[str] | None = None, t_s=None) -> Closure:
    """Quasi-static response along a tendon-displacement path [mm] at times ``t_s`` [s] (needed, and only
    used, when the model has damping or relaxation)."""
    td = np.asarray(tendon_mm, dtype=float)
    t = path_times(m, td, t_s)
    n = m.n
    thmax = np.asarray(m.rotation, float)
    theta = np.zeros((len(td), n))
    T = np.zeros(len(td))
    Ti = np.zeros((len(td), n))
    state = np.zeros((len(td), n))
    slack = np.zeros(len(td), dtype=bool)
    prev = np.zeros(n)
    tau_m = np.zeros(n)
    km = np.asarray(m.relax_stiffness, float)
    pulling = True
    if phase is None:
        phase = ["pull"] + ["pull" if b > a else ("release" if b < a else "hold") for a, b in zip(td[:-1], td[1:])]
    for k, t_d in enumerate(td):
        if k and td[k] != td[k - 1]:
            pulling = td[k] > td[k - 1]
        dt = math.inf if t is None or k == 0 else float(t[k] - t[k - 1])
        guess = np.clip(2.0 * prev - theta[k - 2], 0.0, thmax) if k >= 2 and m.has_gravity else None
        th, Tk, tik, sl, a, b = path_step(m, float(t_d), prev, pulling, T[k - 1] if k else 0.0, dt, tau_m, guess)
        tau_m = a * tau_m + km * b * (th - prev)
        moved = th - prev
        st = np.where(moved > 1e-12, 1.0, np.where(moved < -1e-12, -1.0, 0.0))
        st = np.where((th <= 1e-12) & (st <= 0) | (th >= thmax - 1e-12) & (st >= 0), np.where(st == 0, 2.0, st), st)
        theta[k], T[k], Ti[k], state[k], slack[k] = th, Tk, tik, st, sl
        prev = th
    return Closure(td, list(phase), theta, T, Ti, state, slack)


def path_times(m: FingerModel, td: np.ndarray, t_s) -> np.ndarray | None:
    """The path's times [s] when the model needs them (strictly increasing, one per step), else None."""
    if not m.rate_dependent:
        return None
    if t_s is None:
        raise ParameterError("t_s", None, "the model has damping or relaxation: the path needs its times [s]")
    t = np.asarray(t_s, dtype=float)
    if t.shape != td.shape or not np.all(np.isfinite(t)) or (len(t) > 1 and np.min(np.diff(t)) <= 0):
        raise ParameterError("t_s", t.shape, f"must be {len(td)} finite, strictly increasing times [s]")
    return t


def unbalanced_readings(m: FingerModel, c: Closure, tol: float = 1e-6) -> int:
    """Check value: how many readings have a joint between its stops outside its friction band, the weight taken at
    the reading's own angles: r·T_i − K(θ + θ0) − τ_g(θ) ∉ [−f0 − γ⁻(θ + θ0), f0 + γ⁺(θ + θ0)] ± tol [N·mm]."""
    K, th0, thmax, r, wrap, f0, (gp, gn) = m.arrays()
    bad = 0
    for th, ti in zip(c.theta, c.joint_tension):
        net = r * ti - K * (th + th0) - gravity_torques(m, th)
        inside = (th > 1e-9) & (th < thmax - 1e-9)
        ok = (net <= f0 + gp * (th + th0) + tol) & (net >= -f0 - gn * (th + th0) - tol)
        bad += int(not np.all(ok | ~inside))
    return bad


def frictionless_optimum(m: FingerModel, t_d: float) -> np.ndarray:
    """Closed-form check value: θ minimising Σ½K_i(θ_i+θ0_i)² s.t. Σ r_i θ_i = t_d, 0 ≤ θ ≤ θmax.

    KKT: θ_i = clip(λ·r_i/K_i − θ0_i, 0, θmax_i) with λ (the tension) found by bisection.
    """
    K, th0, thmax, r, *_ = m.arrays()
    lo, hi = 0.0, float(np.max(K * (thmax + th0) / r)) * 2 + 1
    for _ in range(200):
        lam = (lo + hi) / 2
        s = r @ np.clip(lam * r / K - th0, 0, thmax)
        lo, hi = (lam, hi) if s < t_d else (lo, lam)
    return np.clip(hi * r / K - th0, 0, thmax)


def onset_tendon(closure: Closure, threshold: float = 1 * DEG) -> np.ndarray:
    """Tendon displacement at which each joint first exceeds ``threshold`` during the pull [mm]."""
    pull = np.array([p == "pull" for p in closure.phase])
    out = np.full(closure.theta.shape[1], np.nan)
    for i in range(closure.theta.shape[1]):
        idx = np.flatnonzero(pull & (closure.theta[:, i] > threshold))
        if len(idx):
            out[i] = closure.tendon_mm[idx[0]]
    return out


# the model from a manifest, a template or a file (rjcad/physics/finger_sources.py), re-exported
from rjcad.physics.finger_sources import (load_finger_model, model_from_manifest,  # noqa: E402,F401
                                          model_from_template)
