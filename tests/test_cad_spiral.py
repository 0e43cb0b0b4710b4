"""rjcad.cad.spiral: the strip's arcs lie on the Archimedean spiral, its volume is b·t·L, and the boxes and
hooks it is assembled from have the sizes asked for. Small solids only (no joint build)."""

import math

import cadquery as cq
import pytest

from rjcad.cad.spiral import radial_box, ring_hook, spiral_side, strip_solid
from rjcad.params import JointParams


@pytest.fixture(scope="module")
def design():
    """The default joint's spring (the paper's 5.2 N·mm/rad joint)."""
    return JointParams().spring


def radius(v: cq.Vector) -> float:
    return math.hypot(v.x, v.y)


def test_arcs_follow_the_spiral_from_start_to_end():
    r_in, pitch, turns, phi0 = 3.0, 1.2, 2.5, 0.3
    edges = spiral_side(r_in, pitch, turns, phi0, offset=0.4, arcs_per_turn=6)
    assert len(edges) == math.ceil(turns * 6)
    a, b = edges[0].startPoint(), edges[-1].endPoint()
    assert radius(a) == pytest.approx(r_in + 0.4) and math.atan2(a.y, a.x) == pytest.approx(phi0)
    assert radius(b) == pytest.approx(r_in + pitch * turns + 0.4)
    for e in edges:  # consecutive arcs join, and every arc's midpoint is on r(φ) + offset
        m = e.positionAt(0.5)
        phi = (math.atan2(m.y, m.x) - phi0) % (2 * math.pi)
        on_spiral = [r_in + 0.4 + pitch * (phi + 2 * math.pi * k) / (2 * math.pi) for k in range(4)]
        assert min(abs(radius(m) - r) for r in on_spiral) < 0.01
    for e1, e2 in zip(edges, edges[1:]):
        assert (e1.endPoint() - e2.startPoint()).Length < 1e-9
    back = spiral_side(r_in, pitch, turns, phi0, offset=0.4, backwards=True)
    assert (back[0].startPoint() - b).Length < 1e-9 and (back[-1].endPoint() - a).Length < 1e-9


def test_strip_volume_is_width_thickness_length(design):
    s = strip_solid(design, phi0=0.0, z0=2.0)
    assert s.isValid() and len(s.Solids()) == 1
    assert s.Volume() == pytest.approx(design.width * design.thickness * design.length, rel=0.01)
    bb = s.BoundingBox()
    assert bb.zmin == pytest.approx(2.0) and bb.zmax == pytest.approx(2.0 + design.width)
    assert max(bb.xmax, bb.ymax, -bb.xmin, -bb.ymin) <= design.outer_radius + 1e-6


def test_radial_box_sits_on_its_ray():
    box = radial_box(5.0, 9.0, 2.0, math.radians(90), z0=1.0, height=3.0, side=0.5)
    assert box.Volume() == pytest.approx(4.0 * 2.0 * 3.0)
    bb = box.BoundingBox()  # along +y from 5 to 9, shifted 0.5 mm counter-clockwise (towards −x)
    assert (bb.ymin, bb.ymax) == pytest.approx((5.0, 9.0))
    assert (bb.xmin, bb.xmax) == pytest.approx((-1.5, 0.5))
    assert (bb.zmin, bb.zmax) == pytest.approx((1.0, 4.0))


def test_ring_hook_keeps_the_clockwise_half_and_a_bit():
    r_in, r_out, h, keep = 1.0, 2.0, 3.0, 0.5
    hook = ring_hook(10.0, 0.0, r_in, r_out, z0=0.0, height=h, keep_past_centre=keep)
    annulus = math.pi * (r_out**2 - r_in**2) * h
    assert annulus / 2 < hook.Volume() < annulus
    # the counter-clockwise side (+y at φ = 0) is open beyond `keep`, the clockwise side is closed
    assert hook.isInside(cq.Vector(10.0, -1.5, 1.0))
    assert not hook.isInside(cq.Vector(10.0, 1.5, 1.0))
    assert hook.isInside(cq.Vector(11.5, 0.25, 1.0))
