"""Spiral strip solids built from 3-point arcs (analytic faces, fast booleans).

The centreline is r(φ) = r_in + p·(φ − φ0)/(2π), φ ∈ [φ0, φ0 + 2πn], going
counter-clockwise outwards, so that turning the outer end counter-clockwise
(joint flexion) tightens the spiral. Each side of the strip (r ∓ t/2) is a
chain of 3-point arcs, ``arcs_per_turn`` per turn.
"""

from __future__ import annotations

import math

import cadquery as cq

from rjcad.spring import SpringDesign


def _pt(r: float, phi: float) -> cq.Vector:
    return cq.Vector(r * math.cos(phi), r * math.sin(phi), 0.0)


def spiral_side(r_in: float, pitch: float, turns: float, phi0: float, offset: float,
                arcs_per_turn: int = 6, backwards: bool = False) -> list[cq.Edge]:
    """Arcs through r(φ) + offset from φ0 to φ0 + 2πn (counter-clockwise), or back."""
    k = pitch / (2 * math.pi)
    span = 2 * math.pi * turns
    n_arcs = max(2, math.ceil(turns * arcs_per_turn))
    edges = []
    order = range(n_arcs - 1, -1, -1) if backwards else range(n_arcs)
    for i in order:
        a, b = span * i / n_arcs, span * (i + 1) / n_arcs
        if backwards:
            a, b = b, a
        m = 0.5 * (a + b)
        edges.append(cq.Edge.makeThreePointArc(
            _pt(r_in + k * a + offset, phi0 + a), _pt(r_in + k * m + offset, phi0 + m),
            _pt(r_in + k * b + offset, phi0 + b)))
    return edges


def strip_solid(design: SpringDesign, phi0: float, z0: float, arcs_per_turn: int = 6) -> cq.Solid:
    """The spiral strip alone (no tab, no hook), extruded over z ∈ [z0, z0 + b]."""
    r_in, p, n, t = design.inner_radius, design.pitch, design.turns, design.thickness
    outer = spiral_side(r_in, p, n, phi0, +t / 2, arcs_per_turn)
    inner_back = spiral_side(r_in, p, n, phi0, -t / 2, arcs_per_turn, backwards=True)
    phi1 = phi0 + 2 * math.pi * n
    r_out = r_in + p * n
    end_cap = cq.Edge.makeLine(_pt(r_out + t / 2, phi1), _pt(r_out - t / 2, phi1))
    start_cap = cq.Edge.makeLine(_pt(r_in - t / 2, phi0), _pt(r_in + t / 2, phi0))
    wire = cq.Wire.assembleEdges(outer + [end_cap] + inner_back + [start_cap])
    face = cq.Face.makeFromWires(wire)
    return cq.Solid.extrudeLinear(face, cq.Vector(0, 0, design.width)).translate(cq.Vector(0, 0, z0))


def radial_box(r0: float, r1: float, width: float, phi: float, z0: float, height: float,
               side: float = 0.0) -> cq.Solid:
    """Box from radius r0 to r1 along the ray at angle φ, ``width`` across it.

    ``side`` shifts the box across the ray (+ = counter-clockwise side) by that many mm.
    """
    box = cq.Solid.makeBox(r1 - r0, width, height, cq.Vector(r0, -width / 2 + side, z0))
    return box.rotate(cq.Vector(0, 0, 0), cq.Vector(0, 0, 1), math.degrees(phi))


def ring_hook(centre_r: float, phi: float, r_inner: float, r_outer: float, z0: float, height: float,
              keep_past_centre: float) -> cq.Solid:
    """A C-shaped hook: the annulus [r_inner, r_outer] around (centre_r, φ), open counter-clockwise.

    The part kept is the clockwise half plus ``keep_past_centre`` mm beyond the centre line.
    """
    c = _pt(centre_r, phi)
    ring = cq.Solid.makeCylinder(r_outer, height, cq.Vector(c.x, c.y, z0)).cut(
        cq.Solid.makeCylinder(r_inner, height, cq.Vector(c.x, c.y, z0)))
    # remove the counter-clockwise side: a box beyond the centre line, in the tangential direction
    big = 2 * r_outer + 2
    cutter = cq.Solid.makeBox(big, big, height + 2, cq.Vector(-big / 2, keep_past_centre, z0 - 1))
    cutter = cutter.rotate(cq.Vector(0, 0, 0), cq.Vector(0, 0, 1), math.degrees(phi)).translate(c)
    return ring.cut(cutter)
