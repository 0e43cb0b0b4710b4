"""Spiral strip solids built from 3-point arcs (analytic faces, fast booleans), and the boxes and rings
its end fittings are made of.

The centreline is r(a) = r_in + p·a/(2π) at the polar angle φ = φ0 + hand·a, a ∈ [0, 2πn]. The joint
prints ``hand = −1``: the spiral winds CLOCKWISE outwards (seen from +Z), so that turning its outer end
counter-clockwise (the preload, then joint flexion) UNWINDS it. Each side of the strip (r ∓ t/2) is a
chain of 3-point arcs, ``arcs_per_turn`` per turn. The strip may run on past both of the design's end
rays by ``extend`` mm: that part is buried in the end fittings, so the free strip between them has the
design's length.
"""

from __future__ import annotations

import math
from typing import Any

from OCP.TopoDS import TopoDS_Edge

from rjcad.cad import occ
from rjcad.cad.occ import Shape, Vec
from rjcad.spring import SpringDesign

CLOCKWISE = -1
COUNTER_CLOCKWISE = 1


def _pt(r: float, phi: float) -> Vec:
    return Vec(r * math.cos(phi), r * math.sin(phi), 0.0)


def spiral_side(
    r_in: float,
    pitch: float,
    turns: float,
    phi0: float,
    offset: float,
    arcs_per_turn: int = 6,
    backwards: bool = False,
    hand: int = CLOCKWISE,
    a_start: float = 0.0,
    a_end: float | None = None,
    normal: bool = False,
) -> list[TopoDS_Edge]:
    """Arcs through r(a) + offset at φ0 + hand·a, for a from ``a_start`` to ``a_end`` (2πn), or back [rad].

    ``normal``: the offset is along the spiral's normal, not the radius: r(a) + offset·√(r² + k²)/r, k = p/2π
    (a radial offset leaves a strip t·r/√(r² + k²) thick: 0.92·t near the hub of a coarse two-arm spiral)."""
    k = pitch / (2 * math.pi)

    def _pt_at(a: float) -> Vec:
        r = r_in + k * a
        return _pt(r + offset * (math.hypot(r, k) / r if normal else 1.0), phi0 + hand * a)

    a_end = 2 * math.pi * turns if a_end is None else a_end
    span = a_end - a_start
    n_arcs = max(2, math.ceil(span / (2 * math.pi) * arcs_per_turn))
    edges = []
    order = range(n_arcs - 1, -1, -1) if backwards else range(n_arcs)
    for i in order:
        a, b = a_start + span * i / n_arcs, a_start + span * (i + 1) / n_arcs
        if backwards:
            a, b = b, a
        m = 0.5 * (a + b)
        edges.append(occ.arc(_pt_at(a), _pt_at(m), _pt_at(b)))
    return edges


def strip_solid(
    design: SpringDesign, phi0: float, z0: float, arcs_per_turn: int = 6, hand: int = CLOCKWISE, extend: float = 0.0
) -> Shape:
    """The spiral strip alone (no tab, no key), extruded over z ∈ [z0, z0 + b].

    ``extend`` [mm] prolongs the strip past both end rays (arc length ≈ extend at each end). A two-arm spring's
    coarse spiral has its sides offset along the normal (``spiral_side``), so that the strip is t thick.
    """
    r_in, p, n, t = design.inner_radius, design.arm_pitch, design.turns, design.thickness
    r_out = r_in + p * n
    a0, a1 = -extend / r_in, 2 * math.pi * n + extend / r_out
    normal = design.arms == 2
    kw: dict[str, Any] = dict(arcs_per_turn=arcs_per_turn, hand=hand, a_start=a0, a_end=a1, normal=normal)
    outer = spiral_side(r_in, p, n, phi0, +t / 2, **kw)
    inner_back = spiral_side(r_in, p, n, phi0, -t / 2, backwards=True, **kw)
    k = p / (2 * math.pi)
    r0, r1 = r_in + k * a0, r_in + k * a1
    h0, h1 = (math.hypot(r0, k) / r0, math.hypot(r1, k) / r1) if normal else (1.0, 1.0)
    phi_s, phi_e = phi0 + hand * a0, phi0 + hand * a1
    end_cap = occ.line(_pt(r1 + h1 * t / 2, phi_e), _pt(r1 - h1 * t / 2, phi_e))
    start_cap = occ.line(_pt(r0 - h0 * t / 2, phi_s), _pt(r0 + h0 * t / 2, phi_s))
    face = occ.planar_face(occ.wire(outer + [end_cap] + inner_back + [start_cap]))
    return occ.translated(occ.prism(face, (0.0, 0.0, design.width)), (0.0, 0.0, z0))


def radial_box(r0: float, r1: float, width: float, phi: float, z0: float, height: float, side: float = 0.0) -> Shape:
    """Box from radius r0 to r1 along the ray at angle φ, ``width`` across it.

    ``side`` shifts the box across the ray (+ = counter-clockwise side) by that many mm.
    """
    return occ.rotated(occ.box(r1 - r0, width, height, (r0, -width / 2 + side, z0)), math.degrees(phi))


def line_box(
    u: float, v: float, angle: float, s: tuple[float, float], q: tuple[float, float], z0: float, height: float
) -> Shape:
    """Box in the frame whose origin is (u, v) and whose x axis points at ``angle`` [rad]:
    s[0]..s[1] along that axis, q[0]..q[1] across it (+ = to its left), z0..z0 + height."""
    box = occ.box(s[1] - s[0], q[1] - q[0], height, (s[0], q[0], z0))
    return occ.translated(occ.rotated(box, math.degrees(angle)), (u, v, 0.0))


def ring(centre_r: float, phi: float, r_inner: float, r_outer: float, z0: float, height: float) -> Shape:
    """A closed ring, the annulus [r_inner, r_outer] around the point at radius ``centre_r`` on the ray φ."""
    c = _pt(centre_r, phi)
    base = (c.x, c.y, z0)
    return occ.cut(occ.cylinder(r_outer, height, base), occ.cylinder(r_inner, height, base))
