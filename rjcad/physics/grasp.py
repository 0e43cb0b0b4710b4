"""A finger closing on fixed cylinders in its flexion plane: quasi-static, with frictionless unilateral contacts
(issue #40, its first part: no contact friction, no free object, no MuJoCo yet).

Frame: the base's, in mm; the straight finger along +x from joint 1 at the origin, flexion about +z (towards +y,
the palm). Link i runs from axis i to axis i + 1 (the tip for the last) along its direction d_i (the angle
Σ_{k≤i} θ_k); its palmar surface is the segment offset by ``pad`` [mm] towards the palm, n_i = d_i rotated +90°.
A cylinder (centre c, radius R) touches link i where the distance from c to that segment is R.

At tendon travel t_d the angles minimise the stored energy E(θ) = Σ ½ K_i (θ_i + θ0_i)² + ½ k_t s², with the
tendon's stretch s = max(0, t_d − Σ r_i θ_i) (tension T = k_t s), over 0 ≤ θ_i ≤ θmax_i and every gap ≥ 0: the
minimum is the equilibrium with frictionless contacts, whose normal forces are then found from the joints'
balance, K_i (θ_i + θ0_i) = r_i T + Σ_c ((p_c − a_i) × N_c n_c)_z over the contacts c on links j ≥ i (a_i: axis
i; p_c: the contact point, n_c the normal from the cylinder's centre), with a joint stop's reaction where a joint
sits at a limit; all non-negative (non-negative least squares). The closure is followed in small steps of t_d
from the open finger, each minimum started from the last, so that a link meets a cylinder and is never moved
through it. An inextensible tendon (``tendon_stiffness`` = inf) is taken as TENDON_STIFFNESS: against an object
it is the tendon's stretch that sets the grip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rjcad.errors import ParameterError
from rjcad.physics.finger_model import FingerModel
from rjcad.validate import in_range

#: The tendon's stiffness where the model's is infinite [N/mm] (a braided line of ~1 mm over ~200 mm).
TENDON_STIFFNESS = 200.0
#: Default offset of a link's palmar surface from its axis line [mm] (the template's simplified outline).
PAD_MM = 5.0
#: A contact is active when its gap is below this [mm].
TOUCH_MM = 1e-4
#: Tendon travel per step of the closure [mm].
STEP_MM = 0.25
#: Largest turn of a joint per move of the minimiser [rad], and moves per step: the links sweep, not jump.
TURN_RAD, MAX_MOVES = 0.03, 50


@dataclass(frozen=True)
class Cylinder:
    """A fixed cylinder in the flexion plane: centre (x, y) [mm] in the base's frame, diameter [mm]."""

    x: float
    y: float
    diameter: float

    def __post_init__(self) -> None:
        in_range("cylinder x", self.x, limit="must be a finite number [mm]")
        in_range("cylinder y", self.y, limit="must be a finite number [mm]")
        in_range("cylinder diameter", self.diameter, 0.0, 1e4, lo_open=True, hi_open=True, unit="mm")

    @property
    def radius(self) -> float:
        return self.diameter / 2.0


@dataclass
class Contact:
    """One contact of a reading: the link (1…N), the point [mm] and the normal force [N] the object applies."""

    link: int
    point_mm: tuple[float, float]
    normal_force_n: float

    def to_dict(self) -> dict[str, Any]:
        return {"body": f"link{self.link}", "point_mm": list(self.point_mm), "normal_force_n": self.normal_force_n}


@dataclass
class Grasp:
    """The closure on the objects: per reading the tendon travel [mm], angles [rad], tension [N], contacts; the
    order in which the links first touched; and ``blocked`` when the objects stop the tendon from being pulled
    (every joint held)."""

    tendon_mm: list[float] = field(default_factory=list)
    theta: list[np.ndarray] = field(default_factory=list)
    tension_n: list[float] = field(default_factory=list)
    contacts: list[list[Contact]] = field(default_factory=list)
    touch_order: list[int] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "tendon_mm": self.tendon_mm,
            "theta_deg": [[math.degrees(a) for a in th] for th in self.theta],
            "tension_n": self.tension_n,
            "contacts": [[c.to_dict() for c in cs] for cs in self.contacts],
            "touch_order": [f"link{i}" for i in self.touch_order],
            "phalanges_in_contact": sorted({c.link for c in self.contacts[-1]}) if self.contacts else [],
        }


def frames(m: FingerModel, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The axes a_i (n + 1, 2) [mm] (the last: the tip) and the links' directions d_i (n, 2) at ``theta``."""
    lengths = np.asarray(m.link_length, dtype=float)
    ang = np.cumsum(theta)
    d = np.column_stack([np.cos(ang), np.sin(ang)])
    a = np.vstack([np.zeros(2), np.cumsum(d * lengths[:, None], axis=0)])
    return a, d


def closest(m: FingerModel, theta: np.ndarray, c: Cylinder, pad: float) -> tuple[np.ndarray, np.ndarray]:
    """Per link: the point of its palmar segment nearest the cylinder's centre (n, 2) [mm], and its gap (n,) [mm]
    (distance − radius)."""
    a, d = frames(m, theta)
    n = np.column_stack([-d[:, 1], d[:, 0]])  # towards the palm
    start, end = a[:-1] + pad * n, a[1:] + pad * n
    centre = np.array([c.x, c.y])
    seg = end - start
    u = np.clip(np.einsum("ij,ij->i", centre - start, seg) / np.einsum("ij,ij->i", seg, seg), 0.0, 1.0)
    p = start + u[:, None] * seg
    return p, np.linalg.norm(centre - p, axis=1) - c.radius


def _tendon_stiffness(m: FingerModel) -> float:
    return TENDON_STIFFNESS if math.isinf(m.tendon_stiffness) else float(m.tendon_stiffness)


def _equilibrium(
    m: FingerModel, theta: np.ndarray, t_d: float, objects: list[Cylinder], pad: float
) -> tuple[float, list[Contact]]:
    """(tension [N], contacts) at ``theta``: T from the tendon's stretch, the contacts' normal forces and the stops'
    reactions from the joints' balance (non-negative least squares)."""
    from scipy.optimize import nnls

    K, th0, thmax, r = (np.asarray(v, dtype=float) for v in (m.stiffness, m.preload, m.rotation, m.moment_arm))
    T = _tendon_stiffness(m) * max(0.0, t_d - float(r @ theta))
    a, _ = frames(m, theta)
    need = K * (theta + th0) - r * T  # what the contacts and the stops must add, flexing positive
    cols, touching = [], []
    for c in objects:
        p, gap = closest(m, theta, c, pad)
        for j in np.flatnonzero(gap < TOUCH_MM):
            normal = (p[j] - np.array([c.x, c.y])) / max(np.linalg.norm(p[j] - np.array([c.x, c.y])), 1e-12)
            col = np.zeros(len(K))
            for i in range(j + 1):
                arm = p[j] - a[i]
                col[i] = arm[0] * normal[1] - arm[1] * normal[0]
            cols.append(col)
            touching.append((int(j) + 1, p[j]))
    stops = [np.eye(len(K))[i] * (-1.0 if theta[i] >= thmax[i] - 1e-9 else 1.0)
             for i in range(len(K)) if theta[i] >= thmax[i] - 1e-9 or theta[i] <= 1e-9]  # fmt: skip
    A = np.column_stack(cols + stops) if cols or stops else np.zeros((len(K), 0))
    forces = nnls(A, need)[0] if A.shape[1] else np.zeros(0)
    contacts = [Contact(j, (float(p[0]), float(p[1])), float(f)) for (j, p), f in zip(touching, forces)]
    return T, contacts


def close_on(
    m: FingerModel, objects: list[Cylinder], stroke: float, step: float = STEP_MM, pad: float = PAD_MM
) -> Grasp:
    """The finger ``m`` pulled from 0 to ``stroke`` [mm] of tendon travel against fixed ``objects``: a ``Grasp``."""
    from scipy.optimize import minimize

    K, th0, thmax, r = (np.asarray(v, dtype=float) for v in (m.stiffness, m.preload, m.rotation, m.moment_arm))
    kt = _tendon_stiffness(m)
    for c in objects:
        if np.any(closest(m, np.zeros(len(K)), c, pad)[1] < 0):
            raise ParameterError("object", c, "overlaps the open finger")
    out = Grasp()
    theta = np.zeros(len(K))
    for t_d in np.linspace(0.0, stroke, max(2, math.ceil(stroke / step) + 1)):

        def energy(th: np.ndarray, t_d: float = t_d) -> float:
            s = max(0.0, t_d - float(r @ th))
            return 0.5 * float(K @ (th + th0) ** 2) + 0.5 * kt * s * s

        def gradient(th: np.ndarray, t_d: float = t_d) -> np.ndarray:
            s = max(0.0, t_d - float(r @ th))
            return np.asarray(K * (th + th0) - kt * s * r, dtype=float)

        gaps = [{"type": "ineq", "fun": lambda th, c=c: closest(m, th, c, pad)[1]} for c in objects]
        for _ in range(MAX_MOVES):  # within TURN_RAD of where it was: a link never jumps through an object
            lo, hi = np.maximum(theta - TURN_RAD, 0.0), np.minimum(theta + TURN_RAD, thmax)
            res = minimize(
                energy, theta, jac=gradient, method="SLSQP", bounds=list(zip(lo, hi)),
                constraints=gaps, options={"ftol": 1e-14, "maxiter": 500},
            )  # fmt: skip
            new = np.clip(res.x, lo, hi)
            moved_to_edge = np.any((np.abs(new - lo) < 1e-9) & (lo > 0)) or np.any(
                (np.abs(new - hi) < 1e-9) & (hi < thmax)
            )
            theta = new
            if not moved_to_edge:
                break
        T, contacts = _equilibrium(m, theta, float(t_d), objects, pad)
        for touch in contacts:
            if touch.link not in out.touch_order:
                out.touch_order.append(touch.link)
        out.tendon_mm.append(float(t_d))
        out.theta.append(theta.copy())
        out.tension_n.append(T)
        out.contacts.append(contacts)
    return out
