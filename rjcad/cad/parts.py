"""Parts shared by the joint's layouts: the spring with its end fittings, the clamped end's socket, and tendon
channels to cut."""

from __future__ import annotations

import math

from OCP.TopoDS import TopoDS_Wire

from rjcad.cad import occ
from rjcad.cad.occ import Shape, Vec, Z
from rjcad.cad.spiral import CLOCKWISE, line_box, radial_box, ring, strip_solid
from rjcad.design.params import KEY_ENGAGEMENT, STRIP_OVERLAP, JointParams

#: Slope of a horizontal channel's pointed roof from horizontal [rad] (a teardrop section: no ceiling
#: prints over the channel's air; each layer steps in by less than a road's half-width).
CHANNEL_ROOF = math.radians(50.0)


def _teardrop_wire(c: Vec, side: Vec, radius: float) -> TopoDS_Wire:
    """Teardrop section around ``c`` in the plane of ``side`` and Z: the bore's lower arc between its tangent
    points c + r·(±sin β·side + cos β·Z), and the two roof lines up to the apex c + Z·r/cos β (one face: no
    tangent faces between separate tool solids, which OCC's cut mishandles)."""
    u, v, h = radius * math.sin(CHANNEL_ROOF), radius * math.cos(CHANNEL_ROOF), radius / math.cos(CHANNEL_ROOF)
    left, right, apex = c - side * u + Z * v, c + side * u + Z * v, c + Z * h
    return occ.wire([occ.arc(left, c - Z * radius, right), occ.line(right, apex), occ.line(apex, left)])


def _horizontal(a, b) -> bool:
    return abs(a[2] - b[2]) < 1e-9


#: How far a mitred channel piece reaches past its knee's bisector plane, so that neighbouring pieces overlap
#: instead of touching face to face (coincident faces between tool solids upset OCC's cut) [mm].
MITRE_OVERLAP = 0.01


def _keep_side(solid: Shape, at: Vec, normal: Vec) -> Shape:
    """``solid`` cut by the half-space beyond the vertical plane through ``at`` with horizontal ``normal``
    (the part where (x − at)·normal ≤ 0 stays)."""
    n = normal.unit()
    big = 1000.0
    t = Z.cross(n).unit()
    corner = at - t * (big / 2) - Z * (big / 2)
    square = occ.polygon([corner, corner + t * big, corner + t * big + Z * big, corner + Z * big])
    return occ.cut(solid, occ.prism(occ.planar_face(square), n * big))


def tube_path(points: list[tuple[float, float, float]], radius: float) -> list[Shape]:
    """A channel to cut along a polyline: teardrop prisms along horizontal segments (cylinders along others).
    Two horizontal segments meet in a mitre: each prism runs r·tan(β/2) past the knee (β the bend) and is cut
    on the bisector's vertical plane (+ MITRE_OVERLAP), so that their roofs meet in one ridge with no notch or
    fin; other knees get a ball."""
    pts = [Vec(*p) for p in points]
    n = len(pts)
    horiz = [_horizontal(points[i], points[i + 1]) for i in range(n - 1)]
    solids: list[Shape] = []
    for i in range(n - 1):
        va, vb = pts[i], pts[i + 1]
        d = vb - va
        if not horiz[i]:
            solids.append(occ.cylinder(radius, d.length, va, d.unit()))
            continue
        u = d.unit()
        cuts, start, end = [], va, vb
        for j, sign in ((i - 1, -1), (i + 1, +1)):  # the knee at the start (j = i − 1), at the end (j = i + 1)
            if not 0 <= j < n - 1 or not horiz[j]:
                continue
            knee = va if sign < 0 else vb
            other = (pts[j + 1] - pts[j]).unit()
            bend = math.acos(max(-1.0, min(1.0, u.dot(other))))
            if bend < 1e-6:
                continue
            reach = radius * math.tan(bend / 2) + 0.1
            if sign < 0:
                start = va - u * reach
            else:
                end = vb + u * reach
            bisector = (u + other).unit()  # normal of the mitre plane, along the mean direction
            cuts.append((knee + bisector * (sign * MITRE_OVERLAP), bisector * sign))
        side = Z.cross(u).unit()
        prism = occ.prism(occ.planar_face(_teardrop_wire(start, side, radius)), end - start)
        for at, normal in cuts:
            prism = _keep_side(prism, at, normal)
        solids.append(prism)
    for i in range(1, n - 1):
        if horiz[i - 1] and horiz[i]:
            continue
        a, k, b = pts[i - 1], pts[i], pts[i + 1]
        # a ball, poles along the mean direction so they lie buried in the segments
        # (poles on the channel's surface tessellate into an open seam)
        d = (k - a).unit() + (b - k).unit()
        solids.append(occ.ball(radius, k, d.unit()))
    return solids


def spring_phi0(p: JointParams) -> float:
    """Start angle of the clockwise-outward spiral, so that its outer end lies at −preload [rad]."""
    return -p.preload + 2 * math.pi * p.spring.turns


def spring_solids(p: JointParams, z0: float) -> tuple[Shape, list[Shape]]:
    """The strip alone, and its fused end fittings (inner tab, outer key or stub + ring), for z ∈ [z0, z0+b].

    The strip runs STRIP_OVERLAP mm past both end rays into the fittings, which lie beyond the rays
    (the tab counter-clockwise of the start, the key or stub clockwise of the end): the free strip
    between them is the designed one.
    """
    d = p.spring
    b, t = d.width, d.thickness
    phi0, phi1 = spring_phi0(p), -p.preload
    strip = strip_solid(d, phi0, z0, hand=CLOCKWISE, extend=STRIP_OVERLAP)
    # inner tab: radial, overlapping the pin by 0.4 mm, covering the strip's start
    w_tab = 1.5 * max(t, p.printer_spec.min_wall_mm)
    tab = radial_box(p.pin_radius - 0.4, d.inner_radius + 0.25 * t, w_tab, phi0, z0, b, side=w_tab / 2)
    r0 = p.key_root_radius
    if p.end_condition == "clamped":
        return strip, [tab, radial_box(r0, p.key_tip_radius, p.key_width, phi1, z0, b, side=-p.key_width / 2)]
    # pinned: a radial stub into a closed ring around the post's place
    R_h, r_ring = p.post_ring_radius, p.post_radius + p.clearance_mm
    w_stub = 1.2 * max(t, p.printer_spec.min_wall_mm)
    stub = radial_box(r0, R_h - r_ring - 0.5 * p.hook_wall, w_stub, phi1, z0, b, side=-w_stub / 2)
    return strip, [tab, stub, ring(R_h, phi1, r_ring, r_ring + p.hook_wall, z0, b)]


def socket_solids(p: JointParams, z0: float, height: float, base_end: float | None = None) -> list[Shape]:
    """A clamped spring's socket on the moving link at rest (its key's ray is +X), z ∈ [z0, z0 + height].

    Key seated: u ∈ [key root, R_k], v ∈ [−w_k, 0]. The clockwise tine's face passes through the key's
    tip corner (R_k, −w_k), the counter-clockwise tine's through (R_s0, 0), both tilted by α
    counter-clockwise (``socket_tilt``); the base's face is at u = R_k, and it runs on to u = ``base_end``
    (default: into the moving link's block; the desktop layout ends it in the cup's wall). Loaded, the key
    bears on exactly these three places.
    """
    a, wt, wk = p.socket_tilt, p.tine_width, p.key_width
    R0, Rk, depth = p.socket_inner_radius, p.key_tip_radius, p.socket_base_depth
    end = (Rk + depth / 2 - R0) / math.cos(a)  # the tines end inside the base
    ccw = line_box(R0, 0.0, a, (0.0, end), (0.0, wt), z0, height)
    cw = line_box(Rk, -wk, a, (-KEY_ENGAGEMENT / math.cos(a), depth / 2 / math.cos(a)), (-wt, 0.0), z0, height)
    v_lo, v_hi = p.socket_span
    # the base, bridged out to the link block (so that the block, not only the post, holds it)
    base_end = p.block_start + 0.5 if base_end is None else base_end
    base = occ.box(base_end - Rk, v_hi - v_lo, height, (Rk, v_lo, z0))
    return [ccw, cw, base]
