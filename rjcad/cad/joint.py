"""The one-piece joint module: ground (fork, pin, springs) and moving (eye, posts, tendon support).

Frame: joint axis +Z through the origin; ground link towards −X, moving link
towards +X; flexion is positive about +Z. Everything sits on z ≥ 0 (the bed).

Ground body: the knuckle pin (z = 0..H) fused with two cheeks, the fork's
full-height block at x ≤ −X_b, the two stop lugs on each cheek, and the two
springs, whose inner ends are fused to the pin through radial tabs.
Moving body: the eye around the pin (bore = pin + clearance) with the tendon
groove, a beam in the eye band, the full-height block at x ≥ X_b with the
tendon slot and support pin, and the post at radius R_h on the +X ray, which
reaches ``seat_height`` into each spring's layer; a clamped spring's socket
(two tines and a base) hangs from it there.

The springs wind clockwise outwards. In print each spring's outer end (a key,
or a ring when pinned) sits ``preload`` clockwise of its socket (or post); the
user pushes it out of the spring's plane (away from the joint's middle) by
seat_height + clearance, turns it counter-clockwise by the preload, which
unwinds the spiral, and lets it spring back into the socket. The post then
rests on the extension-stop lugs at θ = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

from rjcad.cad import desktop, occ
from rjcad.cad.occ import Shape
from rjcad.cad.parts import socket_solids, spring_phi0, spring_solids, tube_path
from rjcad.cad.spiral import CLOCKWISE, radial_box, strip_solid
from rjcad.design.params import JointParams


def _one_solid(shape: Shape, what: str) -> Shape:
    """Check a boolean result is exactly one valid solid (OCC can return wrong unions silently)."""
    solids = occ.solids(shape)
    valid = occ.is_valid(shape)
    if len(solids) != 1 or not valid:
        raise RuntimeError(f"{what}: boolean gave {len(solids)} solids, valid={valid}")
    return solids[0]


def _fuse(parts: list[Shape], what: str) -> Shape:
    """One batched fuse (never a loop), then clean and check."""
    fused = occ.clean(occ.fuse(parts[0], *parts[1:]))
    return _one_solid(fused, what)


# --------------------------------------------------------------------------
# springs
# --------------------------------------------------------------------------


# --------------------------------------------------------------------------
# ground and moving bodies, as parts (so that the finger can reuse them)
# --------------------------------------------------------------------------


def fork_parts(p: JointParams) -> list[Shape]:
    """Ground-side parts around the axis: pin, cheeks, plates to the block at −X_g, stop lugs, springs."""
    H, xg = p.height, p.ground_block_start
    parts: list[Shape] = [occ.cylinder(p.pin_radius, H)]
    for z0, z1 in (p.z_cheek1, p.z_cheek2):
        h = z1 - z0
        parts.append(occ.cylinder(p.cheek_radius, h, (0.0, 0.0, z0)))
        w = p.cheek_plate_half_width
        parts.append(occ.box(xg + 1.0, 2 * w, h, (-xg - 1.0, -w, z0)))
        # stop lugs: extension (clockwise of the post at rest) and flexion (counter-clockwise at max)
        r0, r1, lw = p.cheek_radius - 1.0, p.post_ring_radius + p.post_radius + 0.5, 2.0
        parts.append(radial_box(r0, r1, lw, -p.stop_angle, z0, h, side=-lw / 2))
        parts.append(radial_box(r0, r1, lw, p.rotation + p.stop_angle, z0, h, side=+lw / 2))
    for z0 in (p.z_spring1[0], p.z_spring2[0]):
        strip, extras = spring_solids(p, z0)
        parts += [strip, *extras]
    return parts


def eye_parts(p: JointParams) -> list[Shape]:
    """Moving-side parts around the axis: eye with groove flanges, eye-band beam to the block, post, sockets."""
    xm = p.block_start
    ze0, ze1 = p.z_eye
    he = ze1 - ze0
    R_e, flange = p.eye_radius, 1.0
    h_s = p.seat_height
    z_post0, z_post1 = p.z_spring1[1] - h_s, p.z_spring2[0] + h_s
    sockets: list[Shape] = []
    if p.end_condition == "clamped":
        sockets = socket_solids(p, z_post0, h_s) + socket_solids(p, p.z_spring2[0], h_s)
    return sockets + [
        occ.cylinder(R_e, he, (0.0, 0.0, ze0)),
        occ.cylinder(R_e + 0.6, flange, (0.0, 0.0, ze0)),
        occ.cylinder(R_e + 0.6, flange, (0.0, 0.0, ze1 - flange)),
        occ.box(xm + 1.0, 2 * R_e, he, (0.0, -R_e, ze0)),
        occ.cylinder(p.post_radius, z_post1 - z_post0, (p.post_ring_radius, 0.0, z_post0)),
    ]


def eye_cuts(p: JointParams, height: float) -> list[Shape]:
    """The eye's bore (pin + clearance) and the tendon slot in the moving block."""
    ze0, ze1 = p.z_eye
    W, R_e, xm = p.link_width, p.eye_radius, p.block_start
    return [
        occ.cylinder(p.pin_radius + p.clearance_mm, height + 2, (0.0, 0.0, -1.0)),
        occ.box(p.slot_length, W / 2 - R_e + 1.0, ze1 - ze0, (xm, R_e, ze0)),
    ]


def ground_side(p: JointParams) -> list[Shape]:
    """The ground body's parts around the axis, in ``p``'s layout."""
    if p.layout == "desktop":
        return desktop.ground_parts(p)
    return fork_parts(p)


def ground_side_cuts(p: JointParams) -> list[Shape]:
    """What the ground body's parts around the axis lose (desktop: the tendon's way through the web)."""
    if p.layout == "desktop":
        return desktop.ground_cuts(p)
    return []


def moving_side(p: JointParams) -> list[Shape]:
    """The moving body's parts around the axis, in ``p``'s layout."""
    if p.layout == "desktop":
        return desktop.moving_parts(p)
    return eye_parts(p)


def moving_side_cuts(p: JointParams, height: float) -> list[Shape]:
    """What the moving body's parts lose: the bore and the slot (stacked), the groove and the slot (desktop)."""
    if p.layout == "desktop":
        return desktop.moving_cuts(p)
    return eye_cuts(p, height)


def support_pin(p: JointParams) -> Shape:
    """Tendon support pin across the slot, above the tendon, embedded 0.5 mm above and below the slot."""
    ze0, ze1 = p.z_eye
    xs = p.block_start + p.slot_length / 2
    ys = p.moment_arm + p.tendon_diameter / 2 + p.support_pin_radius
    return occ.cylinder(p.support_pin_radius, ze1 - ze0 + 1.0, (xs, ys, ze0 - 0.5))


def link_block(x0: float, x1: float, width: float, height: float) -> Shape:
    """Full-height link block from x0 to x1, centred on y = 0, from the bed up."""
    return occ.box(x1 - x0, width, height, (x0, -width / 2, 0.0))


#: Straight run of the tendon's channel into the ground link's end face [mm].
LEAD_IN = 2.0


def ground_channel_points(p: JointParams, reach: float) -> list[tuple[float, float, float]]:
    """Tendon channel centreline in the ground link: from the link end (centre; square to the end face for
    LEAD_IN, so that the mouth leaves no wedge between the face and a slanting channel) to the fork face at y = r."""
    r, zm, xg = p.moment_arm, p.z_mid, p.ground_block_start
    return [(-reach - 0.5, 0.0, zm), (-reach + LEAD_IN, 0.0, zm), (-xg - 3.0, r, zm), (-xg + 0.5, r, zm)]


def moving_channel_start(p: JointParams) -> tuple[float, float, float]:
    """Where the moving link's channel starts: the slot's far end, at y = r, z = z_mid."""
    return (p.block_start + p.slot_length - 0.5, p.moment_arm, p.z_mid)


def moving_channel_points(p: JointParams, reach: float) -> list[tuple[float, float, float]]:
    """Tendon channel centreline in the moving link: from the support slot to the link end at y = r."""
    return [moving_channel_start(p), (reach + 0.5, p.moment_arm, p.z_mid)]


def build_ground(p: JointParams, reach: float | None = None, channel: bool = True) -> Shape:
    """Ground body of a module: fork parts plus the block from x = −reach to −X_g, with its channel."""
    reach = p.link_length if reach is None else reach
    body = _fuse(ground_side(p) + [link_block(-reach, -p.ground_block_start, p.link_width, p.height)], "ground fuse")
    cuts = ground_side_cuts(p)
    if channel:
        cuts += tube_path(ground_channel_points(p, reach), p.tendon_diameter / 2)
    if cuts:
        body = _one_solid(occ.cut(body, *cuts), "ground channel cut")
    return body


def build_moving(p: JointParams, reach: float | None = None, channel: bool = True) -> Shape:
    """Moving body of a module: eye parts plus the block from X_m to x = reach, slot, support pin, channel."""
    reach = p.link_length if reach is None else reach
    body = _fuse(moving_side(p) + [link_block(p.block_start, reach, p.link_width, p.height)], "moving fuse")
    cuts = moving_side_cuts(p, p.height)
    if channel:
        cuts += tube_path(moving_channel_points(p, reach), p.tendon_diameter / 2)
    body = _one_solid(occ.cut(body, *cuts), "moving cut")
    return _fuse([body, support_pin(p)], "support pin")


@dataclass(frozen=True)
class JointSolids:
    """The two printed bodies of one module, in the module frame."""

    params: JointParams
    ground: Shape
    moving: Shape

    @property
    def axis_point(self) -> tuple[float, float, float]:
        return (0.0, 0.0, 0.0)

    @property
    def axis_dir(self) -> tuple[float, float, float]:
        return (0.0, 0.0, 1.0)


def build_joint(p: JointParams) -> JointSolids:
    """Build both bodies of the joint module described by ``p``."""
    return JointSolids(p, build_ground(p), build_moving(p))


def strip_volume(p: JointParams) -> float:
    """B-rep volume of the joint's free spring strips (the parts buried in the fittings excluded) [mm³]."""
    return p.springs * occ.volume(strip_solid(p.spring, spring_phi0(p), 0.0, hand=CLOCKWISE))
