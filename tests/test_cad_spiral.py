"""rjcad.cad.spiral: the strip's arcs lie on the Archimedean spiral, clockwise outwards by default, its volume
is b·t·L, and the boxes and rings it is assembled from have the sizes asked for. Small solids only (no joint
build)."""

import itertools
import math

import pytest
from OCP.BRepAdaptor import BRepAdaptor_Curve

from rjcad.cad import occ
from rjcad.cad.occ import Vec
from rjcad.cad.spiral import COUNTER_CLOCKWISE, line_box, radial_box, ring, spiral_side, strip_solid
from rjcad.design.params import JointParams


@pytest.fixture(scope="module")
def design():
    """The default joint's spring (the paper's 5.2 N·mm/rad joint)."""
    return JointParams().spring


def radius(v: Vec) -> float:
    return math.hypot(v.x, v.y)


def point_at(edge, fraction: float) -> Vec:
    """The point ``fraction`` of the way along an edge's parameter (of its length, for an arc or a line)."""
    c = BRepAdaptor_Curve(edge)
    return Vec(*c.Value(c.FirstParameter() + fraction * (c.LastParameter() - c.FirstParameter())).Coord())


def test_arcs_follow_the_spiral_from_start_to_end():
    r_in, pitch, turns, phi0 = 3.0, 1.2, 2.5, 0.3
    edges = spiral_side(r_in, pitch, turns, phi0, offset=0.4, arcs_per_turn=6, hand=COUNTER_CLOCKWISE)
    assert len(edges) == math.ceil(turns * 6)
    a, b = occ.edge_ends(edges[0])[0], occ.edge_ends(edges[-1])[1]
    assert radius(a) == pytest.approx(r_in + 0.4) and math.atan2(a.y, a.x) == pytest.approx(phi0)
    assert radius(b) == pytest.approx(r_in + pitch * turns + 0.4)
    for e in edges:  # consecutive arcs join, and every arc's midpoint is on r(φ) + offset
        m = point_at(e, 0.5)
        phi = (math.atan2(m.y, m.x) - phi0) % (2 * math.pi)
        on_spiral = [r_in + 0.4 + pitch * (phi + 2 * math.pi * k) / (2 * math.pi) for k in range(4)]
        assert min(abs(radius(m) - r) for r in on_spiral) < 0.01
    for e1, e2 in itertools.pairwise(edges):
        assert (occ.edge_ends(e1)[1] - occ.edge_ends(e2)[0]).length < 1e-9
    back = spiral_side(r_in, pitch, turns, phi0, offset=0.4, backwards=True, hand=COUNTER_CLOCKWISE)
    assert (occ.edge_ends(back[0])[0] - b).length < 1e-9 and (occ.edge_ends(back[-1])[1] - a).length < 1e-9


def test_strip_volume_is_width_thickness_length(design):
    s = strip_solid(design, phi0=0.0, z0=2.0)
    assert occ.is_valid(s) and len(occ.solids(s)) == 1
    assert occ.volume(s) == pytest.approx(design.width * design.thickness * design.length, rel=0.01)
    xmin, ymin, zmin, xmax, ymax, zmax = occ.bounding_box(s)
    assert zmin == pytest.approx(2.0) and zmax == pytest.approx(2.0 + design.width)
    assert max(xmax, ymax, -xmin, -ymin) <= design.outer_radius + 1e-6


def test_radial_box_sits_on_its_ray():
    box = radial_box(5.0, 9.0, 2.0, math.radians(90), z0=1.0, height=3.0, side=0.5)
    assert occ.volume(box) == pytest.approx(4.0 * 2.0 * 3.0)
    xmin, ymin, zmin, xmax, ymax, zmax = occ.bounding_box(box)  # along +y from 5 to 9, shifted 0.5 mm counter-clockwise
    assert (ymin, ymax) == pytest.approx((5.0, 9.0))
    assert (xmin, xmax) == pytest.approx((-1.5, 0.5))
    assert (zmin, zmax) == pytest.approx((1.0, 4.0))


def test_the_default_hand_is_clockwise_outwards():
    """Walking the strip outwards turns clockwise: r grows as the polar angle falls (seen from +Z)."""
    r_in, pitch, turns, phi0 = 3.0, 1.2, 2.0, 0.0
    edges = spiral_side(r_in, pitch, turns, phi0, offset=0.0)
    pts = [point_at(e, f) for e in edges for f in (0.0, 0.5)] + [occ.edge_ends(edges[-1])[1]]
    unwrapped, prev = [], None
    for v in pts:
        a = math.atan2(v.y, v.x)
        if prev is not None:
            a = prev + (a - prev + math.pi) % (2 * math.pi) - math.pi
        unwrapped.append(a)
        prev = a
    assert all(b < a for a, b in itertools.pairwise(unwrapped))  # clockwise all the way
    assert unwrapped[-1] == pytest.approx(phi0 - 2 * math.pi * turns, abs=1e-9)
    for v, a in zip(pts, unwrapped):  # and r = r_in + p·(φ0 − φ)/2π
        assert radius(v) == pytest.approx(r_in + pitch * (phi0 - a) / (2 * math.pi), abs=0.01)


def test_extended_strip_runs_past_both_rays(design):
    """``extend`` adds that much strip beyond each end ray (buried in the fittings); the rest is unchanged."""
    plain = strip_solid(design, phi0=0.0, z0=0.0)
    longer = strip_solid(design, phi0=0.0, z0=0.0, extend=0.3)
    assert occ.volume(longer) - occ.volume(plain) == pytest.approx(2 * 0.3 * design.thickness * design.width, rel=0.05)
    r_in, r_out, k = design.inner_radius, design.centreline_outer_radius, design.pitch / (2 * math.pi)
    z = design.width / 2
    for a in (-0.15 / r_in, 2 * math.pi * design.turns + 0.15 / r_out):  # 0.15 mm past each end, clockwise hand
        v = ((r_in + k * a) * math.cos(-a), (r_in + k * a) * math.sin(-a), z)
        assert occ.is_inside(longer, v) and not occ.is_inside(plain, v)


def test_line_box_follows_its_frame():
    box = line_box(10.0, 1.0, math.radians(90), (0.0, 4.0), (-1.0, 0.0), z0=0.0, height=2.0)
    xmin, ymin, _, xmax, ymax, _ = occ.bounding_box(box)  # along +y from (10, 1), 1 mm to its right (+x)
    assert (xmin, xmax, ymin, ymax) == pytest.approx((10.0, 11.0, 1.0, 5.0))
    assert occ.volume(box) == pytest.approx(8.0)


def test_ring_is_closed_all_round():
    r_in, r_out, h = 1.0, 2.0, 3.0
    rg = ring(10.0, math.radians(90), r_in, r_out, z0=0.0, height=h)
    assert occ.volume(rg) == pytest.approx(math.pi * (r_out**2 - r_in**2) * h, rel=1e-6)
    for a in range(0, 360, 30):  # centred at (0, 10): closed on every side
        c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
        assert occ.is_inside(rg, (1.5 * c, 10.0 + 1.5 * s, 1.0))
        assert not occ.is_inside(rg, (0.5 * c, 10.0 + 0.5 * s, 1.0))
