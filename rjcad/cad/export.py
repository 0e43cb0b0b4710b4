"""The B-rep side of the exports: tessellation, measurements on the built geometry, STEP; the mesh side (STL,
3MF, GLB, PNG, the atomic write) is ``rjcad.cad.mesh_export``."""

from __future__ import annotations

import itertools
import math
import os
import re
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from OCP.BinXCAFDrivers import BinXCAFDrivers
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_StepModelType
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDataStd import TDataStd_Name
from OCP.TDF import TDF_Label
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS_Builder, TopoDS_Compound
from OCP.XCAFApp import XCAFApp_Application
from OCP.XCAFDoc import XCAFDoc_DocumentTool
from OCP.XSControl import XSControl_WorkSession

from rjcad.cad import occ
from rjcad.cad.mesh_export import MESH_ANGULAR_TOLERANCE, MESH_TOLERANCE, mesh_of
from rjcad.cad.occ import Shape, Vec
from rjcad.io.outputs import TemporaryWriteError

if TYPE_CHECKING:
    import trimesh


def triangulate(
    shape: Shape, tolerance: float = MESH_TOLERANCE, angular_tolerance: float = MESH_ANGULAR_TOLERANCE
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) [mm] and triangles (F, 3) of a shape's faces, unmerged, in ``occ.faces`` order, each
    face's triangles wound outwards (flipped on a reversed face). The shape is meshed once (OCCT's incremental
    mesher: ``tolerance`` [mm] relative to each edge's size, ``angular_tolerance`` [rad]) with its faces in
    parallel (OCCT meshes each face on its own once the edges are shared: the same triangles as one thread).
    Nodes and triangles are read by index, each node as one coordinate tuple (iterating OCCT's arrays from
    Python is four times slower)."""
    if not BRepTools.Triangulation_s(shape, tolerance):
        # (shape, deflection, relative, angle, parallel)
        BRepMesh_IncrementalMesh(shape, tolerance, True, angular_tolerance, True)
    coords: list[tuple[float, float, float]] = []
    tris = [np.zeros((0, 3), dtype=np.int64)]
    for face in occ.faces(shape):
        loc = TopLoc_Location()
        poly = BRep_Tool.Triangulation_s(face, loc)
        if poly is None:
            continue
        offset, n, node, tri = len(coords), poly.NbNodes(), poly.Node, poly.Triangle
        if loc.IsIdentity():
            coords += [node(i).Coord() for i in range(1, n + 1)]
        else:
            trsf = loc.Transformation()
            coords += [node(i).Transformed(trsf).Coord() for i in range(1, n + 1)]
        t = np.array([tri(i).Get() for i in range(1, poly.NbTriangles() + 1)], dtype=np.int64).reshape(-1, 3)
        if face.Orientation() == TopAbs_Orientation.TopAbs_REVERSED:
            t = t[:, [0, 2, 1]]
        tris.append(t + (offset - 1))  # OCCT numbers nodes from 1
    return np.array(coords, dtype=float).reshape(-1, 3), np.concatenate(tris)


def to_mesh(
    shape: Shape, tolerance: float = MESH_TOLERANCE, angular_tolerance: float = MESH_ANGULAR_TOLERANCE
) -> trimesh.Trimesh:
    """Tessellate a solid into a trimesh with merged vertices (watertight when the B-rep is)."""
    return mesh_of(*triangulate(shape, tolerance, angular_tolerance))


def segment_inside(shape: Shape, start, end) -> list[tuple[float, float]]:
    """Parameter ranges [mm from ``start``] where the segment start→end lies inside ``shape``."""
    a, b = Vec(*start), Vec(*end)
    spans = []
    for e in occ.edges(occ.common(shape, occ.line(a, b))):
        first, last = occ.edge_ends(e)
        s = sorted(((first - a).length, (last - a).length))
        spans.append((s[0], s[1]))
    return sorted(spans)


def measure_moment_arm(
    moving: Shape, z_mid: float, line_diameter: float, axis_point=(0.0, 0.0, 0.0), direction=(0.0, 1.0, 0.0)
) -> float:
    """Tendon moment arm: radius where a ray from the axis leaves the eye (groove bottom) + line radius [mm]."""
    o = Vec(axis_point[0], axis_point[1], z_mid)
    d = Vec(*direction).unit()
    spans = segment_inside(moving, o, o + d * 50.0)
    if not spans:
        raise RuntimeError("moment arm: the ray from the axis does not cross the eye")
    return spans[0][1] + line_diameter / 2


def channel_axes(shape: Shape, radius: float, tol: float = 1e-4) -> list[tuple[np.ndarray, np.ndarray]]:
    """Axes (point, unit direction) of the cylindrical faces of ``radius``: the channel's straight runs."""
    axes: list[tuple[np.ndarray, np.ndarray]] = []
    for f in occ.faces(shape):
        if not occ.is_cylinder(f):
            continue
        cyl = BRepAdaptor_Surface(f).Cylinder()
        if abs(cyl.Radius() - radius) > tol:
            continue
        ax = cyl.Axis()
        d = np.array([ax.Direction().X(), ax.Direction().Y(), ax.Direction().Z()])
        c = np.array(tuple(occ.area_centre(f)))
        if any(
            abs(abs(float(np.dot(d, d2))) - 1.0) < 1e-9 and np.linalg.norm(np.cross(c - p2, d2)) < radius * 2
            for p2, d2 in axes
        ):
            continue  # the same run, split into several faces
        axes.append((c, d))
    return axes


def measure_wrap_angle(shape: Shape, radius: float, along=(1.0, 0.0, 0.0)) -> float:
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


def _assembly(solids: dict[str, Shape], name: str):
    """An XCAF document holding the assembly ``name``: one part per solid (the solid in a compound of its own),
    placed once, each part and placement named after its key."""
    app = XCAFApp_Application.GetApplication_s()
    BinXCAFDrivers.DefineFormat_s(app)
    doc = TDocStd_Document(TCollection_ExtendedString("BinXCAF"))
    app.InitDocument(doc)
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    shapes.SetAutoNaming_s(False)

    def named(label, text: str):
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(text))
        return label

    top = named(shapes.NewShape(), name)
    for n, s in solids.items():
        part = shapes.NewShape()
        compound, builder = TopoDS_Compound(), TopoDS_Builder()
        builder.MakeCompound(compound)
        builder.Add(compound, s)
        shapes.SetShape(part, compound)
        named(part, n)
        named(shapes.AddComponent(top, part, TopLoc_Location()), n)
    root = TDF_Label()
    shapes.SetLocation(top, TopLoc_Location(), root)
    named(root, name)
    shapes.UpdateAssemblies()
    return doc


#: OpenCASCADE numbers the assembly links (NAUO) of all the STEP files a process writes with one counter: each
#: file's are renumbered 1, 2, …, so that a file does not depend on the files written before it in the process.
_NAUO_ID = re.compile(rb"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('\d+'")


def _renumbered(step: bytes) -> bytes:
    """``step`` with its assembly links numbered from 1 in the order they appear."""
    ids = itertools.count(1)
    return _NAUO_ID.sub(lambda m: b"NEXT_ASSEMBLY_USAGE_OCCURRENCE('%d'" % next(ids), step)


def step_bytes(solids: dict[str, Shape], name: str) -> bytes:
    """A STEP file (AP214, mm) whose solids carry the given names: the assembly ``name`` of one part per solid."""
    doc = _assembly(solids, name)
    writer = STEPCAFControl_Writer(XSControl_WorkSession(), False)
    writer.SetColorMode(True)
    writer.SetLayerMode(True)
    writer.SetNameMode(True)
    Interface_Static.SetIVal_s("write.surfacecurve.mode", 1)  # with the faces' parametric curves
    Interface_Static.SetIVal_s("write.precision.mode", 0)
    Interface_Static.SetIVal_s("write.stepcaf.subshapes.name", 1)
    Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    writer.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, f"{name}.step")
        if writer.Write(path) != IFSelect_ReturnStatus.IFSelect_RetDone:  # a full disk, a file size limit
            raise TemporaryWriteError(f"its STEP file could not be written in the temporary folder ({d})")
        return _renumbered(Path(path).read_bytes())
