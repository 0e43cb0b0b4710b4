"""Checks of the bodies at rest: closed, manifold, as many as expected, and far enough apart."""

from __future__ import annotations

import math

import manifold3d as m3
import numpy as np
import trimesh

from rjcad.check.copies import APART_MM, Copies, candidates, min_gap, refined, simplified
from rjcad.check.report import CheckResult, point


def to_manifold(mesh: trimesh.Trimesh) -> m3.Manifold:
    """manifold3d solid from a merged-vertex mesh, in double precision (Mesh64)."""
    return m3.Manifold(
        m3.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
        )
    )


def _edge_defects(mesh: trimesh.Trimesh) -> tuple[np.ndarray, bool]:
    """Undirected edges not shared by exactly two faces, and whether the winding is consistent.

    Fast path: closed and consistently wound ⟺ every directed edge a→b occurs once and b→a occurs
    too, i.e. sorted(a·N + b) == sorted(b·N + a) with no repeats.
    """
    F = np.asarray(mesh.faces, dtype=np.int64)
    n = len(mesh.vertices)
    a, b = F.ravel(), np.roll(F, -1, axis=1).ravel()
    fwd, rev = np.sort(a * n + b), np.sort(b * n + a)
    if np.array_equal(fwd, rev) and not np.any(fwd[1:] == fwd[:-1]):
        return np.empty((0, 2), dtype=np.int64), True
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keys, counts = np.unique(lo * n + hi, return_counts=True)
    bad = keys[counts != 2]
    return np.stack([bad // n, bad % n], axis=1), bool(mesh.is_winding_consistent)


def _inside_out(mesh: trimesh.Trimesh) -> bool:
    """Whether a closed, consistently wound mesh faces inwards: at its vertex of largest x, the faces around it
    enclose a cone of the solid on the side x ≤ x_max, so their outward area vectors sum to a positive x
    component (divergence theorem on that cone); negative means inside out. O(faces), no mass properties."""
    V = np.asarray(mesh.vertices, dtype=np.float64)
    F = np.asarray(mesh.faces, dtype=np.int64)
    k = int(np.argmax(V[:, 0]))
    around = F[(F == k).any(axis=1)]
    v0 = V[around[:, 0]]
    return float(np.cross(V[around[:, 1]] - v0, V[around[:, 2]] - v0)[:, 0].sum()) < 0.0


def _misdirected_edge(mesh: trimesh.Trimesh) -> np.ndarray | None:
    """Midpoint of a directed edge a→b that two faces both use (where the winding flips), or None."""
    F = np.asarray(mesh.faces, dtype=np.int64)
    n = len(mesh.vertices)
    a, b = F.ravel(), np.roll(F, -1, axis=1).ravel()
    keys, counts = np.unique(a * n + b, return_counts=True)
    twice = keys[counts > 1]
    if not len(twice):
        return None
    return mesh.vertices[[twice[0] // n, twice[0] % n]].mean(axis=0)


def check_watertight(bodies, names) -> CheckResult:
    """Every edge shared by exactly two faces, winding consistent, normals outwards (positive volume)."""
    bad = []
    for b, n in zip(bodies, names):
        open_edges, wound = _edge_defects(b)
        inside_out = not len(open_edges) and wound and _inside_out(b)
        if len(open_edges) or not wound or inside_out:
            if len(open_edges):
                where = b.vertices[open_edges[0]].mean(axis=0)
            else:
                flip = None if wound else _misdirected_edge(b)
                where = flip if flip is not None else b.vertices[b.faces[0]].mean(axis=0)
            bad.append((n, len(open_edges), wound, inside_out, where))
    if not bad:
        return CheckResult(
            "watertight", True, 0, 0, None, f"{len(bodies)} bodies closed, consistently wound, facing outwards"
        )
    n, k, wind, inside_out, where = bad[0]
    what = (
        f"{n}: inside out (closed and consistently wound, but its normals point inwards: volume < 0)"
        if inside_out
        else f"{n}: {k} edges not shared by exactly two faces" + ("" if wind else ", winding inconsistent")
    )
    return CheckResult(
        "watertight", False, k, 0, point(where), what + (f"; {len(bad)} bodies affected" if len(bad) > 1 else "")
    )


def check_manifold(bodies, names) -> tuple[CheckResult, list[m3.Manifold]]:
    """manifold3d accepts every body (status NoError) with a positive volume; genus reported."""
    mans, bad, genus = [], [], []
    for b, n in zip(bodies, names):
        man = to_manifold(b)
        mans.append(man)
        st = man.status()
        if st != m3.Error.NoError or man.is_empty() or man.volume() <= 0:
            bad.append((n, st.name, b.centroid))
        else:
            genus.append(f"{n} genus {man.genus()}")
    if bad:
        n, st, where = bad[0]
        return CheckResult("manifold", False, st, "NoError", point(where), f"{n}: manifold3d says {st}"), mans
    return CheckResult("manifold", True, "NoError", "NoError", None, "; ".join(genus)), mans


def check_bodies(bodies, expected: int | None) -> CheckResult:
    if expected is None:
        return CheckResult("bodies", None, len(bodies), None, None, "skipped: no manifest and no --bodies")
    return CheckResult(
        "bodies",
        len(bodies) == expected,
        len(bodies),
        expected,
        None,
        f"{len(bodies)} separate bodies, {expected} expected",
    )


def _closest_points(a: trimesh.Trimesh, b: trimesh.Trimesh, gap: float) -> np.ndarray:
    """Midpoint of the nearest vertex pair of two meshes (a location for a gap ``gap`` apart). The search radius
    starts just above the gap and doubles: an unbounded nearest-neighbour query from every vertex is slow where
    many vertices lie almost equally far (a pin's vertices from its bore's)."""
    from scipy.spatial import cKDTree

    tree, r = cKDTree(b.vertices), max(gap, 0.0) + 0.1
    while True:
        d, i = tree.query(a.vertices, distance_upper_bound=r)
        if np.isfinite(d).any():
            break
        r *= 2
    k = int(np.argmin(d))
    return (a.vertices[k] + b.vertices[i[k]]) / 2


def _deepest(verts: np.ndarray, a: trimesh.Trimesh, b: trimesh.Trimesh) -> np.ndarray:
    """Where two bodies overlap: of the overlap's vertices that are a body's own vertices (inside the other), the
    one farthest inside the other body; else the overlap's mean vertex."""
    from scipy.spatial import cKDTree

    best, depth = verts.mean(axis=0), -1.0
    for own, other in ((a, b), (b, a)):
        d, _ = cKDTree(own.vertices).query(verts, distance_upper_bound=1e-6)
        inside = verts[np.isfinite(d)]
        if len(inside):
            _, dist, _ = trimesh.proximity.closest_point(other, inside)
            k = int(np.argmax(dist))
            if dist[k] > depth:
                best, depth = inside[k], float(dist[k])
    return best


def _pairs(bodies, search: float):
    """Pairs (i, j) of bodies whose boxes lie within ``search`` of each other."""
    for i in range(len(bodies)):
        for j in range(i + 1, len(bodies)):
            lo = np.maximum(bodies[i].bounds[0], bodies[j].bounds[0])
            hi = np.minimum(bodies[i].bounds[1], bodies[j].bounds[1])
            if not np.any(lo - hi > search):
                yield i, j


def check_clearance(
    bodies, names, mans, clearance: float, allowance: float, copies: Copies | None = None
) -> CheckResult:
    """Every pair of bodies: min gap ≥ clearance − allowance and no overlap.

    Each pair is screened on the coarse copies (``rjcad.check.copies``); pairs that come near are intersected
    on the bodies, and the tightest pairs' gaps measured on the fine copies (within 2·FINE_TOL_MM of the bodies').
    """
    limit = clearance - allowance
    if len(bodies) < 2:
        return CheckResult("clearance", None, None, limit, None, "skipped: a single body")
    copies = simplified(mans) if copies is None else copies
    search = clearance + 1.0
    overlap, pairs, coarse = None, [], []
    for i, j in _pairs(bodies, search):
        g = min_gap(copies.coarse[i], copies.coarse[j], search)
        if g < APART_MM:
            inter = mans[i] ^ mans[j]
            vol = inter.volume()
            if vol > 1e-6 and (overlap is None or vol > overlap[0]):
                verts = np.asarray(inter.to_mesh64().vert_properties)[:, :3]
                overlap = (vol, (i, j), _deepest(verts, bodies[i], bodies[j]))
        pairs.append((i, j))
        coarse.append(g)
    if overlap is not None:
        vol, (i, j), where = overlap
        return CheckResult(
            "clearance", False, 0.0, limit, point(where), f"{names[i]} and {names[j]} overlap by {vol:.3f} mm³"
        )
    tight: tuple[float, tuple[int, int] | None] = (math.inf, None)
    for k in candidates(coarse) if coarse else []:
        i, j = pairs[k]
        gap = refined(coarse[k], copies.fine[i], copies.fine[j], search, copies.same((i, j)))
        if gap < tight[0]:
            tight = (gap, (i, j))
    gap, pair = tight
    if pair is None:
        return CheckResult("clearance", True, search, limit, None, f"no two bodies within {search:.2f} mm")
    i, j = pair
    where = _closest_points(bodies[i], bodies[j], gap)
    return CheckResult(
        "clearance",
        bool(gap >= limit),
        round(float(gap), 4),
        round(limit, 4),
        point(where),
        f"tightest pair {names[i]}–{names[j]}: {gap:.3f} mm (allowance {allowance} mm for tessellation)",
    )
