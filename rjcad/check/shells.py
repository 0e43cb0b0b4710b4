"""Coaxial shells of a group that turns about an axis, and what the rotation cannot change.

A rotation about an axis keeps each point's radius r and its axial coordinate z, and moves it by at most r·Δθ.
The map to (r, z) shortens no distance, so the (r, z) distance between two parts bounds their distance at every
angle. A shell keeps only the turning group's points whose (r, z) comes within a margin of the still group's,
and the still group's points it may meet; the rest stays farther than the margin whatever the angle. Each shell
has its own lever (its largest radius): where it is g apart, it cannot come nearer than g − lever·Δθ within Δθ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import manifold3d as m3
import numpy as np

#: Outer radius of the innermost shell [mm], and each shell's outer / inner radius.
CORE_MM, SHELL_RATIO = 2.0, 1.6
#: Cell of the (r, z) shadows [mm].
CELL_MM = 0.05
#: A slanted triangle is halved, at most SPLITS times, while its (r, z) box is wider than WIDE_MM both ways [mm].
SPLITS, WIDE_MM = 8, 0.2
#: Overlap of neighbouring shells [mm]: more than half the CELL_MM a cut's polygon may lie inside its circle, so
#: that no sliver of the group falls between two cuts.
OVERLAP_MM = CELL_MM


@dataclass(frozen=True)
class Shell:
    """Part of a turning group between two radii and the part of the still group it may meet (world frame);
    lever: its largest radius [mm]."""

    turning: m3.Manifold
    still: m3.Manifold
    lever: float


def axis_frame(point, direction) -> np.ndarray:
    """3×4 rigid transform taking the axis (point, unit direction) to the z axis through the origin."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    x = np.cross(np.eye(3)[int(np.argmin(np.abs(d)))], d)
    x /= np.linalg.norm(x)
    rot = np.vstack([x, np.cross(d, x), d])
    return np.hstack([rot, (-rot @ np.asarray(point, dtype=float))[:, None]])


def _inverse(t: np.ndarray) -> np.ndarray:
    rot = t[:, :3].T
    return np.hstack([rot, (-rot @ t[:, 3])[:, None]])


def _segment_radius(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from the origin to each 2-D segment a–b."""
    ab = b - a
    t = np.clip(-np.einsum("ij,ij->i", a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
    return np.hypot(*(a + t[:, None] * ab).T)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def _boxes(tri: np.ndarray) -> np.ndarray:
    """Each triangle's (r_min, r_max, z_min, z_max) about the z axis [mm]: r_min is the distance from the origin to
    the triangle's plan (0 when the plan holds the origin); r_max and the z bounds are at its corners."""
    p = [tri[:, i, :2] for i in range(3)]
    side = np.array([_cross(p[(i + 1) % 3] - p[i], -p[i]) for i in range(3)])  # the origin's side of each edge
    holds = np.all(side >= 0, axis=0) | np.all(side <= 0, axis=0)
    r_min = np.where(holds, 0.0, np.minimum.reduce([_segment_radius(p[i], p[(i + 1) % 3]) for i in range(3)]))
    z = tri[:, :, 2]
    return np.column_stack([r_min, np.hypot(tri[:, :, 0], tri[:, :, 1]).max(axis=1), z.min(axis=1), z.max(axis=1)])


def _triangles(m: m3.Manifold) -> np.ndarray:
    mesh = m.to_mesh64()
    return np.asarray(mesh.vert_properties)[:, :3][np.asarray(mesh.tri_verts)]


def rz_boxes(m: m3.Manifold, r_max: float = math.inf) -> np.ndarray:
    """(r, z) boxes that hold the surface's image. A triangle whose image is thin but whose box is not (a slanted
    face: a cone's, a chamfer's; its box over WIDE_MM both ways, its corners' images spanning under a quarter of
    it) is halved across its longest edge, up to SPLITS times; a face whose image fills its box (a wall along the
    axis) is kept whole. Only triangles that come within ``r_max`` [mm] of the axis."""
    tri = _triangles(m)
    tri = tri[_boxes(tri)[:, 0] <= r_max]
    done = [np.zeros((0, 4))]
    for _ in range(SPLITS):
        boxes = _boxes(tri)
        r, z = np.hypot(tri[:, :, 0], tri[:, :, 1]), tri[:, :, 2]
        image = 0.5 * np.abs((r[:, 1] - r[:, 0]) * (z[:, 2] - z[:, 0]) - (r[:, 2] - r[:, 0]) * (z[:, 1] - z[:, 0]))
        area = (boxes[:, 1] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 2])
        wide = np.minimum(boxes[:, 1] - boxes[:, 0], boxes[:, 3] - boxes[:, 2]) > WIDE_MM
        thin = wide & (image < 0.25 * area)
        done.append(boxes[~thin])
        if not thin.any():
            break
        tri = _halved(tri[thin])
    else:
        done.append(_boxes(tri))
    return np.concatenate(done)


def _halved(tri: np.ndarray) -> np.ndarray:
    """Each triangle cut in two from the midpoint of its longest edge to the opposite corner."""
    edge = np.linalg.norm(tri - np.roll(tri, -1, axis=1), axis=2)  # edge k: corner k to corner k+1
    k = np.argmax(edge, axis=1)
    a, b, c = (tri[np.arange(len(tri)), (k + i) % 3] for i in range(3))
    mid = (a + b) / 2
    return np.concatenate([np.stack([a, mid, c], axis=1), np.stack([mid, b, c], axis=1)])


def shadow(boxes: np.ndarray, margin: float) -> m3.CrossSection:
    """The (r, z) region within ``margin`` [mm] of these boxes, grown by at least CELL_MM more and simplified:
    the cells the boxes cover, grown by the margin, their runs along z as rectangles, offset and simplified."""
    grow = math.ceil(margin / CELL_MM)
    r0, z0 = 0.0, float(boxes[:, 2].min()) - (grow + 1) * CELL_MM
    n, m = _cell(boxes[:, 1].max(), r0) + grow + 3, _cell(boxes[:, 3].max(), z0) + grow + 3
    i0, i1 = np.maximum(_cell(boxes[:, 0], r0) - grow, 0), _cell(boxes[:, 1], r0) + grow + 1
    j0, j1 = _cell(boxes[:, 2], z0) - grow, _cell(boxes[:, 3], z0) + grow + 1
    diff = np.zeros((n + 1, m + 1), np.int64)
    for i, j, s in ((i0, j0, 1), (i0, j1, -1), (i1, j0, -1), (i1, j1, 1)):
        np.add.at(diff, (i, j), s)
    covered = diff.cumsum(axis=0).cumsum(axis=1)[:n, :m] > 0
    edges = np.diff(np.pad(covered, ((0, 0), (1, 1))).astype(np.int8), axis=1)
    rects = []
    for i in np.flatnonzero(edges.any(axis=1)):
        for j_lo, j_hi in zip(np.flatnonzero(edges[i] == 1), np.flatnonzero(edges[i] == -1)):
            a, b, c, d = r0 + i * CELL_MM, r0 + (i + 1) * CELL_MM, z0 + j_lo * CELL_MM, z0 + j_hi * CELL_MM
            rects.append(np.array([[a, c], [b, c], [b, d], [a, d]]))
    return m3.CrossSection(rects).offset(2 * CELL_MM, m3.JoinType.Miter).simplify(CELL_MM)


def _cell(x, origin: float):
    return np.floor((np.asarray(x) - origin) / CELL_MM).astype(np.int64)


def _band(region: m3.CrossSection, r_lo: float, r_hi: float) -> m3.CrossSection:
    lo, hi = region.bounds()[1] - 1.0, region.bounds()[3] + 1.0
    return region ^ m3.CrossSection.square((r_hi - r_lo, hi - lo)).translate((r_lo, lo))


def _solid(region: m3.CrossSection) -> m3.Manifold:
    """The solid the (r, z) region sweeps about the z axis, as polygons that hold the region's points less
    CELL_MM: a polygon of n sides lies within r·(1/cos(π/n) − 1) ≤ CELL_MM of its circle."""
    r_hi = max(region.bounds()[2], CELL_MM)
    segments = max(8, math.ceil(math.pi / math.acos(1.0 / (1.0 + CELL_MM / r_hi))))
    return m3.Manifold.revolve(region, circular_segments=segments)


def shells(turning: m3.Manifold, still: m3.Manifold, point, direction, margin: float, reach: float) -> list[Shell]:
    """The turning group's points whose (r, z) lies within ``margin`` [mm] of the still group's, cut into coaxial
    shells (outer radii CORE_MM·SHELL_RATIO^k); each with the still group's points within margin + lever·``reach``
    [rad] of its (r, z) extent. Whatever the angle, the rest of the turning group stays farther than ``margin``
    from the still group, and the rest of the still group farther than margin + lever·reach from the shell."""
    to_axis = axis_frame(point, direction)
    local, fixed = turning.transform(to_axis), still.transform(to_axis)
    r_max = float(np.hypot(*np.asarray(local.to_mesh64().vert_properties)[:, :2].T).max())
    still_boxes = rz_boxes(fixed, r_max + margin)
    if not len(still_boxes):  # the still group lies beyond the turning group's reach
        return []
    near_still = shadow(still_boxes, margin)
    radii = [CORE_MM]
    while radii[-1] < r_max:
        radii.append(radii[-1] * SHELL_RATIO)
    back = _inverse(to_axis)
    out = []
    for inner, outer in zip([0.0, *radii[:-1]], radii):
        band = _band(near_still, max(inner - OVERLAP_MM, 0.0), outer + OVERLAP_MM)
        part = m3.Manifold() if band.is_empty() else local ^ _solid(band)
        if part.is_empty():
            continue
        boxes = _boxes(_triangles(part))  # its lever and extent: the corners' radii and heights
        lever = float(boxes[:, 1].max())
        near = fixed ^ _tube(boxes, margin + lever * reach)
        if not near.is_empty():
            out.append(Shell(part.transform(back), near.transform(back), lever))
    return out


def _tube(boxes: np.ndarray, margin: float) -> m3.Manifold:
    """The solid of revolution holding these (r, z) boxes grown by ``margin`` [mm] (and CELL_MM for its polygons)."""
    grow = margin + CELL_MM
    r_lo, r_hi = max(float(boxes[:, 0].min()) - grow, 0.0), float(boxes[:, 1].max()) + grow
    z_lo, z_hi = float(boxes[:, 2].min()) - grow, float(boxes[:, 3].max()) + grow
    return _solid(m3.CrossSection.square((r_hi - r_lo, z_hi - z_lo)).translate((r_lo, z_lo)))


def facing(
    turning: m3.Manifold, still: m3.Manifold, point, direction, margin: float
) -> tuple[m3.Manifold, m3.Manifold]:
    """Each group cut to the solid of revolution holding the other's (r, z) box grown by ``margin`` [mm]: at every
    angle, what is cut off lies farther than ``margin`` from the other group, so gaps up to it are unchanged."""
    to_axis = axis_frame(point, direction)
    local, fixed = turning.transform(to_axis), still.transform(to_axis)
    near_turning = local ^ _tube(_boxes(_triangles(fixed)), margin)
    near_still = fixed ^ _tube(_boxes(_triangles(local)), margin)
    back = _inverse(to_axis)
    return near_turning.transform(back), near_still.transform(back)
