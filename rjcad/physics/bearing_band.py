"""A joint's friction band from its own bearing (rjcad.physics.bearing), in the form the finger's physics takes.

The finger's solver (rjcad.physics.finger) gives joint i the Coulomb band f_i = f0_i + γ±_i·(θ_i + θ0_i) (γ⁺
while it closes, γ⁻ while it opens: paper Eq. 4). The bearing model gives the friction of a tendon-driven joint
as τ_f = μ·S(θ_j, T), at the tension T that turns it: r·T = τ_spring + s·τ_f. Over the joint's range, both
directions, τ_f is sampled at that tension and (f0, γ⁺, γ⁻) ≥ 0 fitted by least squares; the fit's RMS and
largest error are kept with it, so that what the linear band leaves out is said, not hidden.

The loads are those of the manifest's bearing block: the tendon's resultant where it leaves the ground's channel
(in a finger, the links beyond a joint and the tendon in them are one body for that joint's bearing), the
springs' end forces, no gravity. Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.optimize import nnls

from rjcad.design.params import JointParams
from rjcad.errors import ParameterError
from rjcad.physics.bearing import BearingLocked, driven, spring_forces
from rjcad.physics.finger_model import FingerModel

#: Poses over the range at which the band is sampled, each direction.
POSES = 9


@dataclass(frozen=True)
class Band:
    """f = f0 + γ±·(θ_j + θ0) [N·mm, N·mm/rad] fitted to a joint's bearing friction at μ; ``rms`` and ``largest``:
    the fit's error over the samples [N·mm]; ``largest_friction``: the largest friction sampled [N·mm]."""

    mu: float
    f0: float
    gamma_pos: float
    gamma_neg: float
    rms: float
    largest: float
    largest_friction: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "mu": self.mu,
            "f0_nmm": round(self.f0, 4),
            "gamma_pos_nmm_per_rad": round(self.gamma_pos, 4),
            "gamma_neg_nmm_per_rad": round(self.gamma_neg, 4),
            "fit_rms_nmm": round(self.rms, 4),
            "fit_largest_error_nmm": round(self.largest, 4),
            "largest_friction_nmm": round(self.largest_friction, 4),
        }


def samples(p: JointParams, mu: float, poses: int = POSES) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """θ_j [rad] and the bearing's friction [N·mm] closing and opening there, each at the tension that turns the
    joint (0 where the spring alone cannot return it: the friction of the springs' own load). Raises
    ``BearingLocked``."""
    springs = spring_forces(p)
    th = np.linspace(0.0, p.rotation, poses)
    up = [driven(p, mu, float(t), 1, "tendon", springs=springs).state.friction_torque for t in th]
    down = [driven(p, mu, float(t), -1, "tendon", springs=springs).state.friction_torque for t in th]
    return th, np.array(up), np.array(down)


def band(p: JointParams, mu: float, poses: int = POSES) -> Band:
    """The :class:`Band` of ``p``'s bearing at μ: non-negative least squares on both directions' samples, each
    weighted by 1/(K ± γ), the slope of its branch, so that what is fitted is the joint's angle."""
    th, up, down = samples(p, mu, poses)
    x = th + p.preload
    zero = np.zeros_like(x)
    a = np.vstack([np.column_stack([np.ones_like(x), x, zero]), np.column_stack([np.ones_like(x), zero, x])])
    y = np.concatenate([up, down])
    k = p.springs * p.spring.rod.stiffness
    g_pos, g_neg = float(x @ up / (x @ x)), float(x @ down / (x @ x))  # through the origin: the weights' γ±
    w = np.concatenate([np.full_like(x, 1 / (k + g_pos)), np.full_like(x, 1 / max(k - g_neg, 0.1 * k))])
    coef, _ = nnls(a * w[:, None], y * w)
    err = a @ coef - y
    return Band(
        mu,
        float(coef[0]),
        float(coef[1]),
        float(coef[2]),
        float(np.sqrt(np.mean(err**2))),
        float(np.abs(err).max()),
        float(y.max()),
    )


class JointLocked(BearingLocked):
    """A finger's joint whose bearing locks at μ (its tendon's own friction outgrows the tendon)."""

    def parameter_error(self, name: str, mu: float) -> ParameterError:
        """The error line of the option or argument ``name`` that gave μ."""
        return ParameterError(name, mu, f"too high for this finger: {self}")


def finger_bands(joints: Sequence[JointParams], mu: float) -> list[Band]:
    """Each joint's :class:`Band` at μ, proximal first; raises ``JointLocked`` naming the first joint that locks."""
    out = []
    for i, p in enumerate(joints, start=1):
        try:
            out.append(band(p, mu))
        except BearingLocked as e:
            raise JointLocked(f"joint {i}: its bearing locks at μ = {mu:g} ({e})") from None
    return out


def with_bearing_friction(m: FingerModel, joints: Sequence[JointParams], mu: float) -> tuple[FingerModel, list[Band]]:
    """``m`` with each joint's friction band from its bearing at μ (``joints``: its designs, proximal first), and
    the bands; raises ``JointLocked``."""
    if len(joints) != m.n:
        raise ParameterError("joints", len(joints), f"must be one design per joint of the model ({m.n})")
    bands = finger_bands(joints, mu)
    model = replace(
        m,
        friction=tuple(b.f0 for b in bands),
        gamma=(),
        gamma_pos=tuple(b.gamma_pos for b in bands),
        gamma_neg=tuple(b.gamma_neg for b in bands),
    )
    return model, bands
