"""What a closure on objects gives, by either engine: per reading the angles, tension and contacts, and the
final grasp's verdict and quality (``rjcad.physics.grasp`` and ``rjcad.mjcf.grasp`` both fill a ``Grasp``).

Grasp quality: the Ferrari–Canny ε of the contacts on each object. Each contact contributes unit forces along its
normal and, with friction μ, along the two edges of its cone (n ± μ t)/‖n ± μ t‖; each force f at point p is the
wrench (f_x, f_y, ((p − c) × f)_z / ρ) about the object's centre c, with ρ the object's radius (so a torque counts
as a force at its rim). ε is the radius of the largest ball about the origin inside the convex hull of these
wrenches: the smallest disturbance, any direction, that a unit sum of contact forces can resist; 0 where the
contacts cannot resist some disturbance (no force closure). A frictionless cylinder's turn about its own axis
changes nothing, so its ε is taken in the forces alone (f_x, f_y). The grasp's quality is the smallest ε over the
objects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: The definition written beside the number in ``grasp.quality``.
EPSILON_DEFINITION = (
    "Ferrari-Canny epsilon: radius of the largest origin-centred ball inside the convex hull of the contacts' "
    "unit primitive wrenches (normal, and friction-cone edges), torque divided by the object's radius; 0 without "
    "force closure"
)


@dataclass
class Contact:
    """One contact of a reading: ``body`` ("link2", or "object1" for one object on another), the ``object``
    (1-based) it presses, the point [mm], the unit normal pointing into the object, and the forces the body applies
    to the object [N]: normal (≥ 0) and tangential (along the normal turned +90°)."""

    body: str
    object: int
    point_mm: tuple[float, float]
    normal: tuple[float, float]
    normal_force_n: float
    tangential_force_n: float = 0.0

    @property
    def force(self) -> np.ndarray:
        """The force on the object [N] in the base's frame: F_n n + F_t t, t the normal turned +90°."""
        nx, ny = self.normal
        return np.array(
            [
                self.normal_force_n * nx - self.tangential_force_n * ny,
                self.normal_force_n * ny + self.tangential_force_n * nx,
            ]
        )

    @property
    def link(self) -> int | None:
        """The link's number (1…N), or None for an object."""
        return int(self.body[4:]) if self.body.startswith("link") else None

    def to_dict(self) -> dict[str, Any]:
        return {
            "body": self.body,
            "object": self.object,
            "point_mm": [float(v) for v in self.point_mm],
            "normal": [float(v) for v in self.normal],
            "normal_force_n": float(self.normal_force_n),
            "tangential_force_n": float(self.tangential_force_n),
        }


def epsilon(contacts: list[Contact], centre: np.ndarray, radius: float, mu: float, turns: bool) -> float:
    """Ferrari–Canny ε of ``contacts`` on one object (see the module); ``turns``: whether its turn matters."""
    from scipy.spatial import ConvexHull, QhullError

    wrenches = []
    for c in contacts:
        n = np.asarray(c.normal, dtype=float)
        t = np.array([-n[1], n[0]])
        arm = np.asarray(c.point_mm, dtype=float) - centre
        for f in [n] if mu == 0 else [n + mu * t, n - mu * t]:
            f = f / np.linalg.norm(f)
            wrenches.append([f[0], f[1], (arm[0] * f[1] - arm[1] * f[0]) / radius])
    w = np.asarray(wrenches, dtype=float).reshape(-1, 3)
    if not turns:
        w = w[:, :2]
    dim = w.shape[1]
    if len(w) <= dim:
        return 0.0
    try:
        hull = ConvexHull(w)
    except QhullError:  # flat: the contacts span less than the wrench space
        return 0.0
    # facets: a·x + b ≤ 0 inside; the origin is inside when every b < 0, at distance −b from the facet
    b = hull.equations[:, -1]
    return float(max(0.0, -b.max()))


@dataclass
class GraspVerdict:
    """The final state's summary: links touching an object, whether every link does, whether a free object was
    pushed away, the largest tension [N], and ε (smallest over the objects)."""

    phalanges_in_contact: list[int]
    enveloping: bool
    ejected: bool
    max_tension_n: float
    epsilon: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "phalanges_in_contact": self.phalanges_in_contact,
            "enveloping": self.enveloping,
            "ejected": self.ejected,
            "max_tension_n": self.max_tension_n,
            "quality": {"epsilon": self.epsilon, "definition": EPSILON_DEFINITION},
        }


@dataclass
class Grasp:
    """A closure on objects: per reading the tendon travel [mm], tension [N], angles [rad], contacts and the
    objects' poses (x, y [mm], angle [rad]); the links in the order they first touched; the engine's name; whether
    a free object was pushed away (and at which reading); the objects' friction and shape for the quality."""

    n: int
    objects: list[Any]
    engine: str = "rjcad"
    tendon_mm: list[float] = field(default_factory=list)
    tension_n: list[float] = field(default_factory=list)
    theta: list[np.ndarray] = field(default_factory=list)
    contacts: list[list[Contact]] = field(default_factory=list)
    poses: list[list[tuple[float, float, float]]] = field(default_factory=list)
    touch_order: list[int] = field(default_factory=list)
    ejected_at: int | None = None

    def record(self, tendon: float, tension: float, theta: np.ndarray, contacts: list[Contact], poses: Any) -> None:
        """Add a reading; note the links touching for the first time."""
        self.tendon_mm.append(float(tendon))
        self.tension_n.append(float(tension))
        self.theta.append(np.array(theta, dtype=float))
        self.contacts.append(list(contacts))
        self.poses.append([(float(p[0]), float(p[1]), float(p[2])) for p in poses])
        for c in contacts:
            if c.link is not None and c.link not in self.touch_order and c.normal_force_n > 0:
                self.touch_order.append(c.link)

    def verdict(self) -> GraspVerdict:
        """The final reading's ``GraspVerdict``."""
        final = self.contacts[-1] if self.contacts else []
        touching = sorted({c.link for c in final if c.link is not None and c.normal_force_n > 0})
        eps = []
        for k, obj in enumerate(self.objects, start=1):
            on = [c for c in final if c.object == k and c.normal_force_n > 0]
            pose = self.poses[-1][k - 1] if self.poses else (obj.x, obj.y, obj.angle)
            turns = obj.kind != "cylinder" or obj.mu > 0
            eps.append(epsilon(on, np.array(pose[:2]), obj.radius, obj.mu, turns) if on else 0.0)
        return GraspVerdict(
            phalanges_in_contact=touching,
            enveloping=len(touching) == self.n,
            ejected=self.ejected_at is not None,
            max_tension_n=max(self.tension_n, default=0.0),
            epsilon=min(eps, default=0.0),
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``simulate finger --object``: per reading ``tendon_mm``, ``tension_n``, ``theta_deg``,
        ``contacts`` and ``objects`` (poses), then ``touch_order`` and ``grasp`` (the verdict)."""
        return {
            "engine": self.engine,
            "tendon_mm": self.tendon_mm,
            "tension_n": self.tension_n,
            "theta_deg": [[math.degrees(a) for a in th] for th in self.theta],
            "contacts": [[c.to_dict() for c in cs] for cs in self.contacts],
            "objects": [
                [{"x_mm": p[0], "y_mm": p[1], "angle_deg": math.degrees(p[2])} for p in ps] for ps in self.poses
            ],
            "object_specs": [o.to_dict() for o in self.objects],
            "touch_order": [f"link{i}" for i in self.touch_order],
            "ejected_at_reading": self.ejected_at,
            "grasp": self.verdict().to_dict(),
        }


#: Drawn contact forces: the largest one drawn this fraction of the finger's length (the plot and the viewer).
ARROW_FRACTION = 0.25


def arrow_scale(contacts: Any, finger_mm: float) -> float:
    """Millimetres per newton for drawing ``contacts`` (an iterable of ``Contact``): the largest force drawn
    ARROW_FRACTION of ``finger_mm`` long (0 without a force)."""
    peak = max((math.hypot(c.normal_force_n, c.tangential_force_n) for c in contacts), default=0.0)
    return ARROW_FRACTION * finger_mm / peak if peak > 0 else 0.0


#: A contact presses when its normal force exceeds this [N] (smaller ones are a solver's rounding).
PRESS_N = 1e-6


def reach(link_length: Any, outlines: Any) -> float:
    """How far from joint 1 the open finger's outlines reach [mm]: the largest Σ_{k<i} L_k + |p| over each link
    i's outline points p (in its frame)."""
    starts = np.r_[0.0, np.cumsum(np.asarray(link_length, dtype=float))[:-1]]
    return float(max(s + float(np.hypot(*np.asarray(o, dtype=float).T).max()) for s, o in zip(starts, outlines)))


def out_of_reach(obj: Any, pose: Any, finger_reach: float) -> bool:
    """Whether a free object's centre is farther from joint 1 than the finger reaches plus its radius: pushed
    out of the finger (ejected, whichever engine)."""
    return bool(obj.free and math.hypot(pose[0], pose[1]) > finger_reach + obj.radius)


def let_go(obj: Any, k: int, pose: Any, contacts: list[Contact]) -> bool:
    """Whether free object ``k`` (1-based) is farther than its radius from where it was placed with no link
    pressing it: pushed, and not held (ejected, whichever engine)."""
    pressed = any(c.object == k and c.link is not None and c.normal_force_n > PRESS_N for c in contacts)
    return bool(obj.free and math.hypot(pose[0] - obj.x, pose[1] - obj.y) > obj.radius and not pressed)
