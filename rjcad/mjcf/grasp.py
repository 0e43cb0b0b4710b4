"""A finger closing on objects in MuJoCo, read like rjcad's contact solver (a ``Grasp``, engine "mujoco").

The MJCF (``add_grasp``): each link gets, per segment of its outline (a polyline in the link's frame, mm: origin at
its axis, x along the link, y towards the palm), a thin box (``PAD_MM`` thick, ``DEPTH_MM`` deep along the axes)
whose palm-side face lies on the segment; each object is a body of the world at its pose in the base's frame (the
base's frame as the export mounts it): a cylinder is a capsule along the flexion axis (``LENGTH_MM`` long: across
the links' boxes its section is the circle), a box a box. A free object has its mass and three joints in the
plane (slide x, slide y, hinge z); a fixed one none. Only these geoms touch, and only link–object and
object–object (contype/conaffinity ``LINK_BITS`` and ``OBJECT_BITS``; the finger's own collision geoms never
touch an object). Friction: the object's μ on its geoms, 0 on the links'; MuJoCo takes a pair's larger μ and
larger condim (1 where μ = 0, else 3), the shared rule. Contacts: ``SOLREF``/``SOLIMP`` (time constant 2·dt,
critically damped, impedance 0.9999): the penetration is (1 − d)/d·τ²·a with a the acceleration the force would
give the touching bodies alone (about 3e-7 m for 1 N on the default finger, whose links' inertia is the
armature below).

The run (``close_on_mujoco``): the ``pull`` actuator made a pure force on the fixed tendon (−Σ r_i·q_i, rjcad's
constant moment arms; with capstan losses μ_t the arms are r_i·exp(−μ_t·Σ_{k≤i} α_k), the pull direction), its
force T_k = T_max·k/(steps − 1) at reading k, ramped from the last over ``RAMP_STEPS`` time steps, then settled
``SETTLE_STEPS`` at a time until every speed is below ``SPEED_TOL`` (at most ``MAX_SETTLES`` times). Each hinge
gets an armature K·ARMATURE_S² and damping K·SETTLE_S (as ``rjcad.mjcf.simulate``; neither acts at rest); a free
object damping ``OBJECT_TAU_S``·its mass per slide (its radius² times that on its turn). Its pin friction f0 is the
joints' frictionloss; rjcad's load-dependent γ is not in MuJoCo. Travel: Σ r_i·θ_i + T/k_t (k_t finite).

A free object is ejected (as in rjcad's solver) at the first reading where its centre is farther from joint 1 than
the finger's reach (Σ L + the outlines' largest coordinate) and its radius, or at the last reading when it is then
farther than its radius from where it was placed with no link pressing it (pushed and not held).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from typing import Any

import numpy as np

from rjcad.errors import ParameterError
from rjcad.physics.finger_model import FingerModel
from rjcad.physics.grasp import STEPS, check_run, link_outlines
from rjcad.physics.grasp_result import Contact, Grasp, let_go, out_of_reach, reach
from rjcad.physics.objects import Cylinder, Object

#: Link pad boxes: thickness (behind the outline) and depth along the axes [mm]; an object's length [mm]
PAD_MM, DEPTH_MM, LENGTH_MM = 1.0, 10.0, 40.0
#: contype, conaffinity: links touch objects; objects touch links and objects; nothing else touches them
LINK_BITS, OBJECT_BITS = (8, 0), (4, 12)
DT = 5e-4
SOLREF, SOLIMP = (2 * DT, 1.0), (0.9999, 0.9999, 0.001, 0.5, 2.0)
ARMATURE_S, SETTLE_S = 0.01, 0.02  # as rjcad.mjcf.simulate
OBJECT_TAU_S = 0.005  # a free object's damping / mass [s]
RAMP_STEPS, SETTLE_STEPS, MAX_SETTLES = 40, 40, 40
SPEED_TOL = 1e-4  # rad/s, m/s
#: Contacts of one link and one object closer than this are one contact [mm]; weaker ones are dropped [N]
MERGE_MM, FORCE_FLOOR_N = 2.0, 1e-4


def _f(*values: float) -> str:
    return " ".join(f"{(0.0 if abs(v) < 1e-15 else float(v)):.9g}" for v in values)


def _quat_mul(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    )


def _rotate(q: Sequence[float], v: Sequence[float]) -> np.ndarray:
    """Vector v turned by the unit quaternion q (w, x, y, z)."""
    w, *u = q
    _, x, y, z = _quat_mul(_quat_mul(q, (0.0, *v)), (w, -u[0], -u[1], -u[2]))
    return np.array([x, y, z])


def _contact_attrs(mu: float, bits: tuple[int, int]) -> dict[str, str]:
    return {
        "contype": str(bits[0]),
        "conaffinity": str(bits[1]),
        "condim": "1" if mu == 0 else "3",
        "friction": _f(mu, 0.0, 0.0),
        "solref": _f(*SOLREF),
        "solimp": _f(*SOLIMP),
        "margin": "0",
        "group": "1",
    }


def _pad_geoms(body: ET.Element, link: int, outline: np.ndarray) -> None:
    """One thin box per outline segment of ``link``, its palm-side face on the segment (body frame = link frame)."""
    for s, (p, q) in enumerate(itertools.pairwise(outline)):
        d = q - p
        length = float(np.hypot(*d))
        if length < 1e-9:
            continue
        a = math.atan2(d[1], d[0])
        normal = np.array([-d[1], d[0]]) / length  # towards the palm for a segment along +x
        centre = (p + q) / 2 - normal * PAD_MM / 2
        attrs = _contact_attrs(0.0, LINK_BITS) | {
            "name": f"link{link}_pad{s + 1}",
            "type": "box",
            "pos": _f(centre[0] * 1e-3, centre[1] * 1e-3, 0.0),
            "euler": _f(0.0, 0.0, a),
            "size": _f(length / 2e3, PAD_MM / 2e3, DEPTH_MM / 2e3),
            "rgba": "0.2 0.7 0.3 0.6",
        }
        ET.SubElement(body, "geom", attrs)


def _object_inertia(o: Object) -> tuple[float, float, float]:
    """Principal inertia [kg·m²] of a free object about its centre (x, y in the plane, z the axis)."""
    m, ell = o.mass_g * 1e-3, LENGTH_MM * 1e-3
    if isinstance(o, Cylinder):
        r = o.radius * 1e-3
        across = m * (3 * r * r + ell * ell) / 12
        return (across, across, m * r * r / 2)
    w, h = o.w * 1e-3, o.h * 1e-3
    return (m * (h * h + ell * ell) / 12, m * (w * w + ell * ell) / 12, m * (w * w + h * h) / 12)


def _object_body(world: ET.Element, k: int, o: Object, base_pos: np.ndarray, base_quat: Sequence[float]) -> None:
    """Object k (1-based) as a body of the world at its pose in the base's frame; joints in the plane if free."""
    pos = base_pos + _rotate(base_quat, (o.x * 1e-3, o.y * 1e-3, 0.0))
    body = ET.SubElement(world, "body", name=f"object{k}", pos=_f(*pos), quat=_f(*base_quat))
    if o.free:
        ET.SubElement(body, "inertial", pos="0 0 0", mass=_f(o.mass_g * 1e-3), diaginertia=_f(*_object_inertia(o)))
        for name, kind, axis in (("x", "slide", "1 0 0"), ("y", "slide", "0 1 0"), ("turn", "hinge", "0 0 1")):
            ET.SubElement(body, "joint", name=f"object{k}_{name}", type=kind, axis=axis, pos="0 0 0", limited="false")
    attrs = _contact_attrs(o.mu, OBJECT_BITS) | {"name": f"object{k}_geom", "rgba": "0.8 0.4 0.2 0.8"}
    half = LENGTH_MM / 2e3
    if isinstance(o, Cylinder):
        attrs |= {"type": "capsule", "fromto": _f(0, 0, -half, 0, 0, half), "size": _f(o.radius * 1e-3)}
    else:
        attrs |= {"type": "box", "euler": _f(0.0, 0.0, o.angle), "size": _f(o.w / 2e3, o.h / 2e3, half)}
    ET.SubElement(body, "geom", attrs)


def add_grasp(xml: str, objects: Sequence[Object], outlines: Sequence[np.ndarray]) -> str:
    """The MJCF text ``xml`` (an rjcad export: link i the body of hinge ``joint<i>``) with the links' pad geoms
    from ``outlines`` and the ``objects`` (see the module)."""
    root = ET.fromstring(xml)
    world = root.find("worldbody")
    if world is None or world.find("body") is None:
        raise ParameterError("MJCF", "worldbody", "has no mounted base body")
    base = world.find("body")
    assert base is not None
    links = {j.get("name"): b for b in root.iter("body") for j in b.findall("joint")}
    for i, outline in enumerate(outlines, start=1):
        if f"joint{i}" not in links:
            raise ParameterError("MJCF", f"joint{i}", "is not a hinge of the file (one outline per link)")
        _pad_geoms(links[f"joint{i}"], i, outline)
    base_pos = np.array([float(v) for v in base.get("pos", "0 0 0").split()])
    base_quat = [float(v) for v in base.get("quat", "1 0 0 0").split()]
    n = math.sqrt(sum(v * v for v in base_quat))
    for k, o in enumerate(objects, start=1):
        _object_body(world, k, o, base_pos, [v / n for v in base_quat])
    ET.indent(root, "  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _pulled_model(model: FingerModel) -> FingerModel:
    """The model with each moment arm times its capstan factor while pulling (one tension along MuJoCo's tendon)."""
    c = np.exp(-model.mu_t * np.cumsum(model.wrap))
    return dataclasses.replace(model, moment_arm=tuple(float(v) for v in np.asarray(model.moment_arm) * c))


def grasp_files(
    model: FingerModel,
    objects: Sequence[Object],
    outlines: Sequence[np.ndarray] | None = None,
    source: str | None = None,
) -> tuple[str, dict[str, bytes]]:
    """(MJCF text, mesh assets) of the finger with the objects: a manifest ``source`` (.json) exported with its
    meshes, else capsule links from ``model`` (``rjcad.mjcf.model``); gravity as the model's (off without)."""
    from pathlib import Path

    from rjcad.mjcf.model import gravity_vector, spec_from_model
    from rjcad.mjcf.spec import to_xml

    lines = link_outlines(model, outlines)
    grav = gravity_vector(model.gravity) if model.gravity is not None else (0.0, 0.0, 0.0)
    if source is not None and Path(source).suffix.lower() == ".json":
        from rjcad.io.manifest import Manifest
        from rjcad.mjcf.export import check_manifest, mesh_sources, mjcf_files, read_meshes

        man = Manifest.read(source)
        check_manifest(man, Path(source).name)
        files = mjcf_files(man, read_meshes(mesh_sources(source, man)), "finger.xml", source, gravity=grav)
        xml = str(files.pop("finger.xml"))
        assets = {k.split("/")[-1]: v for k, v in files.items() if isinstance(v, bytes)}
    elif source is not None and Path(source).suffix.lower() == ".xml":
        raise ParameterError("source", source, "a grasp in MuJoCo is built from a template or a manifest, not an MJCF")
    else:
        pulled = _pulled_model(model)
        xml, assets = to_xml(spec_from_model(pulled, frictionloss=model.friction, gravity=grav)), {}
    return add_grasp(xml, objects, lines), assets


class _Run:
    """A loaded grasp model made quasi-static (see the module), with the names of what it reads."""

    def __init__(self, model: FingerModel, mj: Any, objects: Sequence[Object]) -> None:
        from rjcad.mjcf.simulate import quiet_mujoco

        mujoco = quiet_mujoco()
        self.mujoco, self.m, self.objects, self.n = mujoco, mj, list(objects), model.n
        mj.opt.timestep = DT
        mj.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        jid = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, f"joint{i + 1}") for i in range(model.n)]
        self.q = np.array([mj.jnt_qposadr[j] for j in jid])
        for j in jid:
            d, k = mj.jnt_dofadr[j], max(float(mj.jnt_stiffness[j]), 1e-6)
            mj.dof_armature[d], mj.dof_damping[d] = k * ARMATURE_S**2, k * SETTLE_S
        self.obj_q: dict[int, int] = {}
        for k, o in enumerate(objects, start=1):
            if o.free:
                j = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, f"object{k}_x")
                self.obj_q[k] = int(mj.jnt_qposadr[j])
                c = o.mass_g * 1e-3 / OBJECT_TAU_S
                dof = int(mj.jnt_dofadr[j])
                mj.dof_damping[dof : dof + 3] = (c, c, c * (o.radius * 1e-3) ** 2)
        self.act = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_ACTUATOR, "pull")
        mj.actuator_gaintype[self.act] = mujoco.mjtGain.mjGAIN_FIXED
        mj.actuator_gainprm[self.act, :3] = (1.0, 0.0, 0.0)
        mj.actuator_biastype[self.act] = mujoco.mjtBias.mjBIAS_NONE
        mj.actuator_biasprm[self.act, :] = 0.0
        mj.actuator_ctrllimited[self.act] = 0
        mj.actuator_forcelimited[self.act] = 0
        mj.actuator_gear[self.act, 0] = -1.0  # force T on the pull −L: flexes
        self.base = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, "base")
        self.owner: dict[int, tuple[str, int]] = {}
        for g in range(mj.ngeom):
            name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            if name.startswith("link") and "_pad" in name:
                self.owner[g] = ("link", int(name[4 : name.index("_")]))
            elif name.startswith("object") and name.endswith("_geom"):
                self.owner[g] = ("object", int(name[6:-5]))
        self.d = mujoco.MjData(mj)
        mujoco.mj_setConst(mj, self.d)  # the constraints' scales from the new armature and damping
        mujoco.mj_resetData(mj, self.d)
        mujoco.mj_forward(mj, self.d)

    def settle(self, tension: float) -> None:
        """Ramp the force to ``tension`` [N] and settle."""
        start = float(self.d.ctrl[self.act])
        chunks = 8
        for s in range(1, chunks + 1):
            self.d.ctrl[self.act] = start + (tension - start) * s / chunks
            self.mujoco.mj_step(self.m, self.d, nstep=RAMP_STEPS // chunks)
        for _ in range(MAX_SETTLES):
            self.mujoco.mj_step(self.m, self.d, nstep=SETTLE_STEPS)
            if float(np.abs(self.d.qvel).max(initial=0.0)) < SPEED_TOL:
                break

    def poses(self) -> list[tuple[float, float, float]]:
        """Each object's (x, y [mm], angle [rad]) in the base's frame."""
        out = []
        for k, o in enumerate(self.objects, start=1):
            if k in self.obj_q:
                a = self.obj_q[k]
                dx, dy, dt = self.d.qpos[a : a + 3]
                out.append((o.x + 1e3 * float(dx), o.y + 1e3 * float(dy), o.angle + float(dt)))
            else:
                out.append((o.x, o.y, o.angle))
        return out

    def contacts(self) -> list[Contact]:
        """MuJoCo's contacts between links and objects and between objects, in the base's frame, merged per body
        and object within MERGE_MM."""
        mujoco, m, d = self.mujoco, self.m, self.d
        rot, p0 = d.xmat[self.base].reshape(3, 3), d.xpos[self.base]
        raw: list[Raw] = []  # body, object, point [mm], force on the object [N], normal into it
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            a, b = self.owner.get(int(c.geom1)), self.owner.get(int(c.geom2))
            if a is None or b is None:
                continue
            mujoco.mj_contactForce(m, d, i, f6)
            frame = c.frame.reshape(3, 3)
            on_b, normal = frame.T @ f6[:3], frame[0].copy()  # the force geom1 applies to geom2 (world), 1 → 2
            if b[0] == "link" or (a[0] == "object" and b[0] == "object" and self.objects[b[1] - 1].free is False):
                a, b, on_b, normal = b, a, -on_b, -normal  # the object pressed second; a free one, not a fixed one
            point = (rot.T @ (c.pos - p0))[:2] * 1e3
            raw.append((f"{a[0]}{a[1]}", b[1], point, (rot.T @ on_b)[:2], (rot.T @ normal)[:2]))
        return _merged(raw)


Raw = tuple[str, int, np.ndarray, np.ndarray, np.ndarray]


def _merged(raw: list[Raw]) -> list[Contact]:
    """Contacts of one body on one object within MERGE_MM as one: forces summed, point and normal weighted by
    force; those pressing less than FORCE_FLOOR_N dropped."""
    groups: list[list[Raw]] = []
    for r in raw:
        for g in groups:
            if g[0][0] == r[0] and g[0][1] == r[1] and np.linalg.norm(g[0][2] - r[2]) < MERGE_MM:
                g.append(r)
                break
        else:
            groups.append([r])
    out = []
    for g in groups:
        force = sum((r[3] for r in g), np.zeros(2))
        w = np.array([max(float(np.linalg.norm(r[3])), 1e-12) for r in g])
        point = (np.array([r[2] for r in g]) * w[:, None]).sum(axis=0) / w.sum()
        normal = (np.array([r[4] for r in g]) * w[:, None]).sum(axis=0)
        normal = normal / max(float(np.linalg.norm(normal)), 1e-12)
        nf = float(force @ normal)
        if nf <= FORCE_FLOOR_N:
            continue
        tangent = np.array([-normal[1], normal[0]])
        out.append(Contact(g[0][0], g[0][1], (float(point[0]), float(point[1])), (float(normal[0]), float(normal[1])),
                           nf, float(force @ tangent)))  # fmt: skip
    return out


def close_on_mujoco(
    model: FingerModel,
    objects: Sequence[Object],
    *,
    max_tension_n: float = 10.0,
    stroke: float | None = None,
    outlines: Sequence[np.ndarray] | None = None,
    steps: int = STEPS,
    source: str | None = None,
) -> Grasp:
    """The finger pulled by its tendon's tension, 0 → ``max_tension_n`` [N] in ``steps`` readings, against
    ``objects``, in MuJoCo (see the module); ``stroke`` [mm] stops it at the first reading whose travel reaches
    it. ``source``: the finger's manifest (.json) for its meshes, else capsule links from ``model``."""
    from rjcad.mjcf.simulate import load, raise_warnings

    check_run(max_tension_n, stroke, steps)
    lines = link_outlines(model, outlines)
    xml, assets = grasp_files(model, objects, lines, source)
    run = _Run(model, load(xml, assets), objects)
    r = np.asarray(model.moment_arm, dtype=float)
    kt = float(model.tendon_stiffness)
    finger_reach = reach(model.link_length, lines)
    out = Grasp(model.n, list(objects), engine="mujoco")
    for k in range(steps):
        tension = max_tension_n * k / (steps - 1)
        run.settle(tension)
        theta = np.array(run.d.qpos[run.q], dtype=float)
        contacts, poses = run.contacts(), run.poses()
        travel = float(r @ theta) + (tension / kt if math.isfinite(kt) else 0.0)
        out.record(travel, tension, theta, contacts, poses)
        if out.ejected_at is None and any(out_of_reach(o, p, finger_reach) for o, p in zip(objects, poses)):
            out.ejected_at = k
        if stroke is not None and travel >= stroke:
            break
    final = zip(objects, out.poses[-1])
    if out.ejected_at is None and any(let_go(o, k, p, out.contacts[-1]) for k, (o, p) in enumerate(final, start=1)):
        out.ejected_at = len(out.tension_n) - 1
    raise_warnings("MuJoCo grasp")
    return out
