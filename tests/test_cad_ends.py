"""The printed spring is the spring the model designs (issue #14): it winds clockwise outwards, so that the
preload and flexion unwind it; its outer end is held the way ``end`` says (clamped: a key in a socket; pinned:
a ring on a post); the fittings seat with the motion the manifest describes; and the wound strip, from an
independent rod-model run, never meets the other parts over the joint's range."""

import math

import numpy as np
import pytest
from OCP.BRepAdaptor import BRepAdaptor_Surface
from shared_builds import joint_build
from wound_tools import wind, wound_strip_clearance

from rjcad.cad import occ
from rjcad.cad.joint import build_joint
from rjcad.cad.occ import Vec, Z
from rjcad.cad.spiral import line_box
from rjcad.design.params import KEY_ENGAGEMENT, JointParams


@pytest.fixture(scope="module", params=["clamped", "pinned"])
def joint(request):
    """Each end's stacked joint: its solids, from the build this session shares (tests/shared_builds.py)."""
    p = JointParams(layout="stacked", end=request.param)
    return p, joint_build(p).solids


@pytest.fixture(scope="module")
def clamped():
    p = JointParams(layout="stacked", end="clamped")
    return p, joint_build(p).solids


def polar(r, phi, z):
    return (r * math.cos(phi), r * math.sin(phi), z)


def inside(shape, point) -> bool:
    return occ.is_inside(shape, point)


# --------------------------------------------------------------------------- the hand


def test_printed_spiral_winds_clockwise_outwards(joint):
    """Points on r = r_end − p·a/2π at φ = −preload + a (inwards counter-clockwise from the end, i.e. outwards
    clockwise) are in the strip, in both spring layers, and the points half a pitch inside them, in the gap,
    are not: the coils follow that hand. A counter-clockwise strip with the same end fails both."""
    p, j = joint
    d = p.spring
    r_end, k = d.centreline_outer_radius, d.pitch / (2 * math.pi)
    a = np.linspace(0.3, 2 * math.pi * (d.turns - 1), 60)
    for z in (d.width / 2, p.z_spring2[0] + d.width / 2):
        assert all(inside(j.ground, polar(r_end - k * x, -p.preload + x, z)) for x in a)
        assert not any(inside(j.ground, polar(r_end - k * x - d.pitch / 2, -p.preload + x, z)) for x in a)
        ccw = [inside(j.ground, polar(r_end - k * x, -p.preload - x, z)) for x in a]
        assert not all(ccw)


def test_free_strip_has_the_design_length(clamped):
    """0.1 mm inside each end ray the strip is bare (t wide), 0.1 mm beyond it the fitting holds it."""
    p, j = clamped
    d = p.spring
    t, z, k = d.thickness, d.width / 2, d.pitch / (2 * math.pi)
    phi0, phi1 = -p.preload + 2 * math.pi * d.turns, -p.preload
    for r, phi, inward in ((d.inner_radius, phi0, -1), (d.centreline_outer_radius, phi1, +1)):
        inside_strip = phi + inward * 0.1 / r  # towards the free strip
        beyond = phi - inward * 0.1 / r  # into the fitting
        rr = r - inward * k * 0.1 / r
        assert inside(j.ground, polar(rr, inside_strip, z))
        assert not inside(j.ground, polar(rr + t / 2 + 0.05, inside_strip, z))
        assert not inside(j.ground, polar(rr - t / 2 - 0.05, inside_strip, z))
        assert inside(j.ground, polar(r + 0.2 * t, beyond, z))


# --------------------------------------------------------------------------- the fittings


def region(phi, r0, r1, q0, q1, z0, z1):
    """A box from radius r0 to r1 along the ray φ, q0..q1 across it (+ = counter-clockwise), z0..z1."""
    return line_box(0.0, 0.0, phi, (r0, r1), (q0, q1), z0, z1 - z0)


def key_and_socket(p, j, top=False):
    """The bottom (or top) spring's key as printed, and its socket, cut out of the two bodies."""
    d = p.spring
    z0, z1 = (p.z_spring2[0], p.height) if top else (0.0, d.width)
    r0, q = d.outer_radius + 0.05, max(map(abs, p.socket_span)) + 1.0
    key = occ.common(j.ground, region(-p.preload, r0, p.hook_outer_radius + 1.0, -q, q, z0, z1))
    socket = occ.common(j.moving, region(0.0, r0, p.block_start - 0.01, -q, q, z0, z1))
    return key, socket


def seated(shape, p):
    return occ.rotated(shape, math.degrees(p.preload))


def about(shape, centre, angle_deg):
    return occ.rotated(shape, angle_deg, centre, Z)


def overlap(a, b) -> float:
    """The volume a and b share [mm³]."""
    return occ.volume(occ.common(a, b))


@pytest.mark.parametrize("top", [False, True])
def test_clamped_key_bears_in_its_socket_at_the_modelled_pose(clamped, top):
    """Turned by the preload about the axis (the rod model's clamp), the key lies in the socket's slot touching
    its three bearing places (the clockwise tine at its tip, the counter-clockwise tine at its inner end, the
    base); turned 1° further clockwise (the sense the spring's moment pushes it) it cuts into the tines, and
    counter-clockwise it has the play α ≈ 2c/ℓ; printed, it is far from the socket."""
    p, j = clamped
    key, socket = key_and_socket(p, j, top)
    assert occ.volume(key) > 0.5 * KEY_ENGAGEMENT * p.key_width * p.spring.width
    assert occ.distance(key, socket) >= p.clearance  # in print: apart, with the clearance kept
    k = seated(key, p)
    _, ky0, _, kx1, ky1, _ = occ.bounding_box(k)
    sx0, sy0, _, sx1, sy1, _ = occ.bounding_box(socket)
    assert kx1 == pytest.approx(p.key_tip_radius, abs=1e-6)  # the tip on the base's face
    assert (ky0, ky1) == pytest.approx((-p.key_width, 0.0), abs=1e-6)  # clockwise of the end's ray
    assert sy0 < ky0 and ky1 < sy1 and sx0 < kx1 < sx1
    assert overlap(k, socket) < 1e-6 and occ.distance(k, socket) < 1e-6  # touching, not overlapping
    centre = Vec(p.key_tip_radius - KEY_ENGAGEMENT / 2, -p.key_width / 2, 0.0)
    a = math.degrees(p.socket_tilt)
    assert a == pytest.approx(math.degrees(2 * p.clearance / KEY_ENGAGEMENT), rel=0.15)
    assert overlap(about(k, centre, -1.0), socket) > 1e-3  # held against the load
    # the play is the other way (off the base by 0.2 mm, so that the tip's corner can turn): up to 2α
    inward = Vec(-0.2, 0.0, 0.0)
    free, c2 = occ.translated(k, inward), centre + inward
    assert overlap(free, socket) < 1e-6
    assert overlap(about(free, c2, 0.9 * a), socket) < 1e-6
    assert overlap(about(free, c2, 2.0 * a + 1.0), socket) > 1e-3
    out = occ.translated(k, (0.05, 0.0, 0.0))  # the end's outward force: borne by the base
    assert overlap(out, socket) > 1e-4


def test_pinned_ring_is_centred_on_its_post():
    """The ring's bore, turned by the preload, is coaxial with the post; printed, ring and post are apart."""
    p = JointParams(layout="stacked", end="pinned")
    j = joint_build(p).solids

    def cylinders(shape, radius):
        out = []
        for f in occ.faces(shape):
            if occ.is_cylinder(f):
                c = BRepAdaptor_Surface(f).Cylinder()
                if abs(c.Radius() - radius) < 1e-6:
                    loc = c.Location()
                    out.append((loc.X(), loc.Y()))
        return out

    bores = cylinders(j.ground, p.post_radius + p.clearance)
    posts = cylinders(j.moving, p.post_radius)
    assert bores and posts
    c, s = math.cos(p.preload), math.sin(p.preload)
    for x, y in bores:  # every ring's bore (both springs) lands on the post's axis
        xs, ys = c * x - s * y, s * x + c * y
        assert min(math.hypot(xs - px, ys - py) for px, py in posts) < 1e-6
    assert (p.post_ring_radius, 0.0) == pytest.approx(posts[0], abs=1e-6)
    key, post = key_and_socket(p, j)
    assert occ.distance(key, post) >= p.clearance
    assert occ.distance(seated(key, p), post) == pytest.approx(p.clearance, abs=1e-6)  # all round the post


def test_seating_motion_is_free(joint):
    """Pushed out of its layer by seat_height + clearance (away from the middle) and turned 0..preload, the key
    (or ring) never meets the moving body; back in its layer at the preload it is seated."""
    p, j = joint
    for top in (False, True):
        key, socket = key_and_socket(p, j, top)
        push = (p.seat_height + p.clearance) * (1 if top else -1)
        lifted = occ.translated(key, (0.0, 0.0, push))
        for a in np.linspace(0.0, math.degrees(p.preload), 13):
            assert occ.distance(occ.rotated(lifted, a), socket) > 0.01, (top, a)
        # without the push, the socket (or post) blocks the way
        blocked = [overlap(occ.rotated(key, a), socket) > 1e-3 for a in np.linspace(0.0, math.degrees(p.preload), 13)]
        assert any(blocked)
        _, _, zmin, _, _, zmax = occ.bounding_box(socket)
        if top:
            assert zmax == pytest.approx(p.z_spring2[0] + p.seat_height, abs=1e-6)
        else:
            assert zmin == pytest.approx(p.spring.width - p.seat_height, abs=1e-6)


# --------------------------------------------------------------------------- the wound strip (rod model)


def test_clamp_load_bears_one_way_over_the_range(clamped):
    """Over preload..preload + rotation the socket holds the key with a counter-clockwise moment ≈ T (so the
    key turns clockwise in its slot: the faces the socket's tilt is made for) and pushes it inwards (the tip
    bears on the base); the tangential force is small beside the couple's M/ℓ."""
    p, _ = clamped
    sol = wind(p, p.preload + p.rotation, 30)
    theta = (p.preload + p.rotation) * sol.lam
    for k in np.nonzero(theta >= p.preload - 1e-9)[0]:
        X = sol.positions(k)
        Fx, Fy, M = sol.reaction[k][-1]
        T = M + X[-1, 0] * Fy - X[-1, 1] * Fx
        psi = math.atan2(X[-1, 1], X[-1, 0])
        radial = Fx * math.cos(psi) + Fy * math.sin(psi)
        tangential = -Fx * math.sin(psi) + Fy * math.cos(psi)
        assert T > 0 and 0.8 * T < M < 1.2 * T
        assert radial < 0
        assert abs(tangential) < 0.1 * M / KEY_ENGAGEMENT


@pytest.mark.parametrize("end", ["clamped", "pinned"])
def test_wound_strip_clears_the_other_parts(end):
    """The strip wound to every 10° of the wind-up (independent rod-model run) keeps the internal gap from the
    ground block (assembly and range) and from the moving body (turned with the joint, over the range), in
    both spring layers."""
    p = JointParams(layout="stacked", end=end)
    assert wound_strip_clearance(p, joint_build(p).meshes) >= p.gap_internal - 0.05


def test_preload_below_the_sockets_reach_is_refused():
    """A small spring with a wide clearance: its socket reaches far clockwise, so a small preload would print the
    key into it. Just below the builder's minimum preload is one ParameterError; just above, the printed key
    clears the socket by the clearance."""
    from rjcad.errors import ParameterError

    kw = dict(stiffness=1.0, rotation=20 * math.pi / 180, clearance=0.5, link_length=32.0, printer="dimension-elite")
    deg = math.pi / 180

    def accepted(preload):
        try:
            return JointParams(**kw, preload=preload)
        except ParameterError as e:
            assert e.parameter == "preload" and "socket" in str(e)
            return None

    # the minimum moves with the preload (the spring is redesigned for it): bisect for the smallest accepted one
    lo, hi = 30 * deg, 60 * deg
    assert accepted(lo) is None and accepted(hi) is not None
    while hi - lo > 0.25 * deg:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if accepted(mid) is not None else (mid, hi)
    with pytest.raises(ParameterError) as e:
        JointParams(**kw, preload=hi - 2 * deg)
    assert e.value.parameter == "preload" and "socket" in str(e.value)
    p = accepted(hi)
    assert 0 <= p.preload - p.min_preload < 1.0 * deg
    key, socket = key_and_socket(p, build_joint(p))
    assert p.clearance <= occ.distance(key, socket) < p.clearance + 0.3
