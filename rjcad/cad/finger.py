"""A single-tendon finger: N joint modules chained, each link one printed body.

Link i (between joints i and i+1) is the moving side of joint i fused with the
ground side (fork) of joint i+1, placed at x = Σ link lengths. Each body is
fused once from a fixed number of parts, so the build cost grows linearly
with N (never one growing union of the whole finger).

Body names: ``base``, ``link1`` … ``link{N-1}``, ``distal``. Joint i's axis is
+Z through (x_i, 0, 0), x_1 = 0, x_{i+1} = x_i + L_i; L_N runs to the fingertip.
"""

from __future__ import annotations

import math

from rjcad.cad import occ
from rjcad.cad.joint import (
    _fuse,
    _one_solid,
    ground_channel_points,
    ground_side,
    ground_side_cuts,
    link_block,
    moving_channel_start,
    moving_side,
    moving_side_cuts,
    support_pin,
)
from rjcad.cad.occ import Shape
from rjcad.cad.parts import CHANNEL_ROOF, tube_path
from rjcad.design.finger_lengths import CHANNEL_RUNS, channel_shift
from rjcad.design.finger_params import FingerParams
from rjcad.design.params import JointParams
from rjcad.progress import Progress, report

M3_CLEARANCE_DIAMETER = 3.4


def _moved(shapes: list[Shape], dx: float) -> list[Shape]:
    return [occ.translated(s, (dx, 0.0, 0.0)) for s in shapes]


def link_channel_points(p: JointParams, q: JointParams, length: float) -> list[tuple[float, float, float]]:
    """Channel through link i: from joint i's slot to joint i+1's fork face (x = L − X_g of q)."""
    s = moving_channel_start(p)
    e = (length - q.ground_block_start + 0.5, q.moment_arm, q.z_mid)
    if channel_shift(p, q) < 1e-9:
        return [s, e]
    out, into = CHANNEL_RUNS
    return [s, (s[0] + out, s[1], s[2]), (e[0] - into, e[1], e[2]), e]


def m3_hole_heights(p: JointParams) -> tuple[float, float]:
    """Heights of the base's two M3 holes: 4 mm above the bed and 4 mm below the top, the upper one moved
    below the tendon's channel when it would come within a wall of it (the holes cross y = r) [mm]."""
    r_hole, r_t = M3_CLEARANCE_DIAMETER / 2, p.tendon_diameter / 2
    tip, wall = 1.0 / math.cos(CHANNEL_ROOF), p.printer_spec.min_wall_mm + 0.2
    z = p.height - 4.0
    if z - r_hole - wall < p.z_mid + r_t * tip and z + r_hole * tip + wall > p.z_mid - r_t:
        z = p.z_mid - r_t - wall - r_hole * tip
    return 4.0, z


def base_body(fp: FingerParams) -> Shape:
    """Fork of joint 1, the base block with two M3 through holes (along Y) and the entry channel."""
    p = fp.joints[0]
    body = _fuse(
        ground_side(p) + [link_block(-fp.base_length, -p.ground_block_start, p.link_width, p.height)], "base fuse"
    )
    x_h = -fp.base_length + 5.0
    # teardrop holes (a round hole's crown is a flat overhang the length of the hole)
    holes = [
        h
        for z in m3_hole_heights(p)
        for h in tube_path([(x_h, -p.link_width / 2 - 1, z), (x_h, p.link_width / 2 + 1, z)], M3_CLEARANCE_DIAMETER / 2)
    ]
    cuts = tube_path(ground_channel_points(p, fp.base_length), p.tendon_diameter / 2) + holes + ground_side_cuts(p)
    return _one_solid(occ.cut(body, *cuts), "base cuts")


def link_body(p: JointParams, q: JointParams) -> Shape:
    """Moving side of joint p fused with the fork of joint q placed at x = L_p."""
    L = p.link_length
    H = max(p.height, q.height)
    W = max(p.link_width, q.link_width)
    parts = moving_side(p) + [link_block(p.block_start, L - q.ground_block_start, W, H)] + _moved(ground_side(q), L)
    body = _fuse(parts, "link fuse")
    cuts = (
        moving_side_cuts(p, H)
        + tube_path(link_channel_points(p, q, L), p.tendon_diameter / 2)
        + _moved(ground_side_cuts(q), L)
    )
    body = _one_solid(occ.cut(body, *cuts), "link cuts")
    return _fuse([body, support_pin(p)], "link support pin")


def distal_anchor_x(p: JointParams) -> float:
    """x of the tendon's cross-hole anchor in the distal link [mm]."""
    return p.link_length - p.link_width / 2 - 2.0


def distal_body(p: JointParams) -> Shape:
    """Moving side of the last joint, ending in a rounded fingertip, with the tendon's cross-hole anchor.

    The tip is a cylinder of the link's width cut at the block's start: a wide, short link's whole cylinder
    would reach back behind it, into the joint's clearance."""
    L, W, H = p.link_length, p.link_width, p.height
    tip = occ.cylinder(W / 2, H, (L - W / 2, 0.0, 0.0))
    if L - W < p.block_start:
        tip = occ.common(tip, link_block(p.block_start, L, W, H))
    body = _fuse(moving_side(p) + [link_block(p.block_start, L - W / 2, W, H), tip], "distal fuse")
    xa = distal_anchor_x(p)
    anchor = occ.cylinder(max(1.0, p.tendon_diameter), H + 2, (xa, p.moment_arm, -1.0))
    channel = tube_path([moving_channel_start(p), (xa, p.moment_arm, p.z_mid)], p.tendon_diameter / 2)
    body = _one_solid(occ.cut(body, *moving_side_cuts(p, H), *channel, anchor), "distal cuts")
    return _fuse([body, support_pin(p)], "distal support pin")


def tendon_path(fp: FingerParams) -> list[tuple[float, float, float]]:
    """Tendon centreline at rest, base entry to the distal anchor, in finger coordinates [mm]."""
    js = fp.joints
    pts = ground_channel_points(js[0], fp.base_length)[:-1]
    pts = [(pts[0][0] + 0.5, *pts[0][1:])] + pts[1:] + [(-js[0].ground_block_start, js[0].moment_arm, js[0].z_mid)]
    for i, p in enumerate(js):
        x0 = fp.axis_x[i]
        if i + 1 < len(js):
            seg = link_channel_points(p, js[i + 1], p.link_length)
            seg[-1] = (seg[-1][0] - 0.5, *seg[-1][1:])
        else:
            seg = [moving_channel_start(p), (distal_anchor_x(p), p.moment_arm, p.z_mid)]
        pts += [(x + x0, y, z) for x, y, z in seg]
    return pts


def build_finger(fp: FingerParams, progress: Progress | None = None) -> dict[str, Shape]:
    """Every body of the finger, named, in finger coordinates (joint 1's axis at the origin); ``progress`` (a
    ``rjcad.progress.Progress``) is told each body."""
    js = fp.joints
    n = len(js) + 1
    report(progress, "building base", 0, n)
    bodies = {"base": base_body(fp)}
    for i in range(len(js) - 1):
        report(progress, f"building link{i + 1}", i + 1, n)
        bodies[f"link{i + 1}"] = occ.translated(link_body(js[i], js[i + 1]), (fp.axis_x[i], 0.0, 0.0))
    report(progress, "building distal", n - 1, n)
    bodies["distal"] = occ.translated(distal_body(js[-1]), (fp.axis_x[-1], 0.0, 0.0))
    return bodies
