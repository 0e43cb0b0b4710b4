"""The finger links' weight: its torque about each joint and that torque's slope in the joint's own angle.

Pure numpy over a ``rjcad.physics.finger.FingerModel`` ``m`` (that module re-exports these; the model is not
imported here, since its module imports this one): links are point masses [g] at their centres of mass, lengths
in mm, torques in N·mm.
"""

from __future__ import annotations

import math

import numpy as np

G = 9.81e-3  # N per g: weight of a 1 g mass [N/g]


def gravity_terms(m, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Torque of the links' weight about each joint, resisting flexion when positive [N·mm], and its slope in the
    joint's own angle [N·mm/rad].

    Links are point masses w_j at their centres of mass p_j (``link_com``, by default their middles); flexion is
    positive about +Z; g is gravity's direction in the plane. With r_ij = p_j − (joint i):
    τ_i = −Σ_{j≥i} w_j (r_ij × g)_z, and turning joint i turns every r_ij, so ∂τ_i/∂θ_i = Σ_{j≥i} w_j r_ij·g
    (positive where the links hang below the joint: gravity then stiffens it).
    """
    n = m.n
    if not m.has_gravity:
        return np.zeros(n), np.zeros(n)
    gx, gy = m.gravity
    length, lx, ly, w, upper = m.link_arrays()
    ang = np.cumsum(theta)
    c, s = np.cos(ang), np.sin(ang)
    x = np.zeros(n + 1)
    y = np.zeros(n + 1)
    x[1:] = np.cumsum(length * c)  # joint i+1's position: joint i's + the link
    y[1:] = np.cumsum(length * s)
    cx = x[:-1] + lx * c - ly * s  # link j's centre of mass
    cy = y[:-1] + lx * s + ly * c
    rx = cx[None, :] - x[:-1, None]  # r_ij = p_j − (joint i), used where j ≥ i
    ry = cy[None, :] - y[:-1, None]
    tau = -np.sum(np.where(upper, w * (rx * gy - ry * gx), 0.0), axis=1)
    slope = np.sum(np.where(upper, w * (rx * gx + ry * gy), 0.0), axis=1)
    return tau, slope


def gravity_torques(m, theta: np.ndarray) -> np.ndarray:
    """Torque of the links' weight about each joint, resisting flexion when positive [N·mm] (``gravity_terms``)."""
    return gravity_terms(m, theta)[0]
