"""Quasi-static closure of a single-tendon finger with N joints, with stick–slip friction: the public entry points.

Per joint i (proximal first): stiffness K_i, preload θ0_i, range [0, θmax_i], tendon moment arm r_i, Coulomb band
f_i = f0_i + γ_i·(θ_i + θ0_i) (pin friction from an external load, and from the tendon's own load as in paper
Eq. 4; γ_i = γ⁺_i while the joint closes, γ⁻_i while it opens: the paper measured γ⁺ 1.89 and γ⁻ 3.15 N·mm/rad),
capstan wrap α_i of the tendon before joint i (in the channel that feeds it) with coefficient μ_t, and optionally
gravity on the links.

Tension reaching joint i: T_i = T·c_i with c_i = exp(−μ_t·Σ_{k≤i} α_k) while pulling and exp(+μ_t·Σ α_k) while
releasing (T at the actuator). Joint i is in equilibrium when |r_i·T_i − K_i(θ_i + θ0_i) − τg_i| ≤ f_i (stick);
beyond the band it slips to the band's edge. The tendon ties the joints: Σ r_i·θ_i + T/k_t = t_d (k_t: tendon
stiffness), or it is slack (T = 0). Rate and wind-up effects (each optional, per joint): viscous damping c_i·θ̇_i, a
cubic stiffening k3_i·(θ_i + θ0_i)³ and a Maxwell relaxation arm. Where every joint sticks the tension is not
unique: it stays as close to the previous step's as the tendon allows.

The solver is compiled (numba), one loop over the path: ``rjcad.physics.finger_path`` (a step's terms and the
weight), ``rjcad.physics.tendon_step`` (the exact piecewise-linear tendon solve), ``rjcad.physics.coupled`` (the
joints coupled through the weight's full slope, Newton) and ``rjcad.physics.gravity`` (the weight's torque);
``rjcad.physics.kernel`` says how they are compiled. A path allocates its scratch once: a step allocates nothing.
tests/test_physics_finger.py and tests/test_finger_closed_forms.py check it against closed forms and root finders.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rjcad import DEG
from rjcad.errors import ParameterError
from rjcad.physics.finger_model import FingerModel, G
from rjcad.physics.finger_path import closure_path
from rjcad.physics.gravity import gravity_terms, gravity_torques, weight_of

__all__ = [
    "AT_STOP",
    "CLOSING",
    "MOVED_RAD",
    "OPENING",
    "STICKING",
    "Closure",
    "FingerModel",
    "G",
    "capstan_factors",
    "frictionless_optimum",
    "gravity_terms",
    "gravity_torques",
    "joint_states",
    "load_finger_model",
    "model_from_manifest",
    "model_from_template",
    "onset_tendon",
    "path_times",
    "pulling_steps",
    "simulate_angles",
    "simulate_path",
    "simulate_stroke",
    "unbalanced_readings",
    "weight_of",
]

#: A joint counts as moved in a step beyond this [rad], and as on a stop within this of it (``joint_states``).
MOVED_RAD = 1e-12
#: ``Closure.state`` values: sticking, sliding closed, sliding open, resting on a stop.
STICKING, CLOSING, OPENING, AT_STOP = 0.0, 1.0, -1.0, 2.0


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

    def to_dict(self) -> dict[str, Any]:
        return {
            "tendon_mm": self.tendon_mm.tolist(),
            "phase": self.phase,
            "theta_deg": np.degrees(self.theta).T.tolist(),
            "tension_n": self.tension.tolist(),
            "joint_tension_n": self.joint_tension.T.tolist(),
            "state": self.state.T.astype(int).tolist(),
        }


def simulate_stroke(m: FingerModel, stroke: float, steps: int = 500, hold: int = 0) -> Closure:
    """Pull the tendon from 0 to ``stroke`` mm, then release back to 0, in ``steps`` steps each way."""
    up = np.linspace(0.0, stroke, steps + 1)
    td = np.concatenate([up, np.full(hold, stroke), up[-2::-1]])
    phase = ["pull"] * (steps + 1) + ["hold"] * hold + ["release"] * steps
    return simulate_path(m, td, phase)


def simulate_path(
    m: FingerModel,
    tendon_mm: ArrayLike,
    phase: list[str] | None = None,
    t_s: ArrayLike | None = None,
    *,
    coupled: bool = True,
) -> Closure:
    """Quasi-static response along a tendon-displacement path [mm] at times ``t_s`` [s] (needed, and only
    used, when the model has damping or relaxation). ``coupled`` False: the weight enters each step through each
    joint's own slope only (the solver's fallback alone; a check value, readings need not be equilibria)."""
    td = np.ascontiguousarray(tendon_mm, dtype=float)
    theta, tension, slack = _run(m, td, t_s, coupled)
    if phase is None:
        phase = ["pull"] + ["pull" if b > a else ("release" if b < a else "hold") for a, b in itertools.pairwise(td)]
    c_pull, c_release = capstan_factors(m)
    joint_tension = tension[:, None] * np.where(pulling_steps(td)[:, None], c_pull, c_release)
    return Closure(td, list(phase), theta, tension, joint_tension, joint_states(theta, m.arrays()[2]), slack)


def simulate_angles(
    m: FingerModel, tendon_mm: ArrayLike, t_s: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """θ (steps, N) [rad] and the actuator tension (steps,) [N] along a tendon path [mm] at times ``t_s`` [s]
    (needed when the model has damping or relaxation): ``simulate_path``'s ``theta`` and ``tension`` without the
    rest of its ``Closure`` (what identification calls thousands of times)."""
    theta, tension, _ = _run(m, np.ascontiguousarray(tendon_mm, dtype=float), t_s)
    return theta, tension


def capstan_factors(m: FingerModel) -> tuple[np.ndarray, np.ndarray]:
    """(c while pulling, c while releasing): the share of the actuator's tension that reaches each joint,
    c_i = exp(∓μ_t·Σ_{k≤i} α_k) (capstan: the tendon rubs on its path over the wraps α before joint i)."""
    cum = np.cumsum(m.arrays()[4])
    return np.exp(-m.mu_t * cum), np.exp(m.mu_t * cum)


def pulling_steps(td: np.ndarray) -> np.ndarray:
    """Per step, whether the tendon is being pulled: it moved up, or held after moving up (the first step pulls)."""
    step = np.sign(np.diff(td, prepend=-math.inf))
    last_move = np.maximum.accumulate(np.where(step != 0, np.arange(len(td)), 0))
    return step[last_move] > 0


def joint_states(theta: np.ndarray, thmax: np.ndarray) -> np.ndarray:
    """``Closure.state`` of each reading: CLOSING, OPENING or STICKING by the move from the reading before (beyond
    MOVED_RAD), AT_STOP for a joint that rests on a stop (one it did not leave in that step)."""
    moved = np.diff(theta, axis=0, prepend=0.0)
    st = np.where(moved > MOVED_RAD, CLOSING, np.where(moved < -MOVED_RAD, OPENING, STICKING))
    on_stop = ((theta <= MOVED_RAD) & (st <= 0)) | ((theta >= thmax - MOVED_RAD) & (st >= 0))
    return np.where(on_stop, np.where(st == STICKING, AT_STOP, st), st)


def _run(
    m: FingerModel, td: np.ndarray, t_s: ArrayLike | None, coupled: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The compiled path (``rjcad.physics.finger_path.closure_path``) on ``m``'s arrays: θ, tension, slack."""
    K, th0, thmax, r, _, f0, (gp, gn) = m.arrays()
    k3, c, km, tr = m.rate_arrays()
    t = path_times(m, td, t_s)
    comp = 0.0 if math.isinf(m.tendon_stiffness) else 1.0 / m.tendon_stiffness  # the tendon's compliance [mm/N]
    c_pull, c_release = capstan_factors(m)
    w = weight_of(m)  # passed as a plain tuple: its type is found faster at each call
    return closure_path(
        td,
        np.zeros(0) if t is None else np.ascontiguousarray(t),
        (K, k3, c, km, tr),
        (th0, thmax, r, f0, gp, gn),
        c_pull,
        c_release,
        comp,
        (w.length, w.com, w.weight, w.gx, w.gy, w.on),
        coupled,
    )


def path_times(m: FingerModel, td: np.ndarray, t_s: ArrayLike | None) -> np.ndarray | None:
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
    K, th0, thmax, r, _wrap, f0, (gp, gn) = m.arrays()
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
from rjcad.physics.finger_sources import load_finger_model, model_from_manifest, model_from_template  # noqa: E402
