"""Mesh helpers for the CAD tests: load bodies, manifold3d conversions, rigid rotations."""

import math

import manifold3d as m3
import numpy as np
import trimesh


def load_bodies(path) -> list[trimesh.Trimesh]:
    """Connected bodies of a mesh file, largest first."""
    mesh = trimesh.load(str(path), force="mesh", process=True)
    bodies = mesh.split(only_watertight=False)
    return sorted(bodies, key=lambda b: -abs(b.volume))


def manifold(mesh: trimesh.Trimesh) -> m3.Manifold:
    return m3.Manifold(m3.Mesh(vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
                               tri_verts=np.asarray(mesh.faces, dtype=np.uint32)))


def rotate_about(man: m3.Manifold, point, direction, angle_rad: float) -> m3.Manifold:
    """Rigid rotation of a Manifold about the axis (point, direction)."""
    R = trimesh.transformations.rotation_matrix(angle_rad, direction, point)
    return man.transform(R[:3, :4])


def sweep_collisions(ground: m3.Manifold, moving: m3.Manifold, point, direction, lo: float, hi: float,
                     step: float):
    """(angle, intersection volume, gap) for poses lo..hi every ≤ step rad."""
    n = max(1, math.ceil((hi - lo) / step))
    out = []
    for a in np.linspace(lo, hi, n + 1):
        mv = rotate_about(moving, point, direction, float(a))
        vol = (ground ^ mv).volume()
        out.append((float(a), vol, ground.min_gap(mv, 1.0)))
    return out
