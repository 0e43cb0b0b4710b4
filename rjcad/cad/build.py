"""From parameters to files: build the joint, measure it, and write joint.{stl,3mf,step,glb,png,json}; the same
for the finger.

The joint's solids come from a source with three stages of plain numbers (``rjcad.cad.measure.LocalJoint``,
in this process, or ``rjcad.cad.process.CadProcess``'s, in a forked one): this module itself imports neither
OpenCASCADE (OCP) nor, until it meshes, trimesh."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rjcad.cad import mesh_export as mx
from rjcad.design.params import KEY_ENGAGEMENT, JointParams
from rjcad.io.manifest import JointEntry, Manifest
from rjcad.io.outputs import OutputError, TemporaryWriteError, check_writable
from rjcad.materials import profile_entries
from rjcad.physics.bearing_block import bearing_block
from rjcad.progress import Progress, report

if TYPE_CHECKING:
    import trimesh

    from rjcad.cad.joint import JointSolids
    from rjcad.design.finger_params import FingerParams

#: The folder of a finger's MJCF in its output directory (``rjcad finger --mjcf``)
MJCF_DIR = "mjcf"
#: The joint's body colours (preview and GLB).
JOINT_COLOURS = {"ground": "#9aa5b1", "moving": "#3b82c4"}

GAPS_NOTE = (
    "radial gaps print side by side in XY; axial gaps are Z steps and use "
    "max(clearance, the printer's vertical minimum)"
)


def joint_entry(p: JointParams, parent: str, child: str, axis_point: list[float], axis_dir: list[float]) -> JointEntry:
    """Manifest entry of a joint built from ``p`` (the tendon's moment arm and wrap are measured later)."""
    spring = p.spring.to_dict()
    return JointEntry(
        parent=parent,
        child=child,
        axis_point_mm=axis_point,
        axis_dir=axis_dir,
        joint_stiffness_nmm_per_rad=spring["joint_stiffness_nmm_per_rad"],
        requested_stiffness_nmm_per_rad=p.stiffness,
        spring=spring,
        preload_deg=math.degrees(p.preload),
        rotation_deg=math.degrees(p.rotation),
        link_length_mm=p.link_length,
        z_mid_mm=p.z_mid,
        height_mm=p.height,
        extra={
            "spring_end": end_fitting_entry(p),
            "layout": p.desktop.summary() if p.layout == "desktop" else {"layout": "stacked"},
            "springs": p.springs,
            **({} if p.arms == 1 else {"arms": p.arms}),
            "bearing": bearing_block(p),
        },
    )


def end_fitting_entry(p: JointParams) -> dict:
    """Manifest keys of the springs' outer-end fitting that the builder made for ``p.end_condition``."""
    h_s, c = p.seat_height, p.clearance_mm
    common = {
        "end": p.end_condition,
        "spiral": (
            f"printed winding {'counter-clockwise' if p.layout == 'desktop' else 'clockwise'} outwards "
            "(seen from +Z); preload and flexion unwind it"
        ),
        "seat_height_mm": h_s,
        "push_out_mm": h_s + c,
        "wound_radius_mm": p.wound_radius,
    }
    if p.end_condition == "clamped":
        a = math.degrees(p.socket_tilt)
        return {
            **common,
            **_keys_entry(p),
            "fitting": "key in a socket: a rigid key on the strip's outer end (clockwise of its ray) between "
            "two tines and against a base on the moving link, holding the end's position and angle",
            "key_width_mm": p.key_width,
            "key_root_radius_mm": p.key_root_radius,
            "key_tip_radius_mm": p.key_tip_radius,
            "engagement_mm": KEY_ENGAGEMENT,
            "slot_width_mm": p.key_width + 2 * c,
            "rotational_play_deg": a,
            "tine_tilt_deg": a,
            "bearing": "the spring's moment on the key (about T, one sense over the whole range) turns it "
            f"clockwise in its slot by the play ({a:.1f} deg, about 2c/l): its tip corner bears on the "
            "clockwise tine, its counter-clockwise face on the counter-clockwise tine's inner end; the "
            "tines are tilted by the play, so the bearing key sits at its modelled pose; the end's "
            "small outward force puts its tip on the base",
        }
    return {
        **common,
        "fitting": "closed ring around the post, free to turn",
        "ring_inner_radius_mm": p.post_radius + c,
        "ring_wall_mm": p.hook_wall,
        "pin_offset_mm": p.post_ring_radius - p.spring.centreline_outer_radius,
        "bearing": "the post pulls the ring counter-clockwise; the pin sits pin_offset_mm radially outside the "
        "strip's end, on a rigid stub (the rod model's pin is at the strip's end)",
    }


def _keys_entry(p: JointParams) -> dict:
    """Two arms: each arm's key (its socket's ray and the ray it is printed on, about +Z, and the rod model's
    smallest gap from the other arm to it); one arm: nothing (its manifest is unchanged)."""
    if p.arms == 1:
        return {}
    from rjcad.design.layout_desktop import SOCKET_RAY

    pre = math.degrees(p.preload)
    rays = [math.degrees(SOCKET_RAY) + 180.0 * i for i in range(p.arms)]
    return {
        "keys": [
            {"arm": i + 1, "socket_ray_deg": r % 360.0, "printed_ray_deg": (r + pre) % 360.0}
            for i, r in enumerate(rays)
        ],
        "min_gap_arm_to_other_key_mm": p.key_gap,
    }


def seating_text(p: JointParams) -> str:
    """What the user does after printing, one sentence."""
    if p.layout == "desktop":
        lift = p.seat_height + p.clearance_mm
        which = "the spring's key" if p.arms == 1 else "each of the two keys in turn"
        return (
            f"lift {which} out of the bed plane (into the cup) by {lift:.1f} mm, "
            f"turn it {math.degrees(p.preload):g} deg clockwise (seen from +Z: this unwinds the spiral) and let it "
            "drop between the tines of its socket on the cup"
        )
    what, where = (
        ("key", "between the tines of its socket") if p.end_condition == "clamped" else ("ring", "around its post")
    )
    return (
        f"for each spring, push its {what} out of the spring's plane (away from the joint's middle) by "
        f"{p.seat_height + p.clearance_mm:.1f} mm, turn it {math.degrees(p.preload):g} deg counter-clockwise "
        f"(seen from +Z, the flexion sense: this unwinds the spiral) and let it spring back {where} "
        "on the moving link"
    )


def preview_sections(p: JointParams) -> list[tuple[str, tuple, tuple]]:
    """The joint preview's three sections (title, point, normal), in ``p``'s layout."""
    deg = math.degrees(p.preload)
    if p.layout == "desktop":
        z = p.desktop.seat + 0.5 * (p.spring.width - p.desktop.seat)
        keys = (
            f"key printed {deg:g}° ccw of its socket (at -X)"
            if p.arms == 1
            else f"two arms, each key printed {deg:g}° ccw of its socket (at -X and +X)"
        )
        return [
            (f"z = {z:.2f}: spring on the bed (ccw out), {keys}", (0, 0, z), (0, 0, 1)),
            ("section through the tendon: band, groove, arm, support pin, channels", (0, 0, p.z_mid), (0, 0, 1)),
            ("section y = 0: spring, cup and 50° roof, hub with flare, band and arm", (0, 0, 0), (0, 1, 0)),
        ]
    fitting = ("key", "socket") if p.end_condition == "clamped" else ("ring", "post")
    z = p.spring.width - p.seat_height / 2
    return [
        (
            f"z = {z:.2f}: bottom spring (clockwise out), its {fitting[0]} printed {deg:g}° clockwise of its "
            f"{fitting[1]}",
            (0, 0, z),
            (0, 0, 1),
        ),
        ("section through the eye band: eye, tendon groove, support pin, channels", (0, 0, p.z_mid), (0, 0, 1)),
        ("section y = 0: the stack spring | cheek | eye | cheek | spring", (0, 0, 0), (0, 1, 0)),
    ]


def _mesh_summary(meshes: dict[str, trimesh.Trimesh]) -> dict:
    return {
        "tolerance_mm": mx.MESH_TOLERANCE,
        "angular_tolerance_rad": mx.MESH_ANGULAR_TOLERANCE,
        "triangles": int(sum(len(m.faces) for m in meshes.values())),
    }


@dataclass
class JointBuild:
    """A built joint: its parameters, solids (None when another process built them), meshes, manifest, the
    tendon at rest [mm], its STEP file (``step(name)``, bytes) and timings [s]."""

    params: JointParams
    solids: JointSolids | None
    meshes: dict[str, trimesh.Trimesh]
    manifest: Manifest
    tendon: np.ndarray
    step: Callable[[str], bytes]
    timings: dict[str, float] = field(default_factory=dict)


def build(p: JointParams, source=None, progress: Progress | None = None) -> JointBuild:
    """Build, tessellate and measure the joint; nothing is written. ``source``: the joint a
    ``rjcad.cad.process.CadProcess`` builds (``cad.joint(p)``; default: built in this process). ``progress`` (a
    ``rjcad.progress.Progress``) is told each stage."""
    report(progress, "building the solids")
    if source is None:
        from rjcad.cad.measure import LocalJoint  # OCP

        source = LocalJoint(p)
    shape = source.shape()
    report(progress, "meshing")
    t0 = time.perf_counter()
    meshes = {name: mx.mesh_of(v, f) for name, (v, f) in shape.triangles.items()}
    t1 = time.perf_counter()
    from rjcad.check.mesh_checks import to_manifold

    report(progress, "measuring the gap between the bodies")
    man = [to_manifold(m) for m in meshes.values()]
    gap = float(man[0].min_gap(man[1], 2.0))
    t2 = time.perf_counter()
    report(progress, "measuring the tendon's moment arm and wrap")
    measured = source.measures()
    entry = joint_entry(p, "ground", "moving", shape.axis_point, shape.axis_dir)
    entry.tendon_moment_arm_mm, entry.tendon_wrap_angle_rad = measured.moment_arm, measured.wrap_angle
    extra = {
        "tendon_diameter_mm": p.tendon_diameter,
        "tendon_moment_arm_mm_requested": p.tendon_moment_arm,
        "pin_radius_mm": p.pin_radius,
        "safety_factor": p.safety_factor,
        "end": p.end_condition,
        "gaps_mm": {
            "radial_pin_eye": p.gap_xy,
            "axial_stack": p.gap_z,
            "spring_internal_min": p.gap_internal,
            "extension_stop_in_print": p.clearance_mm,
            "note": GAPS_NOTE,
        },
        "measured_min_gap_mm": gap,
        "spring_strip_volume_mm3": measured.strip_volume,
        "frame": {
            "ground_interface_x_mm": -p.link_length,
            "moving_interface_x_mm": p.link_length,
            "height_mm": p.height,
            "width_mm": p.link_width,
            "z_eye_mm": list(p.z_eye),
            "post_radius_mm": p.post_ring_radius,
            "note": "axis +Z through axis_point_mm; ground link to -X, moving link to +X; "
            "flexion is positive about +Z; bottom on z = 0",
        },
        "mesh": _mesh_summary(meshes),
        "print": {
            "orientation": (
                "as exported: joint axis vertical (Z); the spring, the cup and both link blocks on the bed"
                if p.layout == "desktop"
                else "as exported: joint axis vertical (Z), bottom spring on the bed"
            ),
            "post_print": seating_text(p),
        },
    }
    manifest = Manifest(
        "joint",
        [entry],
        measured.bodies,
        material=p.material_spec.key,
        printer=p.printer_spec.key,
        clearance_mm=p.clearance_mm,
        extra=extra | profile_entries(p.printer_spec, p.material_spec),
    )
    timings = {
        "build_s": shape.timings["build_s"],
        "tessellate_s": shape.timings["triangulate_s"] + t1 - t0,
        "measure_s": measured.timings["arm_wrap_s"] + t2 - t1,
    }
    return JointBuild(p, source.solids, meshes, manifest, shape.tendon, source.step, timings)


def render_files(
    b: JointBuild, name: str = "joint", png: bool = True, progress: Progress | None = None
) -> dict[str, bytes | str]:
    """Every output file's bytes, in memory (so that an error leaves no partial output). The STEP file is
    asked for last: a CAD process writes it while this one writes the meshes."""
    p = b.params
    report(progress, "exporting STL, 3MF and GLB")
    t0 = time.perf_counter()
    files: dict[str, bytes | str] = {
        f"{name}.stl": mx.stl_bytes(list(b.meshes.values())),
        f"{name}.3mf": mx.threemf_bytes(b.meshes, name),
    }
    t1 = time.perf_counter()
    files[f"{name}.glb"] = mx.glb_bytes(b.meshes, JOINT_COLOURS)
    t2 = time.perf_counter()
    if png:
        report(progress, "rendering the preview")
        files[f"{name}.png"] = mx.preview_png(
            b.meshes,
            f"rjcad joint: K = {p.spring.joint_stiffness:.2f} N·mm/rad, {math.degrees(p.rotation):g}° rotation, "
            f"{math.degrees(p.preload):g}° preload, {p.material}; tendon path in red",
            lines=[b.tendon],
            colours=JOINT_COLOURS,
            sections=preview_sections(p),
        )
    t3 = time.perf_counter()
    report(progress, "exporting STEP")
    files[f"{name}.step"] = b.step(name)
    t4 = time.perf_counter()
    b.timings.update({"stl_3mf_s": t1 - t0, "glb_s": t2 - t1, "png_s": t3 - t2, "step_s": t4 - t3})
    files[f"{name}.json"] = json.dumps(b.manifest.to_json(), indent=2) + "\n"
    order = [f"{name}.{ext}" for ext in ("stl", "3mf", "step", "glb", "png", "json")]
    return {k: files[k] for k in order if k in files}


def write_joint(
    p: JointParams, out_dir: str | Path, png: bool = True, cad=None, progress: Progress | None = None
) -> JointBuild:
    """Build the joint and write joint.stl, .3mf, .step, .glb, .png and .json into ``out_dir`` (as one set).
    ``cad``: a ``rjcad.cad.process.CadProcess`` to build the solids in (default: this process); ``progress`` (a
    ``rjcad.progress.Progress``) is told each stage."""
    check_writable(out_dir)
    source = None
    if cad is not None:
        source = cad.joint(p)  # sent now: the CAD process builds as soon as it has imported OCP
        report(progress, "loading the mesh and preview libraries")
        mx.prepare(png)  # meanwhile
        report(progress, "solving the bearing")
        bearing_block(p)  # meanwhile too (kept for the manifest)
    try:
        b = build(p, source, progress)
    except TemporaryWriteError as e:
        raise OutputError(out_dir, str(e)) from e
    write_joint_files(b, out_dir, png=png, progress=progress)
    return b


def write_joint_files(
    b: JointBuild, out_dir: str | Path, png: bool = True, progress: Progress | None = None
) -> list[Path]:
    """Write the built joint ``b`` as joint.stl, .3mf, .step, .glb, .png and .json into ``out_dir`` (as one set;
    without ``png``, a joint.png of an earlier run is removed); returns the files written."""
    try:
        files = render_files(b, "joint", png=png, progress=progress)
    except TemporaryWriteError as e:
        raise OutputError(out_dir, str(e)) from e
    report(progress, "writing the files")
    return mx.write_outputs(out_dir, files, remove=("joint.png",))


# --------------------------------------------------------------------------
# finger
# --------------------------------------------------------------------------


@dataclass
class FingerBuild:
    """A built finger: named solids, meshes, manifest and timings."""

    params: FingerParams
    solids: dict
    meshes: dict[str, trimesh.Trimesh]
    manifest: Manifest
    timings: dict[str, float] = field(default_factory=dict)


def build_finger_model(fp, progress: Progress | None = None) -> FingerBuild:
    """Build, tessellate and measure the finger; nothing is written. ``progress`` (a ``rjcad.progress.Progress``)
    is told each body built and meshed, and each joint measured."""
    report(progress, "loading the CAD kernel")
    from rjcad.cad import export as ex
    from rjcad.cad.finger import build_finger, tendon_path  # OCP
    from rjcad.cad.measure import body_entries
    from rjcad.cad.outline import outline_points

    t0 = time.perf_counter()
    solids = build_finger(fp, progress)
    t1 = time.perf_counter()
    meshes = {}
    for k, (name, s) in enumerate(solids.items()):
        report(progress, f"meshing {name}", k, len(solids))
        meshes[name] = ex.to_mesh(s)
    t2 = time.perf_counter()
    names = fp.body_names
    joints = []
    for i, p in enumerate(fp.joints):
        report(progress, f"measuring joint {i + 1}'s tendon and its link's outline", i, fp.n)
        entry = joint_entry(p, names[i], names[i + 1], [fp.axis_x[i], 0.0, 0.0], [0.0, 0.0, 1.0])
        entry.tendon_moment_arm_mm = ex.measure_moment_arm(
            solids[names[i + 1]], p.z_mid, p.tendon_line_diameter, axis_point=entry.axis_point_mm
        )
        entry.tendon_wrap_angle_rad = ex.measure_wrap_angle(solids[names[i]], p.tendon_diameter / 2)
        child = meshes[names[i + 1]]
        entry.palmar_outline_mm = outline_points(child.vertices, child.faces, fp.axis_x[i])
        joints.append(entry)
    path = np.array(tendon_path(fp))
    p0 = fp.joints[0]
    extra = {
        "template": fp.source,
        "n_joints": fp.n,
        "tendon_diameter_mm": p0.tendon_diameter,
        "safety_factor": p0.safety_factor,
        "end": p0.end_condition,
        "print": {"post_print": seating_text(p0)},
        "base_length_mm": fp.base_length,
        "tendon_length_mm": float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()),
        "tendon_path_mm": path.tolist(),
        "gaps_mm": {"radial_pin_eye": p0.gap_xy, "axial_stack": p0.gap_z, "note": GAPS_NOTE},
        "mesh": _mesh_summary(meshes),
        "frame": "joint 1's axis is +Z through the origin; the finger extends along +X; flexion is positive "
        "about +Z (towards +Y, the tendon side); every body stands on z = 0",
    }
    manifest = Manifest(
        "finger",
        joints,
        body_entries(solids, p0.material_spec.density_g_cm3),
        material=p0.material_spec.key,
        printer=p0.printer_spec.key,
        clearance_mm=p0.clearance_mm,
        base_palmar_outline_mm=outline_points(meshes["base"].vertices, meshes["base"].faces),
        extra=extra | profile_entries(p0.printer_spec, p0.material_spec),
    )
    t3 = time.perf_counter()
    return FingerBuild(
        fp, solids, meshes, manifest, {"build_s": t1 - t0, "tessellate_s": t2 - t1, "measure_s": t3 - t2}
    )


def render_finger_files(
    b: FingerBuild, png: bool = True, mjcf: bool = False, gravity=None, progress: Progress | None = None
) -> dict[str, bytes | str]:
    """finger.stl/.3mf/.step/.glb/.png/.json as bytes; with ``mjcf``, the MJCF folder too (mjcf/finger.xml,
    mjcf/scene.xml, mjcf/meshes/<body>.stl)."""
    from rjcad.cad import export as ex
    from rjcad.cad import mesh_export as mx

    report(progress, "exporting STL, 3MF, STEP and GLB")
    t0 = time.perf_counter()
    files: dict[str, bytes | str] = {
        "finger.stl": mx.stl_bytes(list(b.meshes.values())),
        "finger.3mf": mx.threemf_bytes(b.meshes, "finger"),
        "finger.step": ex.step_bytes(b.solids, "finger"),
        "finger.glb": mx.glb_bytes(b.meshes),
    }
    t1 = time.perf_counter()
    if png:
        report(progress, "rendering the preview")
        fp = b.params
        ks = ", ".join(f"{j.joint_stiffness_nmm_per_rad:.2f}" for j in b.manifest.joints)
        p0 = fp.joints[0]
        files["finger.png"] = mx.preview_png(
            b.meshes,
            f"rjcad finger: {fp.n} joints, K = [{ks}] N·mm/rad, {p0.material}; tendon in red",
            lines=[np.array(b.manifest.extra["tendon_path_mm"])],
            sections=finger_sections(fp),
        )
    t2 = time.perf_counter()
    b.timings.update({"exports_s": t1 - t0, "png_s": t2 - t1})
    files["finger.json"] = json.dumps(b.manifest.to_json(), indent=2) + "\n"
    if mjcf:
        from rjcad.mjcf.export import mjcf_files

        report(progress, "writing the MuJoCo model")
        mj = mjcf_files(b.manifest, b.meshes, "finger.xml", "finger.json", gravity=gravity)
        files.update({f"{MJCF_DIR}/{name}": data for name, data in mj.items()})
    return files


def finger_sections(fp) -> list[tuple[str, tuple, tuple]]:
    """The finger preview's three sections (title, point, normal), in its joints' layout."""
    p0 = fp.joints[0]
    if p0.layout == "desktop":
        z = min(p.spring.width for p in fp.joints) / 2
        return [
            (
                f"section z = {z:.2f}: the springs on the bed, keys printed {math.degrees(p0.preload):g}° ccw "
                "of their sockets",
                (0, 0, z),
                (0, 0, 1),
            ),
            ("section through the tendon plane: bands, arms, tendon path, support pins", (0, 0, p0.z_mid), (0, 0, 1)),
            ("section y = 0: cups, roofs, hubs and arms", (0, 0, 0), (0, 1, 0)),
        ]
    z = p0.spring.width - p0.seat_height / 2
    return [
        (
            f"section z = {z:.2f}: joint 1's bottom spring, its "
            f"{'key and socket' if p0.end_condition == 'clamped' else 'ring and post'}",
            (0, 0, z),
            (0, 0, 1),
        ),
        ("section at joint 1's eye band: eyes, tendon path, support pins", (0, 0, p0.z_mid), (0, 0, 1)),
        ("section y = 0: the joint stacks", (0, 0, 0), (0, 1, 0)),
    ]


def write_finger(
    fp,
    out_dir: str | Path,
    png: bool = True,
    more=None,
    mjcf: bool = False,
    gravity=None,
    progress: Progress | None = None,
) -> FingerBuild:
    """Build the finger and write finger.{stl,3mf,step,glb,png,json} (and with ``mjcf`` the MJCF folder ``mjcf/``)
    into ``out_dir`` (as one set). ``progress`` (a ``rjcad.progress.Progress``) is told each step.

    ``more(build, files)``, if given, returns further files of the set (``rjcad finger --html``: finger.html);
    without it, a finger.html of an earlier run is removed with the set's other stale files."""
    check_writable(out_dir)
    b = build_finger_model(fp, progress)
    write_finger_files(b, out_dir, png=png, more=more, mjcf=mjcf, gravity=gravity, progress=progress)
    return b


def write_finger_files(
    b: FingerBuild,
    out_dir: str | Path,
    png: bool = True,
    more=None,
    mjcf: bool = False,
    gravity=None,
    progress: Progress | None = None,
) -> list[Path]:
    """Write the built finger ``b``'s files into ``out_dir`` (as one set), as ``write_finger`` does; returns the
    files written."""
    try:
        files = render_finger_files(b, png=png, mjcf=mjcf, gravity=gravity, progress=progress)
    except TemporaryWriteError as e:
        raise OutputError(out_dir, str(e)) from e
    if more is not None:
        report(progress, "writing the viewer page")
        files.update(more(b, files))
    report(progress, "writing the files")
    # and the MJCF files an earlier rjcad wrote beside the manifest (mesh_sources would read those STLs first)
    legacy = ("finger.xml", *(f"finger_{body.name}.stl" for body in b.manifest.bodies or []))
    return mx.write_outputs(out_dir, files, remove=("finger.png", "finger.html", f"{MJCF_DIR}/", *legacy))
