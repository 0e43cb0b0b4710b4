"""Distances between the shapes of a grasp in the flexion plane [mm]: links' outlines (polylines, one-sided: an
object is on their palm side, the left of their direction of increasing x), cylinders (circles) and boxes (convex
polygons, counter-clockwise).

Every function returns (gap, point on A, point on B, unit normal from A towards B). The gap is the distance where
the shapes are apart and negative where they overlap (how far the deepest point is in), so it is continuous
through contact and zero there.
"""

from __future__ import annotations

import math

import numpy as np

Gap = tuple[float, np.ndarray, np.ndarray, np.ndarray]
Nearest = tuple[np.ndarray, np.ndarray, np.ndarray]


def _unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    d = float(np.hypot(v[0], v[1]))
    return v / d if d > 1e-12 else fallback


def to_segments(
    points: np.ndarray, points_s: np.ndarray, points_e: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distances (k, m) from k points to m segments (starts, ends), the nearest points (k, m, 2), and where they
    lie along each segment (k, m) (0 at its start, 1 at its end)."""
    ab = points_e - points_s
    den = np.einsum("ij,ij->i", ab, ab)
    rel = points[:, None, :] - points_s[None, :, :]
    u = np.clip(np.einsum("kmj,mj->km", rel, ab) / np.where(den > 0, den, 1.0), 0.0, 1.0)
    near = points_s[None, :, :] + u[..., None] * ab[None, :, :]
    diff = points[:, None, :] - near
    return np.sqrt(diff[..., 0] ** 2 + diff[..., 1] ** 2), near, u


def _left(s: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Unit normals (m, 2) to the left of segments s → e."""
    d = e - s
    n = np.column_stack([-d[:, 1], d[:, 0]])
    out: np.ndarray = n / np.maximum(np.hypot(n[:, 0], n[:, 1]), 1e-12)[:, None]
    return out


def to_polyline(points: np.ndarray, line: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed distances (k,) of points to a one-sided polyline (positive on its left, and past its ends), the nearest
    points (k, 2), and the unit normals from the line towards each point (k, 2)."""
    s, e = line[:-1], line[1:]
    d, near, u = to_segments(points, s, e)
    j = np.argmin(d, axis=1)
    k = np.arange(len(points))
    p, dist, at = near[k, j], d[k, j], u[k, j]
    left = _left(s[j], e[j])
    away = points - p
    # behind the line only where the nearest point is not one of its two ends (a point past an end is beside it)
    at_end = ((j == 0) & (at <= 0.0)) | ((j == len(s) - 1) & (at >= 1.0))
    side = np.where((np.einsum("ij,ij->i", away, left) >= 0) | at_end, 1.0, -1.0)
    normal = np.where(dist[:, None] > 1e-9, away * side[:, None] / np.maximum(dist, 1e-12)[:, None], left)
    return side * dist, p, normal


def to_polygon(points: np.ndarray, poly: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed distances (k,) of points to a convex polygon's boundary (negative inside), the nearest boundary
    points (k, 2), and the unit outward normals there (k, 2)."""
    ring = np.vstack([poly, poly[:1]])
    d, near, _ = to_segments(points, ring[:-1], ring[1:])
    j = np.argmin(d, axis=1)
    k = np.arange(len(points))
    p, dist = near[k, j], d[k, j]
    outward = -_left(ring[:-1], ring[1:])[j]  # counter-clockwise: the outside is on the right
    edges = ring[1:] - ring[:-1]
    rel = points[:, None, :] - ring[None, :-1, :]
    inside = np.all(edges[None, :, 0] * rel[..., 1] - edges[None, :, 1] * rel[..., 0] > 0, axis=1)
    side = np.where(inside, -1.0, 1.0)
    away = points - p
    normal = np.where(dist[:, None] > 1e-9, away * side[:, None] / np.maximum(dist, 1e-12)[:, None], outward)
    return side * dist, p, normal


def polyline_circle(line: np.ndarray, centre: np.ndarray, radius: float) -> Gap:
    """A link's outline against a circle (``to_polyline`` for its one centre, in fewer array operations: the
    solver asks it thousands of times a closure)."""
    start, ab = line[:-1], line[1:] - line[:-1]
    den = (ab * ab).sum(axis=1)
    u = np.clip(((centre - start) * ab).sum(axis=1) / np.where(den > 0, den, 1.0), 0.0, 1.0)
    near = start + u[:, None] * ab
    diff = centre - near
    d2 = (diff * diff).sum(axis=1)
    j = int(np.argmin(d2))
    p, dist, a = near[j], math.sqrt(float(d2[j])), ab[j]
    left = np.array([-a[1], a[0]]) / max(math.hypot(a[0], a[1]), 1e-12)
    away = centre - p
    at_end = (j == 0 and u[j] <= 0.0) or (j == len(ab) - 1 and u[j] >= 1.0)  # beside the line, not behind it
    side = 1.0 if at_end or float(away @ left) >= 0 else -1.0
    n = away * (side / dist) if dist > 1e-9 else left
    return side * dist - radius, p, centre - radius * n, n


def _nearer(a: np.ndarray, b: np.ndarray, b_to_a: Nearest, a_to_b: Nearest) -> Gap:
    """The nearer of b's corners to shape a (``b_to_a``: their signed distances, nearest points on a, normals
    from a) and a's corners to shape b (``a_to_b``, normals from b)."""
    sd_b, p_b, n_b = b_to_a
    sd_a, p_a, n_a = a_to_b
    i, j = int(np.argmin(sd_b)), int(np.argmin(sd_a))
    if sd_b[i] <= sd_a[j]:
        return float(sd_b[i]), p_b[i], b[i], n_b[i]
    return float(sd_a[j]), a[j], p_a[j], -n_a[j]


def polyline_polygon(line: np.ndarray, poly: np.ndarray) -> Gap:
    """A link's outline against a convex polygon: the nearer of the polygon's corners to the outline and the
    outline's corners to the polygon."""
    return _nearer(line, poly, to_polyline(poly, line), to_polygon(line, poly))


def polygon_circle(poly: np.ndarray, centre: np.ndarray, radius: float) -> Gap:
    """A convex polygon against a circle; the normal from the polygon to the circle."""
    sd, p, n = to_polygon(centre[None, :], poly)
    return float(sd[0]) - radius, p[0], centre - radius * n[0], n[0]


def polygons(a: np.ndarray, b: np.ndarray) -> Gap:
    """Two convex polygons: the nearer of b's corners to a and a's corners to b."""
    return _nearer(a, b, to_polygon(b, a), to_polygon(a, b))


def circles(ca: np.ndarray, ra: float, cb: np.ndarray, rb: float) -> Gap:
    """Two circles; the normal from a's centre to b's."""
    n = _unit(cb - ca, np.array([1.0, 0.0]))
    return float(np.hypot(*(cb - ca))) - ra - rb, ca + ra * n, cb - rb * n, n
