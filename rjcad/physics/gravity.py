"""The finger links' weight: its torque about each joint and that torque's slope in the joint's own angle.

Pure numpy over a ``rjcad.physics.finger.FingerModel`` ``m`` (that module re-exports these; the model is not
imported here, since its module imports this one): links are point masses [g] at their centres of mass, lengths
in mm, torques in N·mm.
"""

from __future__ import annotations

import math

import numpy as np

G = 9.81e-3  # N per g: weight of a 1 g mass [N/g]


def gravity_terms(m, theta) -> tuple[np.ndarray, np.ndarray]:
    """Torque of the links' weight about each joint, resisting flexion when positive [N·mm], and its slope in the
    joint's own angle [N·mm/rad] (``weight_terms`` as arrays)."""
    if not m.has_gravity:
        return np.zeros(m.n), np.zeros(m.n)
    tau, slope = weight_terms(m, np.asarray(theta, dtype=float).tolist())
    return np.array(tau), np.array(slope)


def weight_terms(m, theta: list) -> tuple[list, list]:
    """``gravity_terms`` over Python floats (a finger has a few joints: a loop beats small-array numpy).

    Links are point masses w_j at their centres of mass p_j (``link_com``, by default their middles); flexion is
    positive about +Z; g is gravity's direction in the plane. With r_ij = p_j − (joint i):
    τ_i = −Σ_{j≥i} w_j (r_ij × g)_z, and turning joint i turns every r_ij, so ∂τ_i/∂θ_i = Σ_{j≥i} w_j r_ij·g
    (positive where the links hang below the joint: gravity then stiffens it). The sums over j ≥ i are taken
    from the tip: Σ w_j r_ij = Σ w_j p_j − W_i·(joint i), W_i = Σ_{j≥i} w_j.
    """
    gx, gy = m.gravity
    length, lx, ly, w = m.link_lists()
    n = len(length)
    xs, ys, cxs, cys = [0.0] * n, [0.0] * n, [0.0] * n, [0.0] * n
    ang = x = y = 0.0
    for j in range(n):
        ang += theta[j]
        c, s = math.cos(ang), math.sin(ang)
        xs[j], ys[j] = x, y
        cxs[j], cys[j] = x + lx[j] * c - ly[j] * s, y + lx[j] * s + ly[j] * c
        x, y = x + length[j] * c, y + length[j] * s
    tau, slope = [0.0] * n, [0.0] * n
    W = mx = my = 0.0
    for i in range(n - 1, -1, -1):
        W, mx, my = W + w[i], mx + w[i] * cxs[i], my + w[i] * cys[i]
        rx, ry = mx - W * xs[i], my - W * ys[i]  # Σ_{j≥i} w_j r_ij
        tau[i] = ry * gx - rx * gy
        slope[i] = rx * gx + ry * gy
    return tau, slope


def gravity_torques(m, theta: np.ndarray) -> np.ndarray:
    """Torque of the links' weight about each joint, resisting flexion when positive [N·mm] (``gravity_terms``)."""
    return gravity_terms(m, theta)[0]
