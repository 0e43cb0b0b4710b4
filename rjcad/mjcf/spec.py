"""What an MJCF of a finger holds, in SI units (m, kg, N·m, rad), and its XML text.

A ``FingerSpec`` is built from a finger manifest and its body meshes (``rjcad.mjcf.export``) or from a
``FingerModel`` with capsule links (``rjcad.mjcf.model``). It is in the finger frame at rest (x along the straight
finger, y towards the palm, z along the joint axes; joint 1's axis through the origin): ``to_xml`` changes frames
as it writes, laid out like the models of MuJoCo Menagerie:

* one body per link, nested base → distal, each body's frame at its joint's axis point (the base's at the finger
  frame's origin), axes parallel to the finger frame's; its inertial, geoms and sites offset by −that point; the
  hinge at the body's origin (``pos`` 0 0 0);
* the base mounted ``mount_height`` above the floor, turned (``mount_quat``) so that the spec's gravity, a vector in
  the finger frame, points down (−z); ``option gravity`` is then 0 0 −|g| (0 0 0 without gravity);
* ``<default>`` classes under ``rjcad``: ``joint`` (hinge defaults, stiff limits ``LIMIT_SOLREF``/``LIMIT_SOLIMP``),
  ``visual`` (group 2, no contact), ``collision`` (group 3: a box around each body's mesh, or its capsule;
  contact with the world, not between the finger's links), ``route`` (tendon sites and the grooves' wrap
  cylinders: group 4, no contact);
* one hinge per joint: ``stiffness`` K, ``springref`` = −θ0 (the spring presses the joint on its extension stop
  with K·θ0 at the straight pose), ``range`` [0, rotation];
* ``path``: a spatial tendon through the sites, wrapping a cylinder of the tendon's moment arm on each joint's
  axis (the eye's groove); ``tendon``: a fixed tendon, length −Σ r_i·q_i, rjcad's model (constant moment arms);
* actuator ``pull`` on one of them (``pull_on``): a position servo on the tendon pull p = L_rest − L [m]
  (gear −1: force KP·(ctrl − p) − KV·ṗ, pulling only), ``ctrlrange`` 0 → ``full_stroke``;
* sensors: each hinge's angle, the pulled tendon's length, the actuator's force (the tension, N);
* keyframe ``home``: the straight rest pose, ctrl 0; contacts between neighbouring links excluded.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

#: MJCF names of the two tendons (the spatial one through the sites; the fixed one the groove model)
PATH_TENDON, GROOVE_TENDON = "path", "tendon"
ACTUATOR = "pull"
#: The ``pull`` servo: stiffness [N/m] (1 N per 0.1 mm of pull error), damping [N·s/m], largest tension [N]
ACTUATOR_KP, ACTUATOR_KV, ACTUATOR_MAX_N = 1e4, 50.0, 100.0
#: Time step [s]; joint limits: time constant 2·TIMESTEP (MuJoCo's stiffest safe value), damping ratio 1, and
#: impedance 0.95 → 0.99 within 0.1 mrad: each spring's preload rests on its stop within a few µrad
TIMESTEP = 5e-4
LIMIT_SOLREF, LIMIT_SOLIMP = (2 * TIMESTEP, 1.0), (0.95, 0.99, 1e-4)
#: The mount: the finger's reach (from joint 1's axis) plus this clearance [m] above the floor of scene.xml
MOUNT_CLEARANCE_M = 0.02
#: The class every element of the model takes (its children: joint, visual, collision, route)
CLASS = "rjcad"


@dataclass(frozen=True)
class BodySpec:
    """A link in the finger frame at rest: mass [kg], centre of mass [m] and inertia about it (ixx iyy izz ixy ixz
    iyz) [kg·m²]; its mesh file (vertices in mm, finger frame) with a collision box (centre, half sizes [m]) around
    it, or a capsule (from, to [m], radius [m])."""

    name: str
    mass: float
    com: tuple[float, float, float]
    inertia: tuple[float, ...]
    mesh_file: str | None = None
    capsule: tuple[tuple[float, ...], tuple[float, ...], float] | None = None
    box: tuple[tuple[float, ...], tuple[float, ...]] | None = None


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
    """Bodies base first, joints proximal first, tendon sites (body, position [m]) base entry to anchor; gravity
    [m/s²] in the finger frame."""

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


def _sub(p: ArrayLike, o: np.ndarray) -> str:
    """Point p [m] in the frame of a body whose origin is o (axes parallel), as MJCF text."""
    return _f(*(np.asarray(p, dtype=float) - o))


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


def origin(spec: FingerSpec, body: str) -> np.ndarray:
    """A body's frame origin in the finger frame [m]: its joint's axis point (the base: the finger's origin)."""
    j = next((j for j in spec.joints if j.child == body), None)
    return np.zeros(3) if j is None else np.asarray(j.point, dtype=float)


def mount_quat(g: Sequence[float]) -> tuple[float, float, float, float]:
    """Quaternion (w, x, y, z) of the smallest rotation taking gravity's direction in the finger frame to −z
    (the base's orientation in the world); the identity without gravity."""
    n = float(np.linalg.norm(g))
    if n == 0.0:
        return (1.0, 0.0, 0.0, 0.0)
    u, down = np.asarray(g, dtype=float) / n, np.array([0.0, 0.0, -1.0])
    c = float(np.dot(u, down))
    if c < -1.0 + 1e-12:  # gravity along +z: half a turn about x
        return (0.0, 1.0, 0.0, 0.0)
    axis = np.cross(u, down)
    w = math.sqrt((1.0 + c) / 2.0)
    x, y, z = axis / (2.0 * w)
    return (w, float(x), float(y), float(z))


def _reach(spec: FingerSpec, b: BodySpec) -> float:
    """The farthest a point of body b can be from its own frame's origin [m] (box corners or capsule ends)."""
    o = origin(spec, b.name)
    if b.box is not None:
        c, h = np.asarray(b.box[0]), np.asarray(b.box[1])
        corners = c + h * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        return float(np.linalg.norm(corners - o, axis=1).max())
    assert b.capsule is not None, f"body {b.name}: neither a mesh box nor a capsule"
    p, q, rad = b.capsule
    return max(float(np.linalg.norm(np.asarray(p) - o)), float(np.linalg.norm(np.asarray(q) - o))) + rad


def mount_height(spec: FingerSpec) -> float:
    """Height of the base's frame above the floor [m]: the finger's reach from joint 1's axis in any pose (each
    joint's distance to the next plus the last body's reach, the most of any body) plus MOUNT_CLEARANCE_M, rounded
    up to the centimetre."""
    reach, chain = _reach(spec, spec.bodies[0]), 0.0
    for j in spec.joints:
        chain += float(np.linalg.norm(np.asarray(j.point) - origin(spec, j.parent)))
        reach = max(reach, chain + _reach(spec, spec.body(j.child)))
    return math.ceil((reach + MOUNT_CLEARANCE_M) * 100.0 - 1e-9) / 100.0


def _rotation(axis: Sequence[float], angle: float) -> np.ndarray:
    """Rotation matrix of ``angle`` [rad] about the unit ``axis`` (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def site_polyline(spec: FingerSpec, q: Sequence[float]) -> float:
    """Length [m] of the straight runs between the tendon sites with the joints at angles q [rad] (the spatial
    tendon's length where it does not wrap a groove; a wrap only lengthens it)."""
    pose = {spec.bodies[0].name: (np.eye(3), np.zeros(3))}  # body → (R, t): finger-frame point x ↦ R·x + t
    for j, angle in zip(spec.joints, q):
        r_parent, t_parent = pose[j.parent]
        r = _rotation(j.axis, angle)
        p = np.asarray(j.point)
        pose[j.child] = (r_parent @ r, r_parent @ (p - r @ p) + t_parent)
    pts = np.array([pose[b][0] @ np.asarray(x) + pose[b][1] for b, x in spec.sites])
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def rest_length(spec: FingerSpec, tendon: str) -> float:
    """The tendon's length at the straight rest pose [m]: 0 for the fixed tendon, the sites' polyline for the path
    (straight runs tangent to each groove: nothing wraps at rest)."""
    return 0.0 if tendon == GROOVE_TENDON else site_polyline(spec, [0.0] * len(spec.joints))


def full_stroke(spec: FingerSpec, tendon: str | None = None) -> float:
    """The tendon pull [m] that brings every joint to its rotation limit: Σ r_i·rotation_i on the fixed tendon
    (rjcad's model); on the path, its rest length less its polyline at full flexion (at least the true travel:
    a wrap only lengthens the flexed path). The actuator's ``ctrlrange`` is 0 to this."""
    tendon = tendon or spec.pull_on
    if tendon == GROOVE_TENDON:
        return float(sum(j.arm * j.rotation for j in spec.joints))
    return rest_length(spec, tendon) - site_polyline(spec, [j.rotation for j in spec.joints])


def _defaults(root: ET.Element) -> None:
    top = ET.SubElement(ET.SubElement(root, "default"), "default", {"class": CLASS})
    ET.SubElement(top, "mesh", scale="0.001 0.001 0.001")
    joint = ET.SubElement(top, "default", {"class": "joint"})
    ET.SubElement(
        joint, "joint", type="hinge", limited="true", solreflimit=_f(*LIMIT_SOLREF), solimplimit=_f(*LIMIT_SOLIMP)
    )
    visual = ET.SubElement(top, "default", {"class": "visual"})
    ET.SubElement(visual, "geom", type="mesh", contype="0", conaffinity="0", group="2", rgba="0.85 0.85 0.8 1")
    collision = ET.SubElement(top, "default", {"class": "collision"})
    # contype 2 meets conaffinity 1 (the world's default), never another link's (also 1 & 2 = 0)
    ET.SubElement(collision, "geom", contype="2", conaffinity="1", group="3", rgba="0.3 0.5 0.8 0.4")
    route = ET.SubElement(top, "default", {"class": "route"})
    ET.SubElement(route, "site", group="4", size="0.0006", rgba="0.9 0.1 0.1 1")
    ET.SubElement(route, "geom", type="cylinder", contype="0", conaffinity="0", group="4", rgba="0.9 0.6 0.2 0.3")


def _joint_xml(el: ET.Element, spec: FingerSpec, joint: JointSpec, k: int, o: np.ndarray) -> None:
    """Joint k's hinge at body el's origin, and its groove (a wrap cylinder) with the side site the path takes."""
    ET.SubElement(
        el,
        "joint",
        {"class": "joint"},
        name=f"joint{k + 1}",
        pos="0 0 0",
        axis=_f(*joint.axis),
        stiffness=_f(joint.stiffness),
        springref=_f(-joint.preload),
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
        {"class": "route"},
        name=f"groove{k + 1}",
        pos=_sub(centre, o),
        zaxis=_f(*joint.axis),
        size=_f(joint.arm, 2e-3),
    )
    ET.SubElement(el, "site", {"class": "route"}, name=f"groove{k + 1}_side", pos=_sub(side, o), size="0.0003")


def _body_xml(parent: ET.Element, spec: FingerSpec, b: BodySpec, joint: JointSpec | None, k: int) -> ET.Element:
    o = origin(spec, b.name)
    if joint is None:  # the base: mounted above the floor, turned so that gravity points down
        attrs = {"childclass": CLASS, "pos": _f(0.0, 0.0, mount_height(spec)), "quat": _f(*mount_quat(spec.gravity))}
    else:
        attrs = {"pos": _sub(o, origin(spec, joint.parent))}
    el = ET.SubElement(parent, "body", {"name": b.name, **attrs})
    ET.SubElement(el, "inertial", pos=_sub(b.com, o), mass=_f(b.mass), fullinertia=_f(*b.inertia))
    if joint is not None:
        _joint_xml(el, spec, joint, k, o)
    if b.mesh_file is not None:
        assert b.box is not None, f"body {b.name}: a mesh needs its collision box"
        ET.SubElement(el, "geom", {"class": "visual"}, name=f"{b.name}_visual", mesh=b.name, pos=_f(*(-o)))
        centre, half = b.box
        ET.SubElement(
            el,
            "geom",
            {"class": "collision"},
            name=f"{b.name}_collision",
            type="box",
            pos=_sub(centre, o),
            size=_f(*half),
        )
    else:
        assert b.capsule is not None, f"body {b.name}: neither a mesh nor a capsule"
        (p, q, rad) = b.capsule
        fromto, size = _sub(p, o) + " " + _sub(q, o), _f(rad)
        ET.SubElement(
            el, "geom", {"class": "visual"}, name=f"{b.name}_visual", type="capsule", fromto=fromto, size=size
        )
        ET.SubElement(
            el, "geom", {"class": "collision"}, name=f"{b.name}_collision", type="capsule", fromto=fromto, size=size
        )
    for i, (owner, pos) in enumerate(spec.sites):
        if owner == b.name:
            ET.SubElement(el, "site", {"class": "route"}, name=f"t{i}", pos=_sub(pos, o))
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


def _actuator_and_sensors(root: ET.Element, spec: FingerSpec) -> None:
    """``pull``: actuator length −L (gear −1), force KP·ctrl − KP·L_rest − KP·(−L) − KV·(−L̇) = KP·(ctrl − p) − KV·ṗ
    with the pull p = L_rest − L [m]; then the sensors."""
    act = ET.SubElement(root, "actuator")
    ET.SubElement(
        act,
        "general",
        name=ACTUATOR,
        tendon=spec.pull_on,
        gear="-1",
        ctrlrange=_f(0.0, full_stroke(spec)),
        forcerange=_f(0.0, ACTUATOR_MAX_N),
        gaintype="fixed",
        gainprm=_f(ACTUATOR_KP),
        biastype="affine",
        biasprm=_f(-ACTUATOR_KP * rest_length(spec, spec.pull_on), -ACTUATOR_KP, -ACTUATOR_KV),
    )
    sensor = ET.SubElement(root, "sensor")
    for k in range(len(spec.joints)):
        ET.SubElement(sensor, "jointpos", name=f"joint{k + 1}_angle", joint=f"joint{k + 1}")
    ET.SubElement(sensor, "tendonpos", name=f"{spec.pull_on}_length", tendon=spec.pull_on)
    ET.SubElement(sensor, "actuatorfrc", name=f"{ACTUATOR}_tension", actuator=ACTUATOR)


def to_xml(spec: FingerSpec, meshdir: str = "meshes") -> str:
    """The MJCF text of ``spec``; mesh files are named relative to ``meshdir`` (relative to the XML file)."""
    root = ET.Element("mujoco", model=spec.model_name)
    for note in spec.notes:
        root.append(ET.Comment(f" {xml_comment(note)} "))
    ET.SubElement(root, "compiler", angle="radian", meshdir=meshdir, autolimits="true", inertiafromgeom="false")
    g = float(np.linalg.norm(spec.gravity))
    ET.SubElement(root, "option", timestep=_f(TIMESTEP), integrator="implicitfast", gravity=_f(0.0, 0.0, -g))
    _defaults(root)
    meshes = [(b.name, b.mesh_file) for b in spec.bodies if b.mesh_file is not None]
    if meshes:
        asset = ET.SubElement(root, "asset")
        for name, mesh_file in meshes:
            ET.SubElement(asset, "mesh", {"class": CLASS}, name=name, file=mesh_file)
    world = ET.SubElement(root, "worldbody")
    parent = _body_xml(world, spec, spec.bodies[0], None, -1)
    for k, j in enumerate(spec.joints):
        parent = _body_xml(parent, spec, spec.body(j.child), j, k)
    contact = ET.SubElement(root, "contact")
    for j in spec.joints:
        ET.SubElement(contact, "exclude", body1=j.parent, body2=j.child)
    _tendons(root, spec)
    _actuator_and_sensors(root, spec)
    keyframe = ET.SubElement(root, "keyframe")
    ET.SubElement(keyframe, "key", name="home", qpos=_f(*[0.0] * len(spec.joints)), ctrl="0")
    ET.indent(root, "  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def scene_xml(spec: FingerSpec, model_file: str) -> str:
    """scene.xml: includes ``model_file`` and adds a floor (z = 0, under the mounted finger), lights, a sky."""
    h = mount_height(spec)
    root = ET.Element("mujoco", model=f"{spec.model_name} scene")
    root.append(ET.Comment(" the finger (its base mounted above the floor), a floor and lights: open this file "))
    ET.SubElement(root, "include", file=model_file)
    ET.SubElement(root, "statistic", center=_f(0.0, 0.0, 0.6 * h), extent=_f(2.0 * h))
    visual = ET.SubElement(root, "visual")
    ET.SubElement(visual, "headlight", diffuse="0.6 0.6 0.6", ambient="0.3 0.3 0.3", specular="0 0 0")
    ET.SubElement(visual, "global", azimuth="120", elevation="-20")
    asset = ET.SubElement(root, "asset")
    ET.SubElement(
        asset,
        "texture",
        type="skybox",
        builtin="gradient",
        rgb1="0.4 0.6 0.8",
        rgb2="0 0 0",
        width="512",
        height="3072",
    )
    ET.SubElement(
        asset,
        "texture",
        type="2d",
        name="floor",
        builtin="checker",
        mark="edge",
        rgb1="0.25 0.3 0.35",
        rgb2="0.15 0.2 0.25",
        markrgb="0.8 0.8 0.8",
        width="300",
        height="300",
    )
    ET.SubElement(
        asset, "material", name="floor", texture="floor", texuniform="true", texrepeat="8 8", reflectance="0.1"
    )
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", pos=_f(0.0, 0.0, 1.5), dir="0 0 -1", directional="true")
    ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 0.05", material="floor")
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


def xml_comment(text: str) -> str:
    """``text`` fit for an XML comment, which may not hold "--" (strict readers refuse the file): "- -"."""
    while "--" in text:
        text = text.replace("--", "- -")
    return text
