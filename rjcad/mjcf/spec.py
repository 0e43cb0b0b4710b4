"""What an MJCF of a finger holds, in SI units (m, kg, N·m, rad), and its XML text.

A ``FingerSpec`` is built from a finger manifest and its body meshes (``rjcad.mjcf.export``) or from a
``FingerModel`` with capsule links (``rjcad.mjcf.model``); ``to_xml`` writes either the same way:

* one body per link, nested base → distal; every body frame is the finger frame at rest (bodies at the
  origin of their parent), so meshes, sites and axes keep their built coordinates;
* one hinge per joint at its axis: ``stiffness`` K, ``springref`` = −θ0 (the spring torque at the straight pose
  is K·θ0, pressing the joint on its extension stop), ``range`` [0, rotation] (the stop, then the rotation limit);
* ``path``: a spatial tendon through sites on the built tendon path, with a wrap cylinder of the tendon's
  moment arm on each joint's axis (the eye's groove; the tendon may not cut through it);
* ``tendon``: a fixed tendon, length −Σ r_i·q_i: rjcad's model of the groove (a constant moment arm r_i);
* a position actuator ``pull`` on one of them (``pull_on``), tension only;
* contacts between neighbouring links excluded (they are joined by their hinge).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

#: MJCF names of the two tendons (the spatial one through the sites; the fixed one the groove model)
PATH_TENDON, GROOVE_TENDON = "path", "tendon"
ACTUATOR = "pull"
#: Stiffness of the ``pull`` actuator [N/m] (1 N per mm of tendon length error) and its largest tension [N]
ACTUATOR_KP, ACTUATOR_MAX_N = 1000.0, 100.0


@dataclass(frozen=True)
class BodySpec:
    """A link: mass [kg], centre of mass [m] and inertia about it (ixx iyy izz ixy ixz iyz) [kg·m²], in the
    finger frame at rest; its mesh file (vertices in mm) or a capsule (from, to [m], radius [m])."""

    name: str
    mass: float
    com: tuple[float, float, float]
    inertia: tuple[float, ...]
    mesh_file: str | None = None
    capsule: tuple[tuple[float, ...], tuple[float, ...], float] | None = None


@dataclass(frozen=True)
class JointSpec:
    """A hinge between ``parent`` and ``child``: axis point [m] and unit direction, K [N·m/rad], preload and
    rotation [rad], the tendon's moment arm [m], damping [N·m·s/rad], friction loss [N·m], armature [kg·m²]."""

    parent: str
    child: str
    point: tuple[float, float, float]
    axis: tuple[float, float, float]
    stiffness: float
    preload: float
    rotation: float
    arm: float
    damping: float = 0.0
    frictionloss: float = 0.0
    armature: float = 0.0


@dataclass(frozen=True)
class FingerSpec:
    """Bodies base first, joints proximal first, tendon sites (body, position [m]) base entry to anchor."""

    bodies: tuple[BodySpec, ...]
    joints: tuple[JointSpec, ...]
    sites: tuple[tuple[str, tuple[float, float, float]], ...]
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    pull_on: str = GROOVE_TENDON
    notes: tuple[str, ...] = field(default=())
    model_name: str = "rjcad finger"

    def body(self, name: str) -> BodySpec:
        return next(b for b in self.bodies if b.name == name)


def _f(*values) -> str:
    """Numbers as MJCF text: 9 significant digits, no '-0'."""
    return " ".join(f"{(0.0 if abs(v) < 1e-15 else float(v)):.9g}" for v in values)


def groove_side(spec: FingerSpec, k: int) -> np.ndarray:
    """Unit vector from joint k's axis towards the tendon where it crosses the joint (⟂ the axis)."""
    j = spec.joints[k]
    a, p0 = np.asarray(j.axis), np.asarray(j.point)
    i = crossing(spec, k)
    p, q = np.asarray(spec.sites[i][1]), np.asarray(spec.sites[i + 1][1])
    d = (q - p) / max(float(np.linalg.norm(q - p)), 1e-12)
    w = p + float(np.dot(p0 - p, d)) * d - p0
    w -= float(np.dot(w, a)) * a
    n = float(np.linalg.norm(w))
    return w / n if n > 1e-12 else np.cross(a, d)


def crossing(spec: FingerSpec, k: int) -> int:
    """Index of the last site on joint k's parent side (the tendon crosses the joint after it)."""
    order = [b.name for b in spec.bodies]
    child = order.index(spec.joints[k].child)
    idx = [i for i, (b, _) in enumerate(spec.sites) if order.index(b) < child]
    return idx[-1]


def _body_xml(parent: ET.Element, spec: FingerSpec, b: BodySpec, joint: JointSpec | None, k: int) -> ET.Element:
    el = ET.SubElement(parent, "body", name=b.name, pos="0 0 0")
    ET.SubElement(el, "inertial", pos=_f(*b.com), mass=_f(b.mass), fullinertia=_f(*b.inertia))
    if joint is not None:
        ET.SubElement(
            el,
            "joint",
            name=f"joint{k + 1}",
            type="hinge",
            pos=_f(*joint.point),
            axis=_f(*joint.axis),
            stiffness=_f(joint.stiffness),
            springref=_f(-joint.preload),
            limited="true",
            range=_f(0.0, joint.rotation),
            damping=_f(joint.damping),
            frictionloss=_f(joint.frictionloss),
            armature=_f(joint.armature),
        )
        a, p0 = np.asarray(joint.axis), np.asarray(joint.point)
        centre = p0 + float(np.dot(np.asarray(spec.sites[crossing(spec, k)][1]) - p0, a)) * a  # in the tendon's plane
        side = centre + groove_side(spec, k) * (joint.arm + 0.5e-3)
        ET.SubElement(
            el,
            "geom",
            name=f"groove{k + 1}",
            type="cylinder",
            pos=_f(*centre),
            zaxis=_f(*joint.axis),
            size=_f(joint.arm, 2e-3),
            contype="0",
            conaffinity="0",
            group="3",
            rgba="0.9 0.6 0.2 0.3",
        )
        ET.SubElement(el, "site", name=f"groove{k + 1}_side", pos=_f(*side), size="0.0003", group="3")
    if b.mesh_file is not None:
        ET.SubElement(el, "geom", name=f"{b.name}_mesh", type="mesh", mesh=b.name, group="1")
    else:
        assert b.capsule is not None, f"body {b.name}: neither a mesh nor a capsule"
        (p, q, rad) = b.capsule
        ET.SubElement(el, "geom", name=f"{b.name}_capsule", type="capsule", fromto=_f(*p, *q), size=_f(rad), group="1")
    for i, (owner, pos) in enumerate(spec.sites):
        if owner == b.name:
            ET.SubElement(el, "site", name=f"t{i}", pos=_f(*pos), size="0.0006", rgba="0.9 0.1 0.1 1")
    return el


def _tendons(root: ET.Element, spec: FingerSpec) -> None:
    ten = ET.SubElement(root, "tendon")
    path = ET.SubElement(ten, "spatial", name=PATH_TENDON, width="0.0004", rgba="0.9 0.1 0.1 1")
    wraps = {crossing(spec, k): k for k in range(len(spec.joints))}
    for i in range(len(spec.sites)):
        ET.SubElement(path, "site", site=f"t{i}")
        if i in wraps:
            k = wraps[i]
            ET.SubElement(path, "geom", geom=f"groove{k + 1}", sidesite=f"groove{k + 1}_side")
    fixed = ET.SubElement(ten, "fixed", name=GROOVE_TENDON)
    for k, j in enumerate(spec.joints):
        ET.SubElement(fixed, "joint", joint=f"joint{k + 1}", coef=_f(-j.arm))
    act = ET.SubElement(root, "actuator")
    ET.SubElement(
        act,
        "position",
        name=ACTUATOR,
        tendon=spec.pull_on,
        kp=_f(ACTUATOR_KP),
        forcelimited="true",
        forcerange=_f(-ACTUATOR_MAX_N, 0.0),
    )


def to_xml(spec: FingerSpec) -> str:
    """The MJCF text of ``spec`` (mesh files are referenced by name, relative to the XML file)."""
    root = ET.Element("mujoco", model=spec.model_name)
    for note in spec.notes:
        root.append(ET.Comment(f" {note} "))
    ET.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    ET.SubElement(root, "option", gravity=_f(*spec.gravity), timestep="0.0005", integrator="implicitfast")
    meshes = [(b.name, b.mesh_file) for b in spec.bodies if b.mesh_file is not None]
    if meshes:
        asset = ET.SubElement(root, "asset")
        for name, mesh_file in meshes:
            ET.SubElement(asset, "mesh", name=name, file=mesh_file, scale="0.001 0.001 0.001")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", pos="0 0 1", dir="0 0 -1")
    parent = _body_xml(world, spec, spec.bodies[0], None, -1)
    for k, j in enumerate(spec.joints):
        parent = _body_xml(parent, spec, spec.body(j.child), j, k)
    contact = ET.SubElement(root, "contact")
    for j in spec.joints:
        ET.SubElement(contact, "exclude", body1=j.parent, body2=j.child)
    _tendons(root, spec)
    ET.indent(root, "  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def rod_inertia(mass: float, a, b, radius: float) -> tuple[float, ...]:
    """Inertia about its centre of a solid capsule-like rod from a to b [m] along x (kg·m²), ixx iyy izz 0 0 0."""
    length = float(np.linalg.norm(np.subtract(b, a)))
    along = 0.5 * mass * radius**2
    across = mass * (3 * radius**2 + length**2) / 12.0
    return (along, across, across, 0.0, 0.0, 0.0)


def unit(v: Sequence[float]) -> tuple[float, float, float]:
    n = math.sqrt(sum(x * x for x in v))
    x, y, z = v
    return (float(x) / n, float(y) / n, float(z) / n)
