"""The finger links' weight: its torque about each joint and that torque's slope in the joint's own angle.

Links are point masses [g] at their centres of mass, lengths in mm, torques in N·mm. ``weight_torque`` is the
compiled kernel the finger's solver calls at every step; ``gravity_terms`` and ``gravity_torques`` wrap it for a
``rjcad.physics.finger.FingerModel`` ``m`` (that module re-exports them). The links' weights come from the model
in N (``finger_model.G``).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from rjcad.physics.kernel import kernel


class Weight(NamedTuple):
    """The links' weight as the compiled solver reads it: link lengths [mm], centres of mass (n, 2) in each link's
    frame [mm], weights [N], gravity's unit direction (gx, gy) in the finger plane, and whether it acts at all."""

    length: np.ndarray
    com: np.ndarray
    weight: np.ndarray
    gx: float
    gy: float
    on: bool


def weight_of(m: Any) -> Weight:
    """The ``Weight`` of a finger model (a zero direction and ``on`` False when no weight acts)."""
    length, _, _, weight = m.link_arrays()
    gx, gy = m.gravity if m.gravity is not None else (0.0, 0.0)
    com = np.ascontiguousarray(m.link_com, dtype=float)
    return Weight(length, com, weight, float(gx), float(gy), bool(m.has_gravity))


@kernel
def weight_torque(theta: np.ndarray, wt: Weight, tau: np.ndarray, slope: np.ndarray, frame: np.ndarray) -> None:
    """Fills ``tau`` with the weight's torque about each joint, resisting flexion when positive [N·mm], and
    ``slope`` with its slope in that joint's own angle [N·mm/rad], at the angles ``theta`` [rad].

    Flexion is positive about +Z; g = (gx, gy). With r_ij = p_j − (joint i), p_j link j's centre of mass:
    τ_i = −Σ_{j≥i} w_j (r_ij × g)_z, and turning joint i turns every r_ij, so ∂τ_i/∂θ_i = Σ_{j≥i} w_j r_ij·g
    (positive where the links hang below the joint: gravity then stiffens it). ``frame``: (4, n + 1) scratch, left
    holding the joints' positions x, y [mm] and the links' directions cos, sin (``weight_frame``).
    """
    n = len(theta)
    x, y, c, s = frame[0], frame[1], frame[2], frame[3]
    x[0] = y[0] = 0.0
    ang = 0.0
    for i in range(n):
        ang += theta[i]
        c[i], s[i] = math.cos(ang), math.sin(ang)
        x[i + 1] = x[i] + wt.length[i] * c[i]
        y[i + 1] = y[i] + wt.length[i] * s[i]
    for i in range(n):
        torque = 0.0
        stiff = 0.0
        for j in range(i, n):
            rx = x[j] + wt.com[j, 0] * c[j] - wt.com[j, 1] * s[j] - x[i]
            ry = y[j] + wt.com[j, 0] * s[j] + wt.com[j, 1] * c[j] - y[i]
            torque -= wt.weight[j] * (rx * wt.gy - ry * wt.gx)
            stiff += wt.weight[j] * (rx * wt.gx + ry * wt.gy)
        tau[i] = torque
        slope[i] = stiff


@kernel
def weight_frame(n: int) -> np.ndarray:
    """``weight_torque``'s scratch for n joints: made once per path, not once per call."""
    return np.zeros((4, n + 1))


def gravity_terms(m: Any, theta: Any) -> tuple[np.ndarray, np.ndarray]:
    """Torque of the links' weight about each joint, resisting flexion when positive [N·mm], and its slope in the
    joint's own angle [N·mm/rad] (zeros when no weight acts)."""
    tau, slope = np.zeros(m.n), np.zeros(m.n)
    if m.has_gravity:
        weight_torque(np.ascontiguousarray(theta, dtype=float), weight_of(m), tau, slope, weight_frame(m.n))
    return tau, slope


def gravity_torques(m: Any, theta: Any) -> np.ndarray:
    """Torque of the links' weight about each joint, resisting flexion when positive [N·mm] (``gravity_terms``)."""
    return gravity_terms(m, theta)[0]
