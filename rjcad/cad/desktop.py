"""Solids of the support-free desktop layout (see :mod:`rjcad.design.layout_desktop` for the design and its numbers).

Ground: the cup (wall and conical roof), the key's socket on the cup's inside, two stop lugs on the roof,
the web to the ground link's block. Moving: the hub (flare under the roof, collar in the bore, band with
the tendon's V-groove), the arm to the moving link's block, and the spring, fused to the hub at its inner
end. The spring is built as the stacked layout's (clockwise outwards, key at −preload, socket at 0), then
mirrored across the XZ plane (counter-clockwise outwards, key at +preload) and turned to the socket's ray.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from rjcad.cad import occ
from rjcad.cad.occ import Shape
from rjcad.cad.parts import socket_solids, spring_solids, tube_path
from rjcad.design.layout_desktop import LUG_WIDTH, ROOF_LAND, SOCKET_RAY, T
from rjcad.design.params import JointParams


def revolved(points: list[tuple[float, float]], angle: float = 360.0, start: float = 0.0) -> Shape:
    """Solid of revolution about +Z of the closed (r, z) polygon ``points``, over ``angle`` degrees from ``start``."""
    face = occ.planar_face(occ.polygon([(r, 0.0, z) for r, z in points]))
    solid = occ.revolution(face, angle)
    return occ.rotated(solid, start) if start else solid


def _turned(shapes: Sequence[Shape]) -> list[Shape]:
    """Mirror across XZ and turn to the socket's ray."""
    return [occ.rotated(occ.mirrored(s, (0.0, 1.0, 0.0)), math.degrees(SOCKET_RAY)) for s in shapes]


def _both_arms(shapes: list[Shape], p: JointParams) -> list[Shape]:
    """``shapes``, and with two arms their copies turned by 180° about the axis (the second arm's)."""
    return shapes if p.arms == 1 else shapes + [occ.rotated(s, 180.0) for s in shapes]


def spring_parts(p: JointParams) -> list[Shape]:
    """The spring on the bed: strip, inner tab (into the hub) and key, counter-clockwise outwards (each arm's)."""
    strip, extras = spring_solids(p, 0.0)
    return _both_arms(_turned([strip, *extras]), p)


def socket_parts(p: JointParams) -> list[Shape]:
    """The key's socket on the cup's inside: the stacked layout's tines and base, from the bed to the seat height,
    the base ending in the cup's wall; mirrored and turned like the spring (each arm's)."""
    L = p.desktop
    return _both_arms(_turned(socket_solids(p, 0.0, L.seat, base_end=L.R_co - 0.3)), p)


def cup_profile(p: JointParams) -> list[tuple[float, float]]:
    """(r, z) of the cup's wall and conical roof; the roof's top ends in a flat land ROOF_LAND wide at the
    bore (a cone meeting the bore would end in a knife edge no road can print)."""
    L = p.desktop
    r_land = L.R_bore + ROOF_LAND
    return [
        (L.R_ci, 0.0),
        (L.R_co, 0.0),
        (L.R_co, L.roof_top(L.R_co)),
        (r_land, L.roof_top(r_land)),
        (L.R_bore, L.roof_top(r_land)),
        (L.R_bore, L.roof_under(L.R_bore)),
        (L.R_ci, L.z_w0),
    ]


def hub_profile(p: JointParams) -> list[tuple[float, float]]:
    """(r, z) of the hub: shaft through the spring, flare under the roof, collar in the bore, band."""
    L = p.desktop
    return [
        (0.0, 0.0),
        (L.r_h, 0.0),
        (L.r_h, L.flare_bottom),
        (L.R_flare, L.flare_top(L.R_flare)),
        (L.R_band, L.flare_top(L.R_band)),
        (L.R_band, L.height),
        (0.0, L.height),
    ]


def lug_parts(p: JointParams) -> list[Shape]:
    """Extension and flexion stop lugs on the roof, beside the arm's faces at the clearance, below the tendon."""
    L = p.desktop
    # plane ends (L.lug_span: the far corner inside the cup's outer radius): no knife edge where a curved end
    # would meet the lug's side
    x0, x1, y0 = L.lug_span
    y1 = y0 + LUG_WIDTH
    r1 = L.R_co - 0.05
    zone = revolved(
        [(x0 - 0.3, L.roof_top(x0) - 0.5), (r1, L.roof_top(r1) - 0.5), (r1, L.lug_top), (x0 - 0.3, L.lug_top)]
    )
    ext = occ.box(x1 - x0, LUG_WIDTH, L.lug_top + 1.0, (x0, -y1, -1.0))
    flex = occ.rotated(occ.box(x1 - x0, LUG_WIDTH, L.lug_top + 1.0, (x0, y0, -1.0)), math.degrees(p.rotation))
    return [occ.common(zone, ext), occ.common(zone, flex)]


def web_part(p: JointParams) -> Shape:
    """Full-height web from the cup's wall to the ground link's block, |y| ≤ w_web. Its end starts in the wall
    (x = −(R_ci + 0.3) at the bed) and leans back at the cone angle above the wall's top, so that it meets
    the roof's top at an open angle (180° − 2 × the cone angle's complement), not a slot."""
    L = p.desktop
    x0, zw = L.R_ci + 0.3, L.roof_top(L.R_ci + 0.3)
    x1 = L.X_g + 1.0
    x_top = x0 + (L.height - zw) / T
    pts = [(-x1, 0.0), (-x0, 0.0), (-x0, zw)]
    pts += [(-x_top, L.height), (-x1, L.height)] if x_top < x1 else [(-x1, zw + (x1 - x0) * T)]
    return _xz_prism(pts, -L.w_web, L.w_web)


def ground_parts(p: JointParams) -> list[Shape]:
    """Ground-side parts around the axis: cup and roof, socket, lugs, web."""
    return [revolved(cup_profile(p)), *socket_parts(p), *lug_parts(p), web_part(p)]


def ground_cuts(p: JointParams) -> list[Shape]:
    """The tendon's way from the ground block's face to the band, through the web and a lug."""
    r, z = p.moment_arm, p.z_mid
    return tube_path([(-p.ground_block_start + 1.0, r, z), (-0.2, r, z)], p.tendon_diameter / 2)


def _xz_prism(points: list[tuple[float, float]], y0: float, y1: float) -> Shape:
    """Prism of the closed (x, z) polygon ``points`` from y0 to y1."""
    area = sum(x0 * z1 - x1 * z0 for (x0, z0), (x1, z1) in zip(points, points[1:] + points[:1]))
    if area > 0:  # counter-clockwise in (x, z): its face's normal is −Y; the extrusion wants +Y
        points = points[::-1]
    face = occ.planar_face(occ.polygon([(x, y0, z) for x, z in points]))
    return occ.prism(face, (0.0, y1 - y0, 0.0))


def arm_part(p: JointParams) -> Shape:
    """The arm from the hub to the moving block, |y| ≤ w_a. Its underside is a plane descending along +X at the
    cone angle, through the roof's top cone + clearance at the band (r ≥ x there, so it stays at least the
    clearance above the roof everywhere); it meets the arm's sides at right angles (no knife edge)."""
    L = p.desktop
    z0, H, x_end = L.z_band[0], L.height, L.X_m + 1.0
    x_top = L.R_band - (H - z0) / T
    x_floor = L.R_band + z0 / T
    pts = [(x_top, H)]
    pts += [(x_floor, 0.0), (x_end, 0.0)] if x_floor < x_end else [(x_end, z0 - (x_end - L.R_band) * T)]
    pts += [(x_end, H)]
    return _xz_prism(pts, -L.w_arm, L.w_arm)


def moving_parts(p: JointParams) -> list[Shape]:
    """Moving-side parts around the axis: hub, arm, spring."""
    return [revolved(hub_profile(p)), arm_part(p), *spring_parts(p)]


def groove_cut(p: JointParams) -> Shape:
    """The tendon's V-groove in the band, over the angles the tendon wraps (clear of the arm)."""
    L = p.desktop
    R_e, gh, zt = p.eye_radius, L.groove_half, L.z_t
    R_out = L.R_band + 0.5
    rise = (R_out - R_e) * T
    start = 60.0
    end = min(90.0 + math.degrees(p.rotation) + 40.0, 300.0)
    return revolved(
        [(R_e, zt - gh), (R_out, zt - gh - rise), (R_out, zt + gh + rise), (R_e, zt + gh)],
        angle=end - start,
        start=start,
    )


def moving_cuts(p: JointParams) -> list[Shape]:
    """The groove and the tendon slot in the moving block, open at the top (its roof would be a cantilever:
    the slot is open towards the joint and at the side); the support pin stands in it as a post."""
    z0 = p.z_eye[0]
    W, R_e, xm = p.link_width, p.eye_radius, p.block_start
    slot = occ.box(p.slot_length, W / 2 - R_e + 1.0, p.height + 1.0 - z0, (xm, R_e, z0))
    return [groove_cut(p), slot]
