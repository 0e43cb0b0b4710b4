"""The B-rep side of the exports: tessellation, measurements on the built geometry, STEP; the mesh side (STL,
3MF, GLB, PNG, the atomic write) is ``rjcad.cad.mesh_export``."""

from __future__ import annotations

import itertools
import math
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import cadquery as cq
import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopLoc import TopLoc_Location

from rjcad.cad.mesh_export import MESH_ANGULAR_TOLERANCE, MESH_TOLERANCE, mesh_of

if TYPE_CHECKING:
    import trimesh


def triangulate(
    shape: cq.Shape, tolerance: float = MESH_TOLERANCE, angular_tolerance: float = MESH_ANGULAR_TOLERANCE
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) [mm] and triangles (F, 3) of a shape's faces, unmerged: the arrays CadQuery's
    ``Shape.tessellate`` gives (same meshing, face order and winding). The faces are meshed in parallel
    (OCCT meshes each face on its own once the edges are shared: the same triangles as one thread) and each
    node is read as one coordinate tuple (a third of the time of a Vector per node)."""
    if not BRepTools.Triangulation_s(shape.wrapped, tolerance):
        # CadQuery's Shape.mesh, with OCCT's parallel flag: (shape, deflection, relative, angle, parallel)
        BRepMesh_IncrementalMesh(shape.wrapped, tolerance, True, angular_tolerance, True)
    verts, tris, offset = [np.zeros((0, 3))], [np.zeros((0, 3), dtype=np.int64)], 0
    for face in shape.Faces():
        loc = TopLoc_Location()
        poly = BRep_Tool.Triangulation_s(face.wrapped, loc)
        if poly is None:
            continue
        n, node = poly.NbNodes(), poly.Node
        if loc.IsIdentity():
            v = [node(i).Coord() for i in range(1, n + 1)]
        else:
            trsf = loc.Transformation()
            v = [node(i).Transformed(trsf).Coord() for i in range(1, n + 1)]
        verts.append(np.array(v, dtype=float).reshape(-1, 3))
        t = np.array([tri.Get() for tri in poly.Triangles()], dtype=np.int64).reshape(-1, 3)
        if face.wrapped.Orientation() == TopAbs_Orientation.TopAbs_REVERSED:
            t = t[:, [0, 2, 1]]
        tris.append(t + (offset - 1))  # OCCT numbers nodes from 1
        offset += n
    return np.concatenate(verts), np.concatenate(tris)


def to_mesh(
    shape: cq.Shape, tolerance: float = MESH_TOLERANCE, angular_tolerance: float = MESH_ANGULAR_TOLERANCE
) -> trimesh.Trimesh:
    """Tessellate a solid into a trimesh with merged vertices (watertight when the B-rep is)."""
    return mesh_of(*triangulate(shape, tolerance, angular_tolerance))


def segment_inside(shape: cq.Shape, start, end) -> list[tuple[float, float]]:
    """Parameter ranges [mm from ``start``] where the segment start→end lies inside ``shape``."""
    a, b = cq.Vector(*start), cq.Vector(*end)
    common = shape.intersect(cq.Edge.makeLine(a, b))
    spans = []
    for e in common.Edges():
        s = sorted(((e.startPoint() - a).Length, (e.endPoint() - a).Length))
        spans.append((s[0], s[1]))
    return sorted(spans)


def measure_moment_arm(
    moving: cq.Shape, z_mid: float, line_diameter: float, axis_point=(0.0, 0.0, 0.0), direction=(0.0, 1.0, 0.0)
) -> float:
    """Tendon moment arm: radius where a ray from the axis leaves the eye (groove bottom) + line radius [mm]."""
    o = cq.Vector(axis_point[0], axis_point[1], z_mid)
    d = cq.Vector(*direction).normalized()
    spans = segment_inside(moving, o, o + d * 50.0)
    if not spans:
        raise RuntimeError("moment arm: the ray from the axis does not cross the eye")
    return spans[0][1] + line_diameter / 2


def channel_axes(shape: cq.Shape, radius: float, tol: float = 1e-4) -> list[tuple[np.ndarray, np.ndarray]]:
    """Axes (point, unit direction) of the cylindrical faces of ``radius``: the channel's straight runs."""
    axes: list[tuple[np.ndarray, np.ndarray]] = []
    for f in shape.Faces():
        if f.geomType() != "CYLINDER":
            continue
        cyl = BRepAdaptor_Surface(f.wrapped).Cylinder()
        if abs(cyl.Radius() - radius) > tol:
            continue
        ax = cyl.Axis()
        d = np.array([ax.Direction().X(), ax.Direction().Y(), ax.Direction().Z()])
        c = np.array(f.Center().toTuple())
        if any(
            abs(abs(float(np.dot(d, d2))) - 1.0) < 1e-9 and np.linalg.norm(np.cross(c - p2, d2)) < radius * 2
            for p2, d2 in axes
        ):
            continue  # the same run, split into several faces
        axes.append((c, d))
    return axes


def measure_wrap_angle(shape: cq.Shape, radius: float, along=(1.0, 0.0, 0.0)) -> float:
    """Total turning of the tendon channel: Σ angles between consecutive straight runs [rad].

    Runs are ordered by their centre's position ``along`` the link.
    """
    axes = channel_axes(shape, radius)
    if not axes:
        raise RuntimeError(f"wrap angle: no channel of radius {radius} mm in the body")
    u = np.asarray(along, dtype=float)
    axes.sort(key=lambda pd: float(np.dot(pd[0], u)))
    total = 0.0
    for (_, d1), (_, d2) in itertools.pairwise(axes):
        total += math.acos(min(1.0, abs(float(np.dot(d1, d2)))))
    return total


def step_bytes(solids: dict[str, cq.Shape], name: str) -> bytes:
    """A STEP file whose solids carry the given names (through an Assembly)."""
    assy = cq.Assembly(name=name)
    for n, s in solids.items():
        assy.add(s, name=n)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, f"{name}.step")
        assy.export(path, exportType="STEP")
        return Path(path).read_bytes()
