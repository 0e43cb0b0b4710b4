"""The motion check: each joint's subtree swept over its range never meets the other bodies."""

from __future__ import annotations

import math

import manifold3d as m3
import numpy as np
import trimesh

from rjcad.check.copies import APART_MM, DEV_MM, Copies, candidates, min_gap, near, refined, simplified
from rjcad.check.report import BadInput, CheckResult, point, skipped
from rjcad.check.shells import Shell, facing, shells
from rjcad.io.manifest import JointEntry, Manifest, ManifestError
from rjcad.materials import Printer

#: What the motion check reads of each joint.
MOTION_KEYS = ("parent", "child", "axis_point_mm", "axis_dir", "rotation_deg")
#: Farthest a pose proves the next ones free [rad]: the shells' gaps are searched to lever × this.
MAX_REACH_RAD = 0.03


def motion_joints(manifest: Manifest) -> list[JointEntry]:
    """The manifest's joints, each with what the sweep needs (none: a flat joint without ``moving_body``)."""
    joints = manifest.joints
    if not joints or (joints[0].child is None and manifest.read_version == 0 and manifest.kind == "joint"):
        return []
    for i, j in enumerate(joints):
        for key in MOTION_KEYS:
            if getattr(j, key) is None:
                raise ManifestError(manifest.key_path(i, key), None, "is required for the motion check")
    return joints


def subtree(joints: list[JointEntry], k: int) -> set[str | None]:
    """Bodies that move with joint k: its child and everything hanging from it."""
    moving: set[str | None] = {joints[k].child}
    changed = True
    while changed:
        changed = False
        for j in joints:
            if j.parent in moving and j.child not in moving:
                moving.add(j.child)
                changed = True
    return moving


def _rot(point_, direction, angle) -> np.ndarray:
    return trimesh.transformations.rotation_matrix(angle, direction, point_)[:3, :4]


def _union(mans: list[m3.Manifold]) -> m3.Manifold:
    return m3.Manifold.batch_boolean(mans, m3.OpType.Add)


def _poses(j: JointEntry, moving_vertices: np.ndarray, clearance: float, printer: Printer):
    """Axis point, unit direction, lever (farthest moving vertex from the axis) [mm], step and angles [rad]."""
    pt = np.asarray(j.axis_point_mm, dtype=float)
    d = np.asarray(j.axis_dir, dtype=float)
    d = d / np.linalg.norm(d)
    rel = moving_vertices - pt
    lever = float(np.max(np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)))
    assert j.rotation_deg is not None  # motion_joints requires it
    rot = math.radians(float(j.rotation_deg))
    step = 0.5 * min(clearance, printer.min_wall_mm) / lever
    return pt, d, lever, step, np.linspace(0.0, rot, max(1, math.ceil(rot / step)) + 1)


def _groups(k: int, joints, names) -> tuple[list[int], list[int]]:
    """Indices of the bodies that move with joint k, and of the others."""
    moving = subtree(joints, k)
    mi = [i for i, n in enumerate(names) if n in moving]
    si = [i for i, n in enumerate(names) if n not in moving]
    if not mi or not si:
        raise BadInput(f"manifest joint {k + 1} names bodies the mesh lacks: {joints[k].parent}, {joints[k].child}")
    return mi, si


def _screen(shl: list[Shell], free_until: list[float], a: float, transform: np.ndarray) -> bool:
    """Measure at angle ``a`` [rad] each shell whose proven span has ended: shell k, g apart, stays farther than
    APART_MM until a + (g − APART_MM)/lever (``free_until[k]``; searched to MAX_REACH_RAD). True when one is
    within APART_MM: that pose is measured whole, and the shell again at the next pose."""
    near_now = False
    for k, s in enumerate(shl):
        if a < free_until[k]:
            continue
        lever = s.lever + DEV_MM  # the body's points lie within DEV_MM of their copy's
        g = s.still.min_gap(s.turning.transform(transform), lever * MAX_REACH_RAD + APART_MM)
        near_now |= g <= APART_MM
        free_until[k] = a + max(g - APART_MM, 0.0) / lever
    return near_now


def sweep_joint(k: int, joints, bodies, names, mans, clearance: float, printer: Printer, copies: Copies | None = None):
    """Sweep joint k over 0..rotation.

    The poses are screened on the coarse copies (``rjcad.check.copies``) by coaxial shells
    (``rjcad.check.shells``): a shell g apart cannot come near before it turns by g over its lever, so the poses
    before every shell's span ends are proven free (overlap 0) and skipped; at the others, near copies are
    intersected on the bodies, as are the poses not proven free when nothing was simplified. Gaps are sampled
    on the coarse copies and the smallest measured again on the fine copies (within 2·FINE_TOL_MM of the bodies').
    Returns (worst: (overlap volume, angle, posed subtree), first contact angle or None, smallest sampled gap:
    (gap, angle), detail).
    """
    mi, si = _groups(k, joints, names)
    copies = simplified(mans) if copies is None else copies
    mov, sta = _union([mans[i] for i in mi]), _union([mans[i] for i in si])
    mov_c, sta_c = _union([copies.coarse[i] for i in mi]), _union([copies.coarse[i] for i in si])
    pt, d, lever, step, angles = _poses(joints[k], np.vstack([bodies[i].vertices for i in mi]), clearance, printer)
    shl = shells(mov_c, sta_c, pt, d, APART_MM, MAX_REACH_RAD)
    exact = copies.exact(mi + si)  # nothing simplified: every pose not proven free is intersected on the bodies
    worst: tuple[float, float | None, m3.Manifold | None] = (0.0, None, None)  # (overlap volume, angle, posed)
    first: float | None = None
    overlaps: dict[int, float] = {}  # pose index → overlap volume, where measured
    free_until = [0.0] * len(shl)
    i = 0
    while i < len(angles):
        a = float(angles[i])
        transform = _rot(pt, d, a)
        if _screen(shl, free_until, a, transform) and (exact or near(sta_c, mov_c.transform(transform))):
            posed = mov.transform(transform)
            overlaps[i] = vol = (sta ^ posed).volume()
            if vol > worst[0]:
                worst = (vol, a, posed)
            if vol > 0 and first is None:
                first = a
        i += 1
        while i < len(angles) and angles[i] < min(free_until, default=math.inf):
            i += 1
    every = max(1, len(angles) // 24)
    mov_s, sta_s = facing(mov_c, sta_c, pt, d, clearance + 1.0)  # what the gaps' search can reach
    sampled = [
        (
            0.0
            if overlaps.get(i, 0.0) > 0
            else min_gap(sta_s, mov_s.transform(_rot(pt, d, float(a))), clearance + 1.0),
            float(a),
        )
        for i, a in enumerate(angles)
        if i % every == 0 or i == len(angles) - 1
    ]
    gap = _smallest_gap(
        sampled,
        [copies.fine[i] for i in mi],
        [copies.fine[i] for i in si],
        pt,
        d,
        clearance + 1.0,
        copies.same(mi + si),
    )
    detail = f"joint {k + 1}: {len(angles)} poses, step {math.degrees(step):.3f}° (lever {lever:.1f} mm)"
    return worst, first, gap, detail


def _smallest_gap(sampled, mov_f, sta_f, pt, d, search: float, same: bool) -> tuple[float, float | None]:
    """(gap, angle) of the smallest sampled gap on the fine copies, from the coarse copies' (gap, angle) samples."""
    mov_u, sta_u = _union(mov_f), _union(sta_f)
    best: tuple[float, float | None] = (math.inf, None)
    for k in candidates([g for g, _ in sampled]):
        g_c, a = sampled[k]
        g = refined(g_c, sta_u, mov_u.transform(_rot(pt, d, a)), search, same)
        if g < best[0]:
            best = (g, a)
    return best


def check_motion(
    bodies,
    names,
    mans,
    manifest: Manifest | dict | None,
    clearance: float,
    printer: Printer,
    copies: Copies | None = None,
) -> CheckResult:
    """Each joint's subtree swept over 0..rotation about its axis never intersects the other bodies.

    Step Δθ = 0.5·min(clearance, min wall)/lever, the lever being the farthest moving vertex from the
    axis: no point moves more than half the clearance (or half the thinnest wall) between two poses,
    so a collision cannot hide between them. ``copies``: the bodies' simplified copies (see sweep_joint).
    """
    if manifest is None:
        return skipped("motion", "skipped: no manifest")
    joints = motion_joints(Manifest.coerce(manifest))
    if not joints:
        return skipped("motion", "skipped: the manifest has no joints")
    worst: tuple[float, int | None, float | None, m3.Manifold | None] = (0.0, None, None, None)
    # (overlap volume, joint, angle, posed subtree)
    smallest: tuple[float, int | None, float | None] = (math.inf, None, None)  # (gap, joint, angle)
    first: tuple[int, float] | None = None  # (joint, angle) of the first pose that intersects
    details = []
    copies = simplified(mans) if copies is None else copies
    for k in range(len(joints)):
        (vol, a, posed), first_a, (g, g_a), detail = sweep_joint(
            k, joints, bodies, names, mans, clearance, printer, copies
        )
        if vol > worst[0]:
            worst = (vol, k, a, posed)
        if first is None and first_a is not None:
            first = (k, first_a)
        if g < smallest[0]:
            smallest = (g, k, g_a)
        details.append(detail)
    vol, worst_k, worst_a, posed = worst
    if worst_k is not None:
        # a collision: the worst pose's angle and subtree were set with its joint, and its joint's sweep met the
        # first contact
        assert worst_a is not None and posed is not None and first is not None
        k, a = worst_k, worst_a
        inter = _union([mans[i] for i, nm in enumerate(names) if nm not in subtree(joints, k)]) ^ posed
        where = np.asarray(inter.to_mesh().vert_properties)[:, :3].mean(axis=0)
        return CheckResult(
            "motion",
            False,
            round(math.degrees(a), 2),
            0.0,
            point(where),
            f"joint {k + 1} collides, worst at {math.degrees(a):.1f}° ({vol:.3f} mm³ overlap), "
            f"first contact at joint {first[0] + 1}, {math.degrees(first[1]):.1f}°; " + "; ".join(details),
        )
    g, smallest_k, smallest_a = smallest
    assert smallest_k is not None and smallest_a is not None  # every sweep samples a finite gap (≤ the search length)
    k, a = smallest_k, smallest_a
    return CheckResult(
        "motion",
        True,
        round(float(g), 4),
        0.0,
        None,
        f"free over the whole range; smallest sampled gap {g:.3f} mm at joint {k + 1}, "
        f"{math.degrees(a):.1f}°; " + "; ".join(details),
    )
