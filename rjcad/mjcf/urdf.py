"""The URDF of a built finger or joint: links, revolute joints and meshes in SI units (m, kg, kg·m², rad, N·m).

Read through ``rjcad.mjcf.export.chain_from_manifest`` (the MJCF's reading of a manifest and its body meshes):

* frames: the base link's frame is the manifest's frame; every other link's frame is its parent joint's frame,
  at the joint's axis point, axes parallel to the base's; ``<joint><origin>`` is the axis point's offset from
  the parent link's frame (rpy 0), ``<axis>`` the manifest's unit direction (the same in every frame);
* ``<inertial>``: the manifest's mass; the centre of mass and the inertia tensor about it from the body mesh,
  scaled to that mass (I = ∫ρ(|r|²E − r rᵀ)dV, ρ = m/V), in the link frame;
* ``<visual>``, ``<collision>``: ``meshes/<body>.stl`` (relative to the URDF), in metres in the link frame;
* ``<limit>``: lower 0 (the extension stop), upper the rotation [rad]; effort the spring's torque at full
  flexion K·(θ0 + θr) [N·m] (what the tendon holds there); velocity the spring's release speed
  ω = √(K·((θ0 + θr)² − θ0²)/I) [rad/s] (tendon cut at full flexion, no friction, I the chain beyond the joint
  about its axis at rest); ``<dynamics>``: damping and friction 0 (a manifest holds none);
* what URDF cannot hold (the springs, the tendon and its coupling of the joints) is written as comments.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from rjcad.errors import ParameterError
from rjcad.io.manifest import Manifest
from rjcad.mjcf.spec import BodySpec, JointSpec, xml_comment

if TYPE_CHECKING:
    import trimesh

MESH_DIR = "meshes"
#: A body name that can be a link name and a plain file name: letters, digits, _ . - (no leading dot)
SAFE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,99}")
#: One MuJoCo element (URDF readers skip elements they do not know): MuJoCo's URDF import fuses a link without
#: a joint into the world by default, and the base link's mass would be lost.
MUJOCO_EXTENSION = ("compiler", {"fusestatic": "false"})


def _f(*values: float) -> str:
    """Numbers as XML text: 9 significant digits, no '-0'."""
    return " ".join(f"{(0.0 if abs(v) < 1e-15 else float(v)):.9g}" for v in values)


#: Characters XML 1.0 cannot hold (a manifest's string may have them)
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _comment(parent: ET.Element, text: str) -> None:
    """Append an XML comment of ``text`` (a '--' would end it early: spaced out; characters XML cannot hold: '?')."""
    text = xml_comment(_NOT_XML.sub("?", text))
    parent.append(ET.Comment(f" {text.rstrip('-')} "))


def check_names(man: Manifest, source: str) -> None:
    """Body names that are safe link and file names (``SAFE_NAME``), else one error naming the key."""
    for i, b in enumerate(man.bodies or [], start=1):
        if not SAFE_NAME.fullmatch(b.name):
            raise ParameterError(
                f"{source}: bodies[{i}].name",
                b.name,
                "must be a name of letters, digits, '_', '.' or '-' (not starting with '.') for a URDF link and its "
                "mesh file",
            )


def link_origins(bodies: tuple[BodySpec, ...], joints: tuple[JointSpec, ...]) -> dict[str, np.ndarray]:
    """Each link's frame origin in the base frame [m]: the base's is 0, a child's its joint's axis point."""
    out = {bodies[0].name: np.zeros(3)}
    out.update({j.child: np.asarray(j.point, dtype=float) for j in joints})
    return out


def chain_inertia(bodies: tuple[BodySpec, ...], joints: tuple[JointSpec, ...], k: int) -> float:
    """Inertia [kg·m²] about joint k's axis of the links beyond it at rest: Σ aᵀI_c a + m·|(c − p)⊥a|²."""
    j = joints[k]
    a, p = np.asarray(j.axis), np.asarray(j.point)
    total = 0.0
    for child in [jj.child for jj in joints[k:]]:
        b = next(bb for bb in bodies if bb.name == child)
        ixx, iyy, izz, ixy, ixz, iyz = b.inertia
        tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        r = np.asarray(b.com) - p
        r -= float(np.dot(r, a)) * a
        total += float(a @ tensor @ a) + b.mass * float(np.dot(r, r))
    return total


def effort_velocity(j: JointSpec, inertia: float) -> tuple[float, float]:
    """The ``<limit>``'s effort K·(θ0 + θr) [N·m] and velocity √(K·((θ0 + θr)² − θ0²)/I) [rad/s]."""
    full = j.preload + j.rotation
    energy = j.stiffness * (full**2 - j.preload**2)
    return j.stiffness * full, math.sqrt(max(energy, 0.0) / inertia) if inertia > 0 else 0.0


def _header(man: Manifest, source: str, n: int) -> str:
    what = "a joint" if man.kind == "joint" else f"a finger of {n} joints"
    frame = man.extra.get("frame")
    note = frame.get("note") if isinstance(frame, dict) else frame
    note = note[:300] if isinstance(note, str) else "its frame"
    return (
        f"rjcad: the URDF of {what}, written by rjcad urdf from {Path(source).name}. SI units: m, kg, kg·m², rad, "
        "N·m.\n"
        f"  Frames: the base link's frame is the manifest's ({note}); "
        "every other link's frame is its parent joint's, at the joint's axis point, axes parallel to the base's. "
        "Inertials: the manifest's masses; centres and inertias from the body meshes, about the centre.\n"
        f"  Meshes: {MESH_DIR}/<body>.stl, relative to this file, in metres in the link's frame (no scale).\n"
        "  What URDF cannot hold, lost here (each joint's comment gives its numbers):\n"
        "  - the spiral springs: each joint is free between its limits here; in the finger a spring of stiffness "
        "K holds it on its extension stop (q = 0, the lower limit) with the preload torque K·θ0, and resists "
        "flexion with K·(q + θ0);\n"
        "  - the tendon: its moment arms, its path, and the one tension that couples every joint (the finger "
        "closes when it is pulled; without it nothing drives the joints);\n"
        "  - the friction of the pins and of the tendon in its channel (docs/mujoco.md).\n"
        f"  Where they are: the manifest ({Path(source).name}) holds the springs and the tendon (moment arms, path); "
        "the MJCF of rjcad mjcf has the springs (stiffness, springref), the tendon (spatial and fixed) and the pull "
        "actuator; rjcad simulate finger has the friction.\n"
        "  The <mujoco> element is for MuJoCo's URDF import (other readers skip it): fusestatic false keeps the "
        "base link, and its mass, as a body welded to the world."
    )


def _joint_note(j: JointSpec, effort: float, velocity: float) -> str:
    k, t0, tr = j.stiffness, j.preload, j.rotation
    return (
        f"{j.parent} → {j.child}, flexion q from 0 to θr = {math.degrees(tr):.4g}° ({tr:.6g} rad): spiral spring K = {k * 1e3:.4g} N·mm/rad ({k:.6g} N·m/rad), preload θ0 = "
        f"{math.degrees(t0):.4g}° ({t0:.6g} rad): torque on the joint τ = −K·(q + θ0) = −{k:.6g}·(q + {t0:.6g}) N·m, "
        f"so the spring's rest angle is q = {-t0:.6g} rad and it presses the joint on its extension stop (lower "
        f"limit) with {k * t0:.6g} N·m at q = 0. Tendon: moment arm r = {j.arm * 1e3:.4g} mm: a tension T gives "
        f"+T·{j.arm:.6g} N·m of flexion, and the tendon shortens by {j.arm:.6g} m per rad. effort = K·(θ0 + θr) = "
        f"{effort:.6g} N·m, the spring's torque at full flexion (what the tendon holds there); velocity = "
        f"{velocity:.6g} rad/s, the spring's release speed from full flexion (tendon cut, no friction); dynamics: "
        "damping and friction 0, a manifest holds none (the MJCF's damping K·0.02 s is a stated guess)."
    )


def _link(robot: ET.Element, b: BodySpec, origin: np.ndarray) -> None:
    link = ET.SubElement(robot, "link", name=b.name)
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz=_f(*(np.asarray(b.com) - origin)), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=_f(b.mass))
    ixx, iyy, izz, ixy, ixz, iyz = b.inertia
    ET.SubElement(inertial, "inertia", ixx=_f(ixx), ixy=_f(ixy), ixz=_f(ixz), iyy=_f(iyy), iyz=_f(iyz), izz=_f(izz))
    for kind in ("visual", "collision"):
        el = ET.SubElement(link, kind)
        ET.SubElement(el, "origin", xyz="0 0 0", rpy="0 0 0")
        ET.SubElement(ET.SubElement(el, "geometry"), "mesh", filename=f"{MESH_DIR}/{b.name}.stl")


def to_urdf(name: str, bodies: tuple[BodySpec, ...], joints: tuple[JointSpec, ...], header: str) -> str:
    """The URDF text of a chain of ``bodies`` (base first) joined by ``joints`` (proximal first)."""
    origins = link_origins(bodies, joints)
    robot = ET.Element("robot", name=name)
    _comment(robot, header)
    tag, attrs = MUJOCO_EXTENSION
    ET.SubElement(ET.SubElement(robot, "mujoco"), tag, attrs)
    for b in bodies:
        _link(robot, b, origins[b.name])
    for k, j in enumerate(joints):
        effort, velocity = effort_velocity(j, chain_inertia(bodies, joints, k))
        _comment(robot, f"joint{k + 1}: {_joint_note(j, effort, velocity)}")
        el = ET.SubElement(robot, "joint", name=f"joint{k + 1}", type="revolute")
        ET.SubElement(el, "parent", link=j.parent)
        ET.SubElement(el, "child", link=j.child)
        ET.SubElement(el, "origin", xyz=_f(*(origins[j.child] - origins[j.parent])), rpy="0 0 0")
        ET.SubElement(el, "axis", xyz=_f(*j.axis))
        ET.SubElement(el, "limit", lower="0", upper=_f(j.rotation), effort=_f(effort), velocity=_f(velocity))
        ET.SubElement(el, "dynamics", damping="0", friction="0")
    ET.indent(robot, "  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def robot_name(manifest_path: str | Path, man: Manifest) -> str:
    """The URDF's name: the manifest's stem, cut to a safe name (else the manifest's kind)."""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(manifest_path).stem).lstrip(".")[:100]
    return stem or man.kind


def urdf_files(man: Manifest, meshes: dict[str, trimesh.Trimesh], name: str, source: str) -> dict[str, bytes | str]:
    """``<name>.urdf`` and ``meshes/<body>.stl`` (binary, metres, link frame), in memory."""
    import trimesh

    from rjcad.mjcf.export import chain_from_manifest

    check_names(man, Path(source).name)
    bodies, joints = chain_from_manifest(man, meshes, Path(source).name)
    origins = link_origins(bodies, joints)
    files: dict[str, bytes | str] = {}
    for b in bodies:
        mesh = meshes[b.name]
        moved = trimesh.Trimesh((np.asarray(mesh.vertices) - origins[b.name] * 1e3) * 1e-3, mesh.faces, process=False)
        # trimesh's export is typed for every format (a dict for some); a binary STL is bytes
        files[f"{MESH_DIR}/{b.name}.stl"] = cast(bytes, moved.export(file_type="stl"))
    files[f"{name}.urdf"] = to_urdf(name, bodies, joints, _header(man, source, len(joints)))
    return files
