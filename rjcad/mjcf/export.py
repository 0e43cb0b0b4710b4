"""The MJCF of a built finger: from its manifest (joints, masses, tendon path) and its body meshes.

Meshes read: ``<stem>_<body>.stl`` beside the manifest (what an earlier ``rjcad finger --mjcf`` wrote), else the
body's named part in ``<stem>.3mf``. Mass from the manifest (else mesh volume × the material's density); centre of
mass and inertia from the mesh, scaled to that mass; the collision box: the mesh's bounding box (the body frame's
axes are the finger frame's). Sites: the manifest's ``tendon_path_mm``, each point in the body whose span of x
(between its joint's axis and the next) holds it. Joint friction, damping and armature: an ``rjcad identify``
result when given (its pin friction per joint, and its stiffness and preload if fitted), else the stated defaults
below. Written: ``<stem>.xml``, ``scene.xml`` and ``meshes/<body>.stl`` (binary STL, mm, in the finger frame: the
visual geom's ``pos`` puts each in its body's frame).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar, cast

import numpy as np

from rjcad import DEG
from rjcad.errors import ParameterError, RjcadError, quote
from rjcad.io.manifest import Manifest
from rjcad.mjcf.spec import (
    ACTUATOR,
    GROOVE_TENDON,
    PATH_TENDON,
    BodySpec,
    FingerSpec,
    JointSpec,
    scene_xml,
    to_xml,
    unit,
)

if TYPE_CHECKING:
    import trimesh
    from trimesh.parent import Geometry

#: Stated defaults where nothing is known: damping = K·DAMPING_S [N·m·s/rad] (a 20 ms spring–damper time
#: constant, a guess), no armature (no rotor), no friction loss (the design model is frictionless).
DAMPING_S, ARMATURE, FRICTIONLOSS = 0.02, 0.0, 0.0

#: --gravity: rjcad's finger orientations, as gravity's direction in the finger frame (x along the straight finger,
#: y towards the palm, z along the axes); the MJCF turns the base so that it points down
GRAVITY = {
    "horizontal-palm-down": (0.0, 1.0, 0.0),  # gravity helps flexion
    "horizontal-palm-up": (0.0, -1.0, 0.0),  # gravity opposes flexion
    "vertical-tip-down": (1.0, 0.0, 0.0),
    "vertical-tip-up": (-1.0, 0.0, 0.0),
    "lying-as-printed": (0.0, 0.0, -1.0),  # on the bed, axes vertical: no torque on the joints
    "off": (0.0, 0.0, 0.0),
}
DEFAULT_GRAVITY = "horizontal-palm-down"
G = 9.81

_T = TypeVar("_T")


def gravity_of(value: str | float) -> tuple[float, float, float]:
    """Gravity [m/s²] in the finger frame for a --gravity value: a name, or the angle from x towards y [deg]."""
    if isinstance(value, str) and value in GRAVITY:
        gx, gy, gz = GRAVITY[value]
        return (G * gx, G * gy, G * gz)
    try:
        a = float(value) * DEG
    except (TypeError, ValueError):
        raise ParameterError(
            "--gravity",
            value,
            f"must be one of {', '.join(GRAVITY)}, or the angle of gravity "
            "from the finger's axis towards the palm [deg]",
        ) from None
    if not math.isfinite(a):
        raise ParameterError("--gravity", value, "must be finite")
    return (G * math.cos(a), G * math.sin(a), 0.0)


def _path_points(man: Manifest, source: str) -> np.ndarray:
    pts = man.extra.get("tendon_path_mm")
    ok = (
        isinstance(pts, list)
        and len(pts) >= 2
        and all(
            isinstance(p, list)
            and len(p) == 3
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in p)
            for p in pts
        )
    )
    if not ok:
        raise ParameterError(
            f"{source}: tendon_path_mm",
            pts,
            "must be a list of at least 2 [x, y, z] points (a finger manifest written by rjcad finger)",
        )
    return np.asarray(pts, dtype=float)


def _checked(value: _T | None) -> _T:
    """A manifest field that ``check_manifest`` has found present."""
    assert value is not None, "check_manifest first"
    return value


def _point_m(point_mm: Sequence[float]) -> tuple[float, float, float]:
    """A point [mm] in metres."""
    x, y, z = point_mm
    return (x * 1e-3, y * 1e-3, z * 1e-3)


def check_manifest(man: Manifest, source: str) -> None:
    """A finger manifest the MJCF can be made of: joints with axes, stiffness, preload, rotation, arm; bodies."""
    if not man.joints:
        raise ParameterError(f"{source}: joints", [], "must hold at least one joint (a finger manifest)")
    if not man.bodies:
        raise ParameterError(f"{source}: bodies", None, "must list the finger's bodies")
    names = {b.name for b in man.bodies}
    for i, j in enumerate(man.joints):
        for key in (
            "parent",
            "child",
            "axis_point_mm",
            "axis_dir",
            "joint_stiffness_nmm_per_rad",
            "preload_deg",
            "rotation_deg",
            "tendon_moment_arm_mm",
        ):
            if getattr(j, key) is None:
                raise ParameterError(f"{source}: {man.key_path(i, key)}", None, "is required for the MJCF")
        for key in ("parent", "child"):
            if getattr(j, key) not in names:
                raise ParameterError(f"{source}: {man.key_path(i, key)}", getattr(j, key), "names no body in bodies")


#: Where the meshes go, relative to the model (the compiler's ``meshdir``)
MESHDIR = "meshes"


def mesh_sources(manifest_path: str | Path, man: Manifest, allow_outside: bool = False) -> dict[str, Path]:
    """Where each body's mesh is: ``<stem>_<body>.stl`` beside the manifest, else ``<stem>.3mf``; each must resolve
    (symlinks followed) inside the manifest's folder unless ``allow_outside``."""
    from rjcad.io.untrusted import confined, regular_or_absent

    p = Path(manifest_path)
    out = {}
    threemf = p.with_suffix(".3mf")
    for k, b in enumerate(_checked(man.bodies), 1):
        if not b.name or "/" in b.name or "\\" in b.name or b.name.startswith(".") or "\0" in b.name:
            raise ParameterError(
                f"{p}: bodies[{k}].name", b.name, "must be a plain name (no '/', '\\' or leading '.'): it names a file"
            )
        stl = confined(p.parent, f"{p.stem}_{b.name}.stl", str(p), allow_outside)
        if regular_or_absent(stl):
            out[b.name] = stl
        elif regular_or_absent(confined(p.parent, threemf.name, str(p), allow_outside)):
            out[b.name] = threemf
        else:
            raise RjcadError(
                f"{stl}: mesh file not found (nor {threemf.name}): each body's mesh is read beside the manifest "
                "(rjcad joint and rjcad finger write the 3MF; rjcad finger --mjcf one STL per body)"
            )
    return out


def read_meshes(sources: dict[str, Path]) -> dict[str, trimesh.Trimesh]:
    """Each body's trimesh from its source (a per-body STL, or the named part of a 3MF)."""
    import io

    import trimesh

    from rjcad.check.load import load_bodies
    from rjcad.io.untrusted import read_bytes

    out: dict[str, trimesh.Trimesh] = {}
    parts: dict[Path, dict[str, trimesh.Trimesh]] = {}
    for name, path in sources.items():
        mesh: Geometry | None
        if path.suffix.lower() == ".stl":
            raw = read_bytes(path, "mesh")
            try:
                mesh = trimesh.load(io.BytesIO(raw), file_type="stl", force="mesh")
            except Exception as e:  # trimesh raises many kinds on garbage
                raise RjcadError(f"{path}: not a readable STL ({type(e).__name__})") from None
        else:
            if path not in parts:
                bodies, names = load_bodies(path)
                parts[path] = dict(zip(names or [], bodies))
            mesh = parts[path].get(name)
            if mesh is None:
                raise RjcadError(f"{path}: no part named {quote(name)} (the manifest's body)")
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise RjcadError(f"{path}: holds no triangles for body {quote(name)}")
        out[name] = mesh
    return out


def _mass_properties(mesh, mass_kg: float) -> tuple[tuple, tuple]:
    """Centre of mass [m] and inertia about it (ixx iyy izz ixy ixz iyz) [kg·m²] of a mesh in mm, of mass m."""
    vol = abs(float(mesh.volume))
    com = np.asarray(mesh.center_mass, dtype=float)
    inertia = np.asarray(mesh.moment_inertia, dtype=float) * np.sign(mesh.volume) * (mass_kg / vol) * 1e-6
    return tuple(com * 1e-3), (inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2])


def _site_owner(man: Manifest, point: np.ndarray) -> str:
    """The body holding a path point: the child of the last joint whose axis lies before it along the finger."""
    owner = _checked(man.joints[0].parent)
    for j in man.joints:
        a, d = np.asarray(j.axis_point_mm), np.asarray(unit(_checked(j.axis_dir)))
        w = point - a
        w -= np.dot(w, d) * d
        if w[0] > 0:  # along the finger (+x, the frame of rjcad's fingers)
            owner = _checked(j.child)
    return owner


def chain_from_manifest(
    man: Manifest,
    meshes: dict[str, trimesh.Trimesh],
    source: str = "manifest",
    identified: dict[str, Any] | None = None,
) -> tuple[tuple[BodySpec, ...], tuple[JointSpec, ...]]:
    """The bodies (base first) and hinges (proximal first) of a finger or joint manifest and its body meshes
    (trimesh, mm), in SI units and the finger frame; mesh files ``<body>.stl``. No tendon path needed."""
    from rjcad.materials import Material, from_manifest

    check_manifest(man, source)
    try:
        mat = from_manifest("materials", man.material, man.extra)
    except ParameterError:  # a material this rjcad does not know: the bodies' masses must say
        mat = None
    dens = mat.density_g_cm3 if isinstance(mat, Material) else None
    man_bodies = _checked(man.bodies)
    bodies = []
    for b in man_bodies:
        mesh = meshes[b.name]
        mass_g = b.mass_g if b.mass_g is not None else (abs(float(mesh.volume)) * dens / 1000.0 if dens else None)
        if mass_g is None or mass_g <= 0:
            raise ParameterError(f"{source}: bodies.{b.name}.mass_g", b.mass_g, "is required (or a known material)")
        com, inertia = _mass_properties(mesh, mass_g * 1e-3)
        lo, hi = np.asarray(mesh.bounds, dtype=float) * 1e-3
        box = (tuple((lo + hi) / 2), tuple((hi - lo) / 2))
        bodies.append(BodySpec(b.name, mass_g * 1e-3, com, inertia, mesh_file=f"{b.name}.stl", box=box))
    order = [b.name for b in man_bodies]
    bodies.sort(
        key=lambda b: ([j.child for j in man.joints].index(b.name) + 1) if b.name != man.joints[0].parent else 0
    )
    if [b.name for b in bodies] != [man.joints[0].parent] + [j.child for j in man.joints] or len(order) != len(bodies):
        raise ParameterError(
            f"{source}: joints",
            [j.child for j in man.joints],
            "must chain the bodies base → distal, each joint's parent the previous child",
        )
    params = joint_parameters(man, identified)
    joints = tuple(
        JointSpec(
            _checked(j.parent),
            _checked(j.child),
            _point_m(_checked(j.axis_point_mm)),
            unit(_checked(j.axis_dir)),
            p["stiffness"] * 1e-3,
            p["preload"],
            _checked(j.rotation_deg) * DEG,
            _checked(j.tendon_moment_arm_mm) * 1e-3,
            p["stiffness"] * 1e-3 * DAMPING_S,
            p["friction"] * 1e-3,
            ARMATURE,
        )
        for j, p in zip(man.joints, params)
    )
    return tuple(bodies), joints


def spec_from_manifest(
    man: Manifest,
    meshes: dict[str, trimesh.Trimesh],
    source: str = "manifest",
    gravity: tuple[float, float, float] | None = None,
    identified: dict[str, Any] | None = None,
    pull: str = GROOVE_TENDON,
) -> FingerSpec:
    """The ``FingerSpec`` of a finger manifest and its body meshes (trimesh, mm; mesh files ``<body>.stl``), its
    actuator on the tendon ``pull``."""
    bodies, joints = chain_from_manifest(man, meshes, source, identified)
    pts = _path_points(man, source)
    sites = tuple((_site_owner(man, pt), tuple(pt * 1e-3)) for pt in pts)
    grav = gravity if gravity is not None else gravity_of(DEFAULT_GRAVITY)
    notes = _notes(man, source, identified, grav, pull)
    return FingerSpec(
        bodies,
        joints,
        sites,
        gravity=grav,
        pull_on=pull,
        notes=notes,
        model_name=f"rjcad finger ({len(joints)} joints)",
    )


def joint_parameters(man: Manifest, identified: dict[str, Any] | None) -> list[dict[str, float]]:
    """Per joint: stiffness [N·mm/rad], preload [rad], pin friction [N·mm]: the manifest's, or identified."""
    out = []
    params = (identified or {}).get("params", {})
    for k, j in enumerate(man.joints, start=1):
        out.append(
            {
                "stiffness": float(params.get(f"stiffness_nmm_per_rad_j{k}", j.joint_stiffness_nmm_per_rad)),
                "preload": float(params.get(f"preload_deg_j{k}", j.preload_deg)) * DEG,
                "friction": float(params.get(f"friction_nmm_j{k}", FRICTIONLOSS * 1e3)),
            }
        )
    return out


def _notes(
    man: Manifest, source: str, identified: dict[str, Any] | None, grav: tuple[float, float, float], pull: str
) -> tuple[str, ...]:
    fitted = sorted((identified or {}).get("params", {}))
    lost = [k for k in fitted if k.startswith(("gamma", "beta", "mu_alpha"))]
    g = math.sqrt(sum(x * x for x in grav))
    return (
        f"written by rjcad mjcf from {Path(source).name}: SI units (m, kg, N·m, rad); each body's frame at its "
        "joint's axis, axes as the finger frame's: x along the straight finger, y towards the palm (flexion), z "
        "along the joint axes; open scene.xml (this model over a floor)",
        f"the base is turned so that gravity (finger frame: {', '.join(f'{x / g:.3f}' for x in grav)}) points down"
        if g > 0
        else "no gravity (gravity off)",
        f"tendon '{PATH_TENDON}': the built tendon path (sites), wrapping each eye's groove; tendon "
        f"'{GROOVE_TENDON}': rjcad's model, length -sum(r_i q_i) (constant moment arms); actuator '{ACTUATOR}' on "
        f"'{pull}': ctrl = the tendon pull [m] (rest length - length), 0 to full flexion, force = tension [N]",
        "joints: springref = -preload (the spring presses each joint on its extension stop at q = 0); stiff limits "
        "(solreflimit at 2 time steps); "
        + (
            f"stiffness, preload and pin friction (frictionloss) from the identify result: {', '.join(fitted)}"
            if identified
            else f"frictionloss {FRICTIONLOSS} (design model), damping K*{DAMPING_S} s and "
            f"armature {ARMATURE}: stated defaults, not measured"
        ),
        "collision: a box around each body's mesh (group 3), touching the world, not the other links; visual: the "
        "meshes (group 2)",
        "MuJoCo cannot represent: a tension that changes along the tendon (capstan), nor pin friction that grows "
        "with the tendon load"
        + (f" (identified, left out: {', '.join(lost)})" if lost else "")
        + "; see docs/mujoco.md",
    )


def check_identified(data: Any, man: Manifest, source: str) -> dict[str, Any]:
    """An ``rjcad identify`` finger result for this design (same joints and stiffness within 2 %), else one error."""
    if not isinstance(data, dict) or data.get("kind") != "finger" or not isinstance(data.get("design"), dict):
        raise RjcadError(f"{source}: not an rjcad identify result of a finger (kind 'finger' with a design)")
    design = data["design"]
    ks = design.get("stiffness_nmm_per_rad")
    mine = [_checked(j.joint_stiffness_nmm_per_rad) for j in man.joints]
    if (
        design.get("joints") != len(man.joints)
        or not isinstance(ks, list)
        or len(ks) != len(mine)
        or any(not isinstance(a, (int, float)) or abs(a - b) > 0.02 * b for a, b in zip(ks, mine))
    ):
        raise RjcadError(
            f"{source}: identify result for another design: its finger has "
            f"{quote(design.get('joints'))} joints, K = {quote(ks)} N·mm/rad; the manifest's has "
            f"{len(mine)}, K = {[round(k, 2) for k in mine]}"
        )
    params = data.get("params", {})
    if not isinstance(params, dict) or not all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in params.values()
    ):
        raise RjcadError(f"{source}: params must be an object of finite numbers")
    for k, v in params.items():
        if k.startswith("friction_nmm_j") and v < 0:
            raise RjcadError(f"{source}: params.{k} = {quote(v)} must be >= 0")
    return data


def mjcf_files(
    man: Manifest,
    meshes: dict[str, trimesh.Trimesh],
    xml_name: str,
    source: str,
    gravity: tuple[float, float, float] | None = None,
    identified: dict[str, Any] | None = None,
    pull: str = GROOVE_TENDON,
) -> dict[str, bytes | str]:
    """The MJCF folder in memory (relative path → content): the model ``xml_name``, ``scene.xml`` (which includes
    it) and ``meshes/<body>.stl`` (binary STL)."""
    spec = spec_from_manifest(man, meshes, source, gravity, identified, pull)
    files: dict[str, bytes | str] = {xml_name: to_xml(spec, MESHDIR), "scene.xml": scene_xml(spec, xml_name)}
    for b in spec.bodies:  # trimesh's export is typed for every format (a dict for some); a binary STL is bytes
        files[f"{MESHDIR}/{b.mesh_file}"] = cast(bytes, meshes[b.name].export(file_type="stl"))
    return files
