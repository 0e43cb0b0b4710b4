"""Distances between the shapes of a grasp in the flexion plane [mm]: links' outlines (polylines), cylinders
(circles) and boxes (convex polygons).

Every function returns (gap, point on A, point on B, unit normal from A towards B). The gap is the distance where
the shapes are apart and minus the depth of overlap where they overlap (along the axis of least overlap, the
separating-axis test), so it is continuous through contact and zero there.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

Gap = tuple[float, np.ndarray, np.ndarray, np.ndarray]


def _unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    d = float(np.hypot(v[0], v[1]))
    return v / d if d > 1e-12 else fallback


def closest_on_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The point of segment ab nearest p."""
    ab = b - a
    den = float(ab @ ab)
    u = 0.0 if den == 0 else min(1.0, max(0.0, float((p - a) @ ab) / den))
    out: np.ndarray = a + u * ab
    return out


def _left_normal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = _unit(b - a, np.array([1.0, 0.0]))
    return np.array([-d[1], d[0]])


def polyline_circle(line: np.ndarray, centre: np.ndarray, radius: float) -> Gap:
    """A polyline (k, 2) against a circle: the nearest of its segments; the normal from the line to the centre."""
    best: Gap | None = None
    for a, b in pairwise(line):
        p = closest_on_segment(centre, a, b)
        n = _unit(centre - p, _left_normal(a, b))
        gap = float(np.hypot(*(centre - p))) - radius
        if best is None or gap < best[0]:
            best = (gap, p, centre - radius * n, n)
    assert best is not None
    return best


def polygon_circle(poly: np.ndarray, centre: np.ndarray, radius: float) -> Gap:
    """A convex polygon (k, 2), counter-clockwise, against a circle; negative inside."""
    closed = np.vstack([poly, poly[:1]])
    gap, p, q, n = polyline_circle(closed, centre, radius)
    edges = closed[1:] - closed[:-1]
    rel = centre - closed[:-1]
    if np.all(edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0] > 0):  # the centre is inside
        d = gap + radius
        return -d - radius, p, centre + radius * n, -n
    return gap, p, q, n


def _axes(poly: np.ndarray, closed: bool) -> list[np.ndarray]:
    pts = np.vstack([poly, poly[:1]]) if closed else poly
    out = []
    for a, b in pairwise(pts):
        n = _left_normal(a, b)
        out += [n, -n]
    return out


def polygons(a: np.ndarray, a_closed: bool, b: np.ndarray, b_closed: bool) -> Gap:
    """Two convex shapes (a segment is one: two points, not closed): the exact distance where apart, the
    separating-axis overlap where not."""
    best_sep, axis, own = -np.inf, np.array([0.0, 1.0]), True
    for u, of_a in [(u, True) for u in _axes(a, a_closed)] + [(u, False) for u in _axes(b, b_closed)]:
        sep = float((b @ u).min() - (a @ u).max())
        if sep > best_sep:
            best_sep, axis, own = sep, u, of_a
    if best_sep <= 0:  # overlap: the other shape's deepest vertex across the face of least overlap
        if own:
            pb = b[int(np.argmin(b @ axis))]
            return best_sep, pb - best_sep * axis, pb, axis
        pa = a[int(np.argmax(a @ axis))]
        return best_sep, pa, pa + best_sep * axis, axis
    best: Gap | None = None
    for pts, other, other_closed, flip in ((a, b, b_closed, False), (b, a, a_closed, True)):
        ring = np.vstack([other, other[:1]]) if other_closed else other
        for v in pts:
            for s, e in pairwise(ring):
                q = closest_on_segment(v, s, e)
                d = float(np.hypot(*(v - q)))
                if best is None or d < best[0]:
                    pa, pb = (q, v) if flip else (v, q)
                    best = (d, pa, pb, _unit(pb - pa, axis))
    assert best is not None
    return best


def polyline_polygon(line: np.ndarray, poly: np.ndarray) -> Gap:
    """A polyline against a convex polygon: the nearest of its segments."""
    gaps = [polygons(line[k : k + 2], False, poly, True) for k in range(len(line) - 1)]
    return min(gaps, key=lambda g: g[0])


def circles(ca: np.ndarray, ra: float, cb: np.ndarray, rb: float) -> Gap:
    """Two circles; the normal from a's centre to b's."""
    n = _unit(cb - ca, np.array([1.0, 0.0]))
    return float(np.hypot(*(cb - ca))) - ra - rb, ca + ra * n, cb - rb * n, n
