"""Independent checks of built bodies for the property tests: nothing here comes from rjcad.check.

The STL the builder writes is read back by trimesh and split into connected bodies; each must be watertight, wound
consistently with outward normals (positive volume) and match a body of the manifest. Gaps are measured twice, by
two algorithms: manifold3d's exact triangle-to-triangle distance (the solids built here from the raw arrays), and a
vertex-to-triangle distance from trimesh's triangle tree (an upper bound of the true gap, so it must pass too).
"""

from __future__ import annotations

import io
import itertools

import manifold3d as m3
import numpy as np
import trimesh

#: How far below the clearance a measured gap may fall: the tessellation's chords cut into convex faces [mm].
GAP_ALLOWANCE = 0.02


def solid(mesh: trimesh.Trimesh) -> m3.Manifold:
    """manifold3d solid of a merged-vertex mesh, double precision; it must be a valid manifold."""
    man = m3.Manifold(
        m3.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
        )
    )
    assert man.status() == m3.Error.NoError, man.status()
    return man


def named_bodies(stl: bytes, meshes: dict[str, trimesh.Trimesh], volumes: dict[str, float]) -> dict:
    """The STL's connected bodies, each named after the built mesh whose bounding box it shares.

    Asserts: as many bodies as the manifest names, each watertight, consistently wound, outward (positive
    volume), and within 0.5 % of its manifest volume (the B-rep's)."""
    whole = trimesh.load(io.BytesIO(stl), file_type="stl", process=True)
    bodies = whole.split(only_watertight=False)
    assert len(bodies) == len(volumes) == len(meshes), (len(bodies), sorted(volumes))
    out = {}
    for body in bodies:
        centre = body.bounds.mean(axis=0)
        name = min(meshes, key=lambda n: np.linalg.norm(meshes[n].bounds.mean(axis=0) - centre))
        assert name not in out, f"two bodies match {name}"
        assert body.is_watertight and body.is_winding_consistent, name
        assert body.volume > 0, (name, body.volume)  # outward normals
        assert abs(body.volume / volumes[name] - 1) < 0.005, (name, body.volume, volumes[name])
        out[name] = body
    return out


def vertex_face_gap(a: trimesh.Trimesh, b: trimesh.Trimesh, reach: float) -> float:
    """Smallest distance from a vertex of ``a`` to the surface of ``b``, looked for within ``reach`` (``reach`` if
    nothing is nearer) [mm]. It does not see a vertex inside ``b``: :func:`check_gaps` rules out overlaps first."""
    lo, hi = a.vertices - reach, a.vertices + reach
    idx = np.flatnonzero(np.all((hi > b.bounds[0]) & (lo < b.bounds[1]), axis=1))
    if not len(idx):
        return reach
    # every triangle whose box meets each vertex's box, all vertices in one query (5-10x a query per vertex)
    tri, counts = b.triangles_tree.intersection_v(lo[idx], hi[idx])
    if not len(tri):
        return reach
    pts = a.vertices[np.repeat(idx, counts.astype(np.int64))]
    near = trimesh.triangles.closest_point(b.triangles[tri.astype(np.int64)], pts)
    return min(reach, float(np.linalg.norm(near - pts, axis=1).min()))


def check_gaps(bodies: dict, clearance: float, neighbours) -> dict:
    """Gaps between every pair of bodies: no overlap, each ≥ clearance − 0.02 mm by both measures; each pair in
    ``neighbours`` (a joint's parent and child) also comes within clearance + 0.05 mm somewhere, so the
    clearance is the one built. Returns {pair: exact gap} [mm]."""
    names = list(bodies)
    mans = {n: solid(bodies[n]) for n in names}
    reach = clearance + 0.1
    gaps = {}
    for a, b in itertools.combinations(names, 2):
        assert (mans[a] ^ mans[b]).volume() < 1e-9, (a, b, "overlap")
        exact = mans[a].min_gap(mans[b], reach)
        by_vertex = min(vertex_face_gap(bodies[a], bodies[b], reach), vertex_face_gap(bodies[b], bodies[a], reach))
        assert exact >= clearance - GAP_ALLOWANCE, (a, b, exact, clearance)
        assert by_vertex >= clearance - GAP_ALLOWANCE, (a, b, by_vertex, clearance)
        assert by_vertex >= exact - 1e-6, (a, b, by_vertex, exact)  # an upper bound of the exact gap
        gaps[(a, b)] = exact
    for a, b in neighbours:
        g = gaps[(a, b)] if (a, b) in gaps else gaps[(b, a)]
        assert g <= clearance + 0.05, (a, b, g, clearance)
    return gaps


def overlap_free_sweep(fixed: m3.Manifold, moving: m3.Manifold, point, direction, angle: float, step: float) -> int:
    """Turn ``moving`` about the axis (point, direction) from 0 to ``angle`` in steps ≤ ``step`` [rad]; asserts it
    never overlaps ``fixed``. Returns the number of poses."""
    n = max(1, int(np.ceil(angle / step)))
    for a in np.linspace(0.0, angle, n + 1):
        R = trimesh.transformations.rotation_matrix(float(a), direction, point)
        vol = (fixed ^ moving.transform(R[:3, :4])).volume()
        assert vol < 1e-9, (np.degrees(a), vol)
    return n + 1
