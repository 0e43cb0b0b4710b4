"""Simplified copies of the bodies, on which the gaps and the motion sweep are measured.

manifold3d's ``simplify(t)`` keeps a subset of a body's vertices and moves no surface by t or more. So a gap
between copies within t of their bodies is within 2t of the bodies' gap, and copies more than 4t apart prove
their bodies apart: crossing surfaces would leave the copies within 2t, a body inside another within 4t.

Two tiers: ``fine`` copies (FINE_TOL_MM) give every reported gap; ``coarse`` ones (COARSE_TOL_MM more) screen
the poses and pairs, and only those that come near are measured on the fine copies (gaps) or on the bodies
(overlaps). Simplifying removes what a tessellation holds beyond its shape at that tolerance (vertices inside
flat faces and along straight edges, a subdivided mesh's midpoints, chords finer than the allowance): the
sweep then costs what the shape costs, not what the triangle count costs. A copy that does not halve its
body's triangles is not kept: the body itself stands in (the same object), and its measures are exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import manifold3d as m3
import numpy as np

#: Tolerance of the fine copies [mm]: reported gaps are within 2·FINE_TOL_MM of the bodies'.
FINE_TOL_MM = 1e-5
#: Added tolerance of the coarse copies [mm]: a quarter of the default tessellation allowance (0.02 mm).
COARSE_TOL_MM = 5e-3
#: How far a coarse copy may lie from its body [mm].
DEV_MM = FINE_TOL_MM + COARSE_TOL_MM
#: Coarse copies farther apart than this prove their bodies apart [mm].
APART_MM = 4 * DEV_MM


@dataclass
class Copies:
    """The bodies (manifolds) and their fine and coarse copies, index for index."""

    bodies: list[m3.Manifold]
    fine: list[m3.Manifold]
    coarse: list[m3.Manifold]

    def exact(self, idx) -> bool:
        """Whether the coarse copies of these bodies are the bodies themselves (nothing was simplified)."""
        return all(self.coarse[i] is self.bodies[i] for i in idx)

    def same(self, idx) -> bool:
        """Whether the coarse copies of these bodies are their fine copies (a coarse gap is then the fine gap)."""
        return all(self.coarse[i] is self.fine[i] for i in idx)


def _copy(m: m3.Manifold, tol: float) -> m3.Manifold:
    c = m.simplify(tol)
    return c if c.num_tri() <= m.num_tri() // 2 else m


def simplified(mans: list[m3.Manifold]) -> Copies:
    """Each body's fine copy, and a coarse copy of that."""
    fine = [_copy(m, FINE_TOL_MM) for m in mans]
    return Copies(list(mans), fine, [_copy(f, COARSE_TOL_MM) for f in fine])


def _vertices(m: m3.Manifold) -> np.ndarray:
    return np.asarray(m.to_mesh64().vert_properties)[:, :3]


def min_gap(a: m3.Manifold, b: m3.Manifold, search: float) -> float:
    """manifold3d's ``min_gap`` (0 when they overlap, ``search`` when nothing is nearer) with the search length cut
    to the nearest vertex pair's distance, which no gap exceeds: ``min_gap`` measures every pair of triangles
    whose boxes lie within the search length, i.e. pairs × (search / edge)² on a fine mesh."""
    from scipy.spatial import cKDTree

    va, vb = _vertices(a), _vertices(b)
    if not len(va) or not len(vb):
        return float(search)
    nearest = float(cKDTree(vb).query(va, distance_upper_bound=search)[0].min())
    return float(a.min_gap(b, min(search, nearest * (1 + 1e-9) + 1e-9)))


def near(a: m3.Manifold, b: m3.Manifold) -> bool:
    """Whether two coarse copies lie within APART_MM (their bodies may then touch or overlap)."""
    return a.min_gap(b, APART_MM) < APART_MM


def refined(coarse_gap: float, fine_a: m3.Manifold, fine_b: m3.Manifold, search: float, same: bool) -> float:
    """The fine copies' gap (``min_gap`` semantics), given their coarse copies' gap (``same``: the coarse copies are
    the fine ones): the two differ by less than 2·(DEV_MM + FINE_TOL_MM), so the search stops there."""
    if same or coarse_gap >= search:
        return float(min(coarse_gap, search))
    return float(fine_a.min_gap(fine_b, min(search, coarse_gap + 2 * (DEV_MM + FINE_TOL_MM) + 1e-9)))


def candidates(coarse_gaps: list[float]) -> list[int]:
    """Indices whose coarse gap may hide the smallest fine one (within 4·(DEV_MM + FINE_TOL_MM) of the smallest)."""
    lo = min(coarse_gaps)
    return [k for k, g in enumerate(coarse_gaps) if g <= lo + 4 * (DEV_MM + FINE_TOL_MM)]
