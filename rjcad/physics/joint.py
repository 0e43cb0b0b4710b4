"""Joint hysteresis model: spring, preload, pin friction, tendon-induced friction, capstan (paper Eq. 3–7).

Units: N, mm, N·mm, rad, s. θ_j is the joint angle from rest, θ = θ_j + θ_0 the
spring deformation, s the sign of the joint velocity (kept through holds).

* bar drive:     τ = K·θ + k3·θ³ + s·μ_j·F_n + c·θ̇ + τ_M
* tendon drive:  τ_req = K·θ + k3·θ³ + s·μ_j·F_n + (γ⁺·θ if s > 0 else −γ⁻·θ) + c·θ̇ + τ_M
                 F_t = β_s·τ_req / r, β_s = β⁺ (pulling) or β⁻ (releasing) when routed, else 1
* Maxwell relaxation arm: dτ_M/dt = K_M·θ̇ − τ_M/T_r.
* bearing friction from the joint's geometry (``Setup.bearing``): r·T = τ_req + s·μ_b·S(θ_j, T), solved for the
  tension T at the joint (rjcad.physics.bearing_table); F_t = β_s·T when routed.

rjcad's β convention (see shared/paper-notes.md): F_t is the force at the
actuator, β⁺ ≥ 1 while pulling, β⁻ ≤ 1 while releasing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from rjcad import DEG
from rjcad.errors import ParameterError
from rjcad.paper import JOINT
from rjcad.validate import in_range

if TYPE_CHECKING:
    from rjcad.physics.bearing_table import FrictionTable


@dataclass(frozen=True)
class JointModel:
    """Parameters of one joint (N·mm/rad, rad, mm, s)."""

    stiffness: float = JOINT.designed_stiffness
    preload: float = 90 * DEG
    mu_j: float = 0.0
    gamma_pos: float = 0.0
    gamma_neg: float = 0.0
    beta_pos: float = 1.0
    beta_neg: float = 1.0
    pulley_radius: float = JOINT.pulley_radius
    viscous: float = 0.0
    cubic: float = 0.0
    relaxation_stiffness: float = 0.0
    relaxation_time: float = 1.0
    #: μ of the bearing's material pair, with friction μ·S(θ_j, T) from the joint's geometry (``Setup.bearing``)
    mu_bearing: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            in_range(f.name, getattr(self, f.name), limit="must be finite")
        in_range("pulley_radius", self.pulley_radius, 0.0, lo_open=True, limit="must be > 0 mm")
        in_range("relaxation_time", self.relaxation_time, 0.0, lo_open=True, limit="must be > 0 s")
        in_range("beta_pos", self.beta_pos, 1.0, limit="must be >= 1 (pulling through the path costs force)")
        in_range(
            "beta_neg", self.beta_neg, 0.0, 1.0, lo_open=True, limit="must be in (0, 1] (releasing needs less force)"
        )
        in_range("viscous", self.viscous, 0.0, limit="must be >= 0")
        in_range("relaxation_stiffness", self.relaxation_stiffness, 0.0, limit="must be >= 0")
        in_range("mu_bearing", self.mu_bearing, 0.0, limit="must be >= 0")

    def with_(self, **kw: float) -> JointModel:
        return replace(self, **kw)

    def to_vector(self, names: Sequence[str] | None = None) -> np.ndarray:
        """The parameters ``names`` (default: all of PARAM_NAMES, in that order) as a float array."""
        return np.array([getattr(self, n) for n in (PARAM_NAMES if names is None else names)], dtype=float)

    @classmethod
    def from_vector(
        cls, x: ArrayLike, names: Sequence[str] | None = None, base: JointModel | None = None
    ) -> JointModel:
        """A model whose parameters ``names`` take the values ``x``; the others come from ``base``."""
        names = PARAM_NAMES if names is None else tuple(names)
        x = np.asarray(x, dtype=float).ravel()
        if len(x) != len(names):
            raise ParameterError("x", len(x), f"needs {len(names)} values, one per name")
        unknown = [n for n in names if n not in PARAM_NAMES]
        if unknown:
            raise ParameterError("names", unknown[0], f"unknown parameter; known: {', '.join(PARAM_NAMES)}")
        return replace(base if base is not None else cls(), **{n: float(v) for n, v in zip(names, x)})


#: Parameter names in vector order (for fitting: JointModel.to_vector / from_vector).
PARAM_NAMES = tuple(f.name for f in fields(JointModel))


@dataclass(frozen=True)
class Setup:
    """An experiment: ``drive`` 'bar' or 'tendon', transverse load F_n [N], tendon routed in the base; ``bearing``:
    the joint's bearing friction per unit μ (rjcad.physics.bearing_table), which a tendon drive loads."""

    drive: str = "bar"
    normal_load: float = 0.0
    routed: bool = False
    bearing: FrictionTable | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        if self.drive not in ("bar", "tendon"):
            raise ParameterError("drive", self.drive, "must be 'bar' or 'tendon'")

    @property
    def quantity(self) -> str:
        return "torque_nmm" if self.drive == "bar" else "tendon_force_n"


def motion_direction(theta: ArrayLike, deadband: float = 0.0, initial: float = 1.0) -> np.ndarray:
    """Sign of the joint velocity per sample, holding the last sign while |Δθ| ≤ deadband [±1]."""
    theta = np.asarray(theta, dtype=float)
    d = np.diff(theta, prepend=theta[:1])
    s = np.where(d > deadband, 1.0, np.where(d < -deadband, -1.0, 0.0))
    idx = np.where(s != 0, np.arange(len(s)), 0)
    np.maximum.accumulate(idx, out=idx)
    out = s[idx]
    first = np.flatnonzero(s)
    out[: first[0] if len(first) else len(s)] = initial if not len(first) else s[first[0]]
    return out


def velocity(theta: ArrayLike, t: ArrayLike) -> np.ndarray:
    """Joint velocity θ̇ by central differences [rad/s]."""
    v: np.ndarray = np.gradient(np.asarray(theta, dtype=float), np.asarray(t, dtype=float))
    return v


def relaxation_torque(theta: ArrayLike, t: ArrayLike, k_m: float, t_r: float) -> np.ndarray:
    """Maxwell arm torque τ_M: dτ_M/dt = K_M·θ̇ − τ_M/T_r, exact for piecewise-linear θ(t) [N·mm].

    τ_k = a_k·τ_{k−1} + K_M·T_r·(1 − a_k)·Δθ_k/Δt_k, a_k = exp(−Δt_k/T_r); τ_0 = 0.
    """
    theta = np.asarray(theta, dtype=float)
    t = np.asarray(t, dtype=float)
    if k_m == 0.0 or len(theta) < 2:
        return np.zeros_like(theta)
    dt = np.diff(t)
    dth = np.diff(theta)
    a = np.exp(-dt / t_r)
    drive = k_m * t_r * (1 - a) * dth / np.where(dt > 0, dt, np.inf)
    if np.ptp(dt) <= 1e-9 * max(dt.mean(), 1e-300):  # uniform steps: a linear filter
        from scipy.signal import lfilter  # here: 1.1 s of import that a joint without relaxation never needs

        tau = lfilter([1.0], [1.0, -a[0]], drive)
    else:
        tau = _decaying_sum(drive, np.cumsum(dt) / t_r)
    return np.concatenate([[0.0], tau])


def _decaying_sum(d: np.ndarray, s: np.ndarray, span: float = 40.0) -> np.ndarray:
    """y_k = e^{−(s_k − s_{k−1})}·y_{k−1} + d_k for non-uniform steps, vectorised.

    y_k = e^{−s_k}·Σ_{j≤k} e^{s_j}·d_j, evaluated in blocks where s grows by at most ``span``
    (so e^{s} stays far from overflow); each block starts from the last value of the previous one.
    """
    y = np.empty_like(d)
    carry, s_prev, i, n = 0.0, 0.0, 0, len(d)
    while i < n:
        j = int(np.searchsorted(s, s[i] + span, side="right"))
        j = max(j, i + 1)
        rel = s[i:j] - s[i]
        y[i:j] = np.exp(-rel) * (np.cumsum(np.exp(rel) * d[i:j]) + carry * math.exp(-(s[i] - s_prev)))
        carry, s_prev, i = y[j - 1], s[j - 1], j
    return y


def spring_torque(m: JointModel, theta_j: ArrayLike) -> np.ndarray:
    """K·θ + k3·θ³ with θ = θ_j + θ_0 [N·mm]."""
    th = np.asarray(theta_j, dtype=float) + m.preload
    return m.stiffness * th + m.cubic * th**3


def simulate(
    m: JointModel,
    setup: Setup,
    theta_j: ArrayLike,
    t: ArrayLike | None = None,
    direction: ArrayLike | None = None,
    velocity_: ArrayLike | None = None,
) -> np.ndarray:
    """The measured quantity along a trajectory: torque [N·mm] (bar) or actuator tendon force [N] (tendon).

    ``t`` (s) is needed for viscous damping and relaxation; ``direction`` (±1) may be given,
    else it is the sign of Δθ held through holds; ``velocity_`` [rad/s] may be given (e.g. a
    smoothed estimate), else it is the central difference of θ_j.
    """
    theta_j = np.asarray(theta_j, dtype=float)
    s = motion_direction(theta_j) if direction is None else np.asarray(direction, dtype=float)
    tau = spring_torque(m, theta_j) + s * m.mu_j * setup.normal_load
    if t is not None and (m.viscous or m.relaxation_stiffness):
        if m.viscous:
            tau = tau + m.viscous * (velocity(theta_j, t) if velocity_ is None else np.asarray(velocity_, float))
        if m.relaxation_stiffness:
            tau = tau + relaxation_torque(theta_j, t, m.relaxation_stiffness, m.relaxation_time)
    if setup.drive == "bar":
        return tau
    force: np.ndarray = np.maximum(_tendon_torque(m, setup, theta_j, s, tau), 0.0) / m.pulley_radius
    return force


def _tendon_torque(m: JointModel, setup: Setup, theta_j: np.ndarray, s: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """β_s·(τ + γ_s-term + s·μ_b·S(θ_j, T)): the torque the tendon must give [N·mm]; negative where it would have
    to push. The bearing term (``setup.bearing``) is solved for the tension at the joint, r·T."""
    th = theta_j + m.preload
    tau = tau + np.where(s > 0, m.gamma_pos * th, -m.gamma_neg * th)
    if setup.bearing is not None and m.mu_bearing > 0.0:
        tau = m.pulley_radius * setup.bearing.tension(tau, s, m.mu_bearing, m.pulley_radius, theta_j)
    if setup.routed:
        tau = tau * np.where(s > 0, m.beta_pos, m.beta_neg)
    return tau


def tendon_slack(m: JointModel, setup: Setup, theta_j: ArrayLike, direction: ArrayLike | None = None) -> np.ndarray:
    """Where a tendon drive would have to push (required force ≤ 0): the tendon is slack there, the joint is
    held by friction and the measured force is 0 (bool per sample; all False for a bar drive). Quasi-static."""
    theta_j = np.asarray(theta_j, dtype=float)
    if setup.drive == "bar":
        return np.zeros(len(theta_j), dtype=bool)
    s = motion_direction(theta_j) if direction is None else np.asarray(direction, dtype=float)
    tau = spring_torque(m, theta_j) + s * m.mu_j * setup.normal_load
    return _tendon_torque(m, setup, theta_j, s, tau) <= 0.0


def loop_width(theta_j: ArrayLike, y: ArrayLike, direction: ArrayLike, taut: ArrayLike | None = None) -> float | None:
    """Mean vertical width of a hysteresis loop: mean over the angles both branches reach (taut samples only)
    of y_forward(θ) − y_backward(θ), each branch interpolated in θ; None when no angle has both."""
    theta_j, y, d = (np.asarray(a, dtype=float) for a in (theta_j, y, direction))
    ok = np.ones(len(y), dtype=bool) if taut is None else np.asarray(taut, dtype=bool)
    f, b = ok & (d > 0), ok & (d < 0)
    if f.sum() < 2 or b.sum() < 2:
        return None
    lo = max(theta_j[f].min(), theta_j[b].min())
    hi = min(theta_j[f].max(), theta_j[b].max())
    if hi <= lo:
        return None
    grid = np.linspace(lo, hi, 101)
    of, ob = np.argsort(theta_j[f]), np.argsort(theta_j[b])
    yf = np.interp(grid, theta_j[f][of], y[f][of])
    yb = np.interp(grid, theta_j[b][ob], y[b][ob])
    return float(np.mean(yf - yb))


def cycle(rotation: float, samples: int = 401) -> tuple[np.ndarray, np.ndarray]:
    """One 0 → rotation → 0 cycle: joint angles [rad] and their motion direction."""
    up = np.linspace(0.0, rotation, samples // 2 + 1)
    th = np.concatenate([up, up[-2::-1]])
    d = np.concatenate([np.ones(len(up)), -np.ones(len(up) - 1)])
    return th, d


#: The paper's measured joint (rjcad.paper.JOINT).
PAPER_JOINT = JointModel(
    stiffness=JOINT.stiffness,
    preload=JOINT.preload,
    mu_j=JOINT.mu_j,
    gamma_pos=JOINT.gamma_pos,
    gamma_neg=JOINT.gamma_neg,
    beta_pos=JOINT.beta_pos,
    beta_neg=JOINT.beta_neg,
    pulley_radius=JOINT.pulley_radius,
)
