"""A body's palmar outline in the flexion plane, measured on its mesh: for stations along x, the palm-most
(largest y) point of the body within a slab of heights z, then simplified to a short polyline.

The finger flexes about +z towards +y (the palm side), so an object in the flexion plane (a prism along z that
spans the slab: a cylinder, a box) first meets a link at its largest y for each x: the upper envelope of the
body's section by every plane z = const of the slab. Within the slab, that envelope at x = s is the largest y of
the body's section by the plane x = s, whose vertices are the mesh edges' crossings of that plane (or, where the
slab cuts the body, the crossings of the slab's faces). Pure numpy on vertices and faces [mm]."""

from __future__ import annotations

import numpy as np

#: Spacing of the stations where the envelope is evaluated [mm]
STATION_MM = 0.1
#: The simplified outline lies at most this far on the palm side of the measured envelope [mm] ...
TOL_OUT_MM = 0.1
#: ... and at most this far inside it (the solid protruding beyond the outline) [mm]
TOL_IN_MM = 0.03
#: Stations evaluated together (memory: edges × this many floats)
_CHUNK = 64


def _edges(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The mesh's unique edges, shape (m, 2, 3) [mm]."""
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    return vertices[np.unique(e, axis=0)]


def crossing_max_y(
    segments: np.ndarray, stations: np.ndarray, z_range: tuple[float, float] = (-np.inf, np.inf)
) -> np.ndarray:
    """For each station s, the largest y where a segment (rows (2, 2) x, y or (2, 3) x, y, z) meets the plane
    x = s at a height within ``z_range``: its point at x = s, or the higher end of a segment lying on that plane;
    NaN where none does [mm]."""
    x0, x1 = segments[:, 0, 0], segments[:, 1, 0]
    lo, hi, dx = np.minimum(x0, x1), np.maximum(x0, x1), x1 - x0
    flat = dx == 0
    top = np.where((segments[:, 0, 1] >= segments[:, 1, 1])[:, None], segments[:, 0], segments[:, 1])
    d = (segments[:, 1] - segments[:, 0]) / np.where(flat, 1.0, dx)[:, None]
    out = np.full(len(stations), -np.inf)
    for k in range(0, len(stations), _CHUNK):
        s = stations[k : k + _CHUNK, None]
        near = (lo <= s.max()) & (hi >= s.min())  # the segments that reach these stations
        if not near.any():
            continue
        seg, x0n, fl = segments[near], x0[near], flat[near]
        t = np.where(fl, 0.0, s - x0n)
        y = np.where(fl, top[near, 1], seg[:, 0, 1] + t * d[near, 1])
        hit = (lo[near] <= s) & (s <= hi[near])
        if segments.shape[2] == 3:
            z = np.where(fl, top[near, 2], seg[:, 0, 2] + t * d[near, 2])
            hit &= (z >= z_range[0]) & (z <= z_range[1])
        out[k : k + _CHUNK] = np.where(hit, y, -np.inf).max(axis=1, initial=-np.inf)
    return np.where(np.isfinite(out), out, np.nan)


def _slab_face_segments(vertices: np.ndarray, faces: np.ndarray, z: float) -> np.ndarray:
    """The body's section by the plane at height ``z``, as segments (m, 2, 2) in (x, y) [mm]."""
    tri = vertices[faces]
    d = tri[:, :, 2] - z
    pts = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        da, db = d[:, a], d[:, b]
        cross = (da * db < 0) | ((da == 0) & (db != 0))
        t = np.where(cross, da / np.where(da == db, 1.0, da - db), 0.0)
        p = tri[:, a, :2] + t[:, None] * (tri[:, b, :2] - tri[:, a, :2])
        pts.append((cross, p))
    segs = []
    for i in range(3):
        for j in range(i + 1, 3):
            both = pts[i][0] & pts[j][0]
            segs.append(np.stack([pts[i][1][both], pts[j][1][both]], axis=1))
    return np.concatenate(segs) if segs else np.zeros((0, 2, 2))


def palmar_envelope(
    vertices: np.ndarray, faces: np.ndarray, stations: np.ndarray, slab: tuple[float, float] | None = None
) -> np.ndarray:
    """The body's largest y at each x of ``stations`` within heights ``slab`` = (z_lo, z_hi) (default: the
    body's whole height); NaN where the body has no material there [mm]."""
    z_lo, z_hi = (float(vertices[:, 2].min()), float(vertices[:, 2].max())) if slab is None else slab
    e = _edges(vertices, faces)
    e = e[(e[:, :, 2].max(axis=1) >= z_lo) & (e[:, :, 2].min(axis=1) <= z_hi)]
    y = crossing_max_y(e, stations, (z_lo, z_hi))
    for z in (z_lo, z_hi):
        if vertices[:, 2].min() < z < vertices[:, 2].max():
            y = np.fmax(y, crossing_max_y(_slab_face_segments(vertices, faces, z), stations))
    return y


def simplify(points: np.ndarray, tol_out: float = TOL_OUT_MM, tol_in: float = TOL_IN_MM) -> np.ndarray:
    """A subset of ``points`` (ordered by x), first and last kept, such that every point dropped lies between
    ``tol_in`` above and ``tol_out`` below the chord that replaces it (in y, mm): greedy, longest chords first."""
    keep, i, n = [0], 0, len(points)
    while i < n - 1:
        j = i + 1
        while j + 1 < n:
            a, b = points[i], points[j + 1]
            mid = points[i + 1 : j + 1]
            chord = a[1] + (b[1] - a[1]) * (mid[:, 0] - a[0]) / (b[0] - a[0])
            gap = mid[:, 1] - chord
            if gap.max() > tol_in or gap.min() < -tol_out:
                break
            j += 1
        keep.append(j)
        i = j
    return points[keep]


def palmar_outline(
    vertices: np.ndarray,
    faces: np.ndarray,
    origin_x: float = 0.0,
    slab: tuple[float, float] | None = None,
    step: float = STATION_MM,
) -> np.ndarray:
    """The body's palmar outline (rows x, y; x strictly increasing) in a frame at x = ``origin_x`` [mm]: the
    envelope (``palmar_envelope``) at stations ``step`` apart and at the x of each vertex near it (so a corner
    is kept), simplified (``simplify``)."""
    z_lo, z_hi = (float(vertices[:, 2].min()), float(vertices[:, 2].max())) if slab is None else slab
    v = vertices[(vertices[:, 2] >= z_lo) & (vertices[:, 2] <= z_hi)]
    x_min, x_max = float(vertices[:, 0].min()), float(vertices[:, 0].max())
    grid = np.linspace(x_min, x_max, max(2, int(np.ceil((x_max - x_min) / step)) + 1))
    y = palmar_envelope(vertices, faces, grid, (z_lo, z_hi))
    ok = ~np.isnan(y)
    near = v[v[:, 1] > np.interp(v[:, 0], grid[ok], y[ok]) - 2 * step]
    stations = np.unique(np.concatenate([grid, near[:, 0]]))
    stations = stations[np.r_[True, np.diff(stations) > 1e-9]]
    y = palmar_envelope(vertices, faces, stations, (z_lo, z_hi))
    ok = ~np.isnan(y)
    pts = np.column_stack([stations[ok] - origin_x, y[ok]])
    return simplify(pts)


def outline_points(vertices: np.ndarray, faces: np.ndarray, origin_x: float = 0.0) -> list[list[float]]:
    """``palmar_outline`` over the body's whole height as the manifest writes it: [[x, y], ...] rounded to
    1e-4 mm, points that share a rounded x merged into the palm-most one (so x strictly increases)."""
    pts = np.round(palmar_outline(vertices, faces, origin_x), 4)
    out: list[list[float]] = []
    for x, y in pts.tolist():
        if out and x <= out[-1][0]:
            out[-1][1] = max(out[-1][1], y)
        else:
            out.append([x, y])
    return out
