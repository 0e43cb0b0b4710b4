"""Mesh conversions shared by the builders, the checks and the tests (no CAD imports)."""

from __future__ import annotations

import manifold3d as m3
import numpy as np
import trimesh


def to_manifold(mesh: trimesh.Trimesh) -> m3.Manifold:
    """manifold3d solid from a merged-vertex mesh, in double precision (Mesh64)."""
    return m3.Manifold(m3.Mesh64(vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
                                 tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64)))
