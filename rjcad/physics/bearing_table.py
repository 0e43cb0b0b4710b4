"""A joint's bearing friction per unit μ over its range and its tendon's tension, and the tension that turns it.

The bearing model (rjcad.physics.bearing) gives the friction of a pose as τ_f = μ·S, S = Σ N_i·ρ_i [N·mm], with
the normal forces N_i from the loads alone (friction is left out of their balance: first order in μ). With the
tendon ending in the moving link and no other load than the springs', S depends on the pose θ_j and the tension
T only. :func:`friction_table` samples S(θ_j, T) once; :meth:`FrictionTable.tension` then solves, for any μ,

    r·T = τ + s·μ·S(θ_j, T)        (s = +1 flexing, −1 releasing; τ the torque the tendon gives without it)

exactly on the table's bilinear interpolation (piecewise linear in T for each θ_j). Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from rjcad.errors import ParameterError

if TYPE_CHECKING:
    from rjcad.design.params import JointParams

#: The table's tension grid reaches this many times the tension that holds the springs at full flexion.
TENSION_REACH = 4.0
#: The tension the table returns where the friction outgrows the tendon (the joint locks), per unit of its top.
LOCKED = 1e3


@dataclass(frozen=True, eq=False)
class FrictionTable:
    """S(θ_j, T) = Σ N_i·ρ_i of a joint's bearing [N·mm per unit μ] at poses ``theta_j`` (I,) [rad] and tendon
    tensions ``tension_grid`` (J,) [N, from 0, rising]; ``s`` (I, J)."""

    theta_j: np.ndarray
    tension_grid: np.ndarray
    s: np.ndarray
    arm: float = 0.0  # the tendon's moment arm the loads were taken at [mm] (0: not given)

    def __post_init__(self) -> None:
        th, t, s = (np.asarray(a, dtype=float) for a in (self.theta_j, self.tension_grid, self.s))
        if th.ndim != 1 or t.ndim != 1 or s.shape != (len(th), len(t)) or len(th) < 2 or len(t) < 2:
            raise ParameterError("friction table", s.shape, "needs s of shape (poses, tensions), at least 2 × 2")
        if not (np.all(np.diff(th) > 0) and np.all(np.diff(t) > 0) and t[0] == 0.0):
            raise ParameterError("friction table", "grid", "poses must rise, tensions rise from 0")
        if not np.all(np.isfinite(s)) or s.min() < 0:
            raise ParameterError("friction table", "s", "must be finite and >= 0")

    def at(self, theta_j: ArrayLike) -> np.ndarray:
        """S at each pose (clamped to the table's range) for every tension of the grid, (n, J) [N·mm]."""
        th = np.clip(np.asarray(theta_j, dtype=float).ravel(), self.theta_j[0], self.theta_j[-1])
        i = np.clip(np.searchsorted(self.theta_j, th, side="right") - 1, 0, len(self.theta_j) - 2)
        w = (th - self.theta_j[i]) / (self.theta_j[i + 1] - self.theta_j[i])
        out: np.ndarray = (1.0 - w)[:, None] * self.s[i] + w[:, None] * self.s[i + 1]
        return out

    def tension(self, torque: ArrayLike, direction: ArrayLike, mu: float, arm: float, theta_j: ArrayLike) -> np.ndarray:
        """The least T ≥ 0 with r·T = τ + s·μ·S(θ_j, T) [N]: 0 where τ + s·μ·S(θ_j, 0) ≤ 0 (the tendon is slack);
        LOCKED × the grid's top where the friction outgrows the tendon beyond the grid."""
        tau = np.asarray(torque, dtype=float).ravel()
        s = np.broadcast_to(np.asarray(direction, dtype=float).ravel(), tau.shape)
        col = self.at(np.broadcast_to(np.asarray(theta_j, dtype=float).ravel(), tau.shape))
        g = self.tension_grid
        # h(T) = r·T − τ − s·μ·S(T): piecewise linear in T; the tension is its first root
        h = arm * g[None, :] - tau[:, None] - (s * mu)[:, None] * col
        up = h >= 0.0
        first = np.argmax(up, axis=1)
        found = up[np.arange(len(tau)), first]
        k = np.maximum(first - 1, 0)
        rows = np.arange(len(tau))
        h0, h1 = h[rows, k], h[rows, k + 1]
        t_in = g[k] + (g[k + 1] - g[k]) * np.divide(-h0, h1 - h0, out=np.zeros_like(h0), where=h1 != h0)
        t = np.where(first == 0, 0.0, t_in)
        # beyond the grid: the last segment's slope carries on; a slope ≤ 0 locks
        slope = (h[:, -1] - h[:, -2]) / (g[-1] - g[-2])
        top = LOCKED * g[-1]
        beyond = np.where(slope > 0, g[-1] - h[:, -1] / np.where(slope > 0, slope, 1.0), top)
        out: np.ndarray = np.where(found, t, np.minimum(beyond, top))
        return out


def friction_table(p: JointParams, poses: int = 13, tensions: int = 10) -> FrictionTable:
    """S(θ_j, T) of the joint ``p`` (a JointParams) from its bearing model: ``poses`` angles over its range and
    ``tensions`` tensions from 0 to TENSION_REACH × the one that holds its springs at full flexion, denser at
    small T (quadratic spacing: the contact set changes there); the tendon ends in the moving link, the springs'
    end forces load the body, no gravity."""
    from rjcad.physics import bearing as B

    th = np.linspace(0.0, p.rotation, poses)
    top = TENSION_REACH * B.spring_torque(p, p.rotation) / p.moment_arm
    grid = top * np.linspace(0.0, 1.0, tensions) ** 2
    springs = B.spring_forces(p)
    contacts = B.contacts_of(p)
    s = np.array(
        [
            [
                B.solve(contacts, [B.tendon_load(p, float(t), float(a)), *springs.loads(float(a))], 1.0).friction_torque
                for t in grid
            ]
            for a in th
        ]
    )
    return FrictionTable(th, grid, s, float(p.moment_arm))
