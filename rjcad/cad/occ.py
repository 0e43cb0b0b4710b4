"""The few OpenCASCADE operations rjcad's solids are made of, through OCP (OpenCASCADE's Python binding): boxes,
cylinders, balls, prisms and revolutions of plane faces, booleans, rigid moves, and what is read back from a shape
(its solids, faces and edges, volume, centres, bounding box, inside test, distance).

Shapes are OCP's ``TopoDS_Shape``; points and vectors are ``Vec`` or (x, y, z) tuples, in mm; angles are in degrees
where a name says ``deg``. Each function is one OpenCASCADE call or a short fixed sequence of them, always with the
same options: booleans run on all cores without a fuzzy value; prisms, revolutions and moves copy the geometry; a
plane face is made from its wire once ShapeFix has checked it, and its orientation fixed; ``clean`` merges faces and
edges that lie on one surface or curve.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import TypeAlias

from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_BooleanOperation, BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
    BRepBuilderAPI_MakeWire,
    BRepBuilderAPI_Transform,
)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.BRepPrimAPI import (
    BRepPrimAPI_MakeBox,
    BRepPrimAPI_MakeCylinder,
    BRepPrimAPI_MakePrism,
    BRepPrimAPI_MakeRevol,
    BRepPrimAPI_MakeSphere,
)
from OCP.GC import GC_MakeArcOfCircle
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.Message import Message, Message_Gravity
from OCP.ShapeAnalysis import ShapeAnalysis
from OCP.ShapeFix import ShapeFix_Face, ShapeFix_Shape
from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_ShapeEnum, TopAbs_SOLID, TopAbs_State
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shape, TopoDS_Solid, TopoDS_Vertex, TopoDS_Wire
from OCP.TopTools import TopTools_IndexedMapOfShape, TopTools_ListOfShape

#: A solid, face, edge, ... (OpenCASCADE's topological shape).
Shape: TypeAlias = TopoDS_Shape

# OpenCASCADE's messages (the STEP writer's statistics, ...) go to stdout, the program's: only failures are printed
for _printer in Message.DefaultMessenger_s().Printers():
    _printer.SetTraceLevel(Message_Gravity.Message_Fail)


@dataclass(frozen=True, slots=True)
class Vec:
    """A point or a vector [mm]. Its arithmetic is OpenCASCADE's (gp_Vec's), operation for operation, so that a
    point computed here is the same double a gp_Vec computes."""

    x: float
    y: float
    z: float

    def __iter__(self) -> Iterator[float]:
        return iter((self.x, self.y, self.z))

    def __add__(self, o: Vec) -> Vec:
        return Vec(self.x + o.x, self.y + o.y, self.z + o.z)

    def __sub__(self, o: Vec) -> Vec:
        return Vec(self.x - o.x, self.y - o.y, self.z - o.z)

    def __mul__(self, k: float) -> Vec:
        return Vec(self.x * k, self.y * k, self.z * k)

    def dot(self, o: Vec) -> float:
        return self.x * o.x + self.y * o.y + self.z * o.z

    def cross(self, o: Vec) -> Vec:
        return Vec(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)

    @property
    def length(self) -> float:
        return math.sqrt(self.x * self.x + self.y * self.y + self.z * self.z)

    def unit(self) -> Vec:
        """This vector divided by its length."""
        n = self.length
        return Vec(self.x / n, self.y / n, self.z / n)


ORIGIN = Vec(0.0, 0.0, 0.0)
Z = Vec(0.0, 0.0, 1.0)
Point = Vec | Sequence[float]


def _pnt(p: Point) -> gp_Pnt:
    x, y, z = p
    return gp_Pnt(x, y, z)


def _dir(v: Point) -> gp_Dir:
    x, y, z = v
    return gp_Dir(x, y, z)


def _frame(origin: Point, axis: Point) -> gp_Ax2:
    """A frame at ``origin`` whose Z is ``axis`` (its X chosen by OpenCASCADE)."""
    return gp_Ax2(_pnt(origin), _dir(axis))


# ------------------------------------------------------------------ solids


def box(dx: float, dy: float, dz: float, corner: Point = ORIGIN) -> Shape:
    """The box [corner, corner + (dx, dy, dz)], axis-aligned [mm]."""
    return BRepPrimAPI_MakeBox(_frame(corner, Z), dx, dy, dz).Shape()


def cylinder(radius: float, height: float, base: Point = ORIGIN, axis: Point = Z) -> Shape:
    """A cylinder of ``radius`` from ``base`` along ``axis`` (any length) for ``height`` [mm]."""
    return BRepPrimAPI_MakeCylinder(_frame(base, axis), radius, height, math.radians(360.0)).Shape()


def ball(radius: float, centre: Point, axis: Point) -> Shape:
    """The ball of ``radius`` around ``centre``, its poles on ``axis`` [mm]."""
    a = math.radians
    return BRepPrimAPI_MakeSphere(_frame(centre, axis), radius, a(-90.0), a(90.0), a(360.0)).Shape()


def prism(face: Shape, v: Point) -> Shape:
    """The solid a planar face sweeps moved along ``v`` [mm]."""
    x, y, z = v
    return BRepPrimAPI_MakePrism(face, gp_Vec(x, y, z), True).Shape()


def revolution(face: Shape, angle_deg: float, axis_point: Point = ORIGIN, axis: Point = Z) -> Shape:
    """The solid a planar face sweeps turning ``angle_deg`` about the axis through ``axis_point``."""
    return BRepPrimAPI_MakeRevol(face, gp_Ax1(_pnt(axis_point), _dir(axis)), math.radians(angle_deg), True).Shape()


# ------------------------------------------------------------------ edges, wires, faces


def line(a: Point, b: Point) -> TopoDS_Edge:
    """The straight edge from a to b."""
    return BRepBuilderAPI_MakeEdge(_pnt(a), _pnt(b)).Edge()


def arc(a: Point, m: Point, b: Point) -> TopoDS_Edge:
    """The circular arc from a through m to b."""
    return BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(_pnt(a), _pnt(m), _pnt(b)).Value()).Edge()


def wire(edges: Iterable[TopoDS_Edge]) -> TopoDS_Wire:
    """One wire of edges that meet end to end."""
    todo = TopTools_ListOfShape()
    for e in edges:
        todo.Append(e)
    maker = BRepBuilderAPI_MakeWire()
    maker.Add(todo)
    maker.Build()
    if not maker.IsDone():
        raise RuntimeError(f"edges do not make one wire (OpenCASCADE's error {maker.Error()})")
    return maker.Wire()


def polygon(points: Iterable[Point]) -> TopoDS_Wire:
    """The closed polygon through ``points``."""
    maker = BRepBuilderAPI_MakePolygon()
    for p in points:
        maker.Add(_pnt(p))
    maker.Close()
    return maker.Wire()


def planar_face(outline: TopoDS_Wire) -> TopoDS_Face:
    """The plane face a closed, planar wire bounds (the wire fixed first, the face's orientation fixed after)."""
    fix_wire = ShapeFix_Shape(outline)
    fix_wire.Perform()
    maker = BRepBuilderAPI_MakeFace(TopoDS.Wire_s(fix_wire.Shape()), True)
    maker.Build()
    if not maker.IsDone():
        raise ValueError(f"no plane face in this wire (OpenCASCADE's error {maker.Error()})")
    fix_face = ShapeFix_Face(maker.Face())
    fix_face.FixOrientation()
    fix_face.Perform()
    return fix_face.Result()


# ------------------------------------------------------------------ booleans


def _boolean(op: BRepAlgoAPI_BooleanOperation, shape: Shape, tools: Sequence[Shape]) -> Shape:
    """``op`` of ``shape`` with ``tools``, on all cores."""
    arguments, others = TopTools_ListOfShape(), TopTools_ListOfShape()
    arguments.Append(shape)
    for t in tools:
        others.Append(t)
    op.SetArguments(arguments)
    op.SetTools(others)
    op.SetRunParallel(True)
    op.Build()
    if not op.IsDone():
        raise RuntimeError(f"{type(op).__name__} failed")
    return op.Shape()


def fuse(shape: Shape, *others: Shape) -> Shape:
    """The union of ``shape`` and ``others``, in one operation."""
    return _boolean(BRepAlgoAPI_Fuse(), shape, others)


def cut(shape: Shape, *tools: Shape) -> Shape:
    """``shape`` less every tool, in one operation."""
    return _boolean(BRepAlgoAPI_Cut(), shape, tools)


def common(shape: Shape, *tools: Shape) -> Shape:
    """What ``shape`` has in common with the tools (a solid with a solid, or with an edge: the edge's parts inside)."""
    return _boolean(BRepAlgoAPI_Common(), shape, tools)


def clean(shape: Shape) -> Shape:
    """``shape`` with neighbouring faces on one surface, and edges on one curve, merged into one (no internal
    edges kept)."""
    unify = ShapeUpgrade_UnifySameDomain(shape, True, True, True)
    unify.AllowInternalEdges(False)
    unify.Build()
    return unify.Shape()


# ------------------------------------------------------------------ moves (each copies the geometry)


def _moved(shape: Shape, t: gp_Trsf) -> Shape:
    return BRepBuilderAPI_Transform(shape, t, True).Shape()


def translated(shape: Shape, v: Point) -> Shape:
    """``shape`` moved by ``v`` [mm]."""
    x, y, z = v
    t = gp_Trsf()
    t.SetTranslation(gp_Vec(x, y, z))
    return _moved(shape, t)


def rotated(shape: Shape, angle_deg: float, axis_point: Point = ORIGIN, axis: Point = Z) -> Shape:
    """``shape`` turned by ``angle_deg`` (right hand) about the axis through ``axis_point`` along ``axis``."""
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(_pnt(axis_point), _dir(axis)), math.radians(angle_deg))
    return _moved(shape, t)


def mirrored(shape: Shape, normal: Point, point: Point = ORIGIN) -> Shape:
    """``shape`` mirrored across the plane through ``point`` with ``normal``."""
    t = gp_Trsf()
    t.SetMirror(_frame(point, normal))
    return _moved(shape, t)


# ------------------------------------------------------------------ what a shape is made of, and its measures


def _parts(shape: Shape, kind: TopAbs_ShapeEnum) -> list[Shape]:
    """The distinct sub-shapes of one kind, in OpenCASCADE's order of exploration."""
    found = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, kind, found)
    return list(found)


def solids(shape: Shape) -> list[TopoDS_Solid]:
    return [TopoDS.Solid_s(s) for s in _parts(shape, TopAbs_SOLID)]


def faces(shape: Shape) -> list[TopoDS_Face]:
    return [TopoDS.Face_s(f) for f in _parts(shape, TopAbs_FACE)]


def edges(shape: Shape) -> list[TopoDS_Edge]:
    """The edges, less degenerate ones (a sphere's poles)."""
    found = (TopoDS.Edge_s(e) for e in _parts(shape, TopAbs_EDGE))
    return [e for e in found if not BRep_Tool.Degenerated_s(e)]


def edge_ends(edge: TopoDS_Edge) -> tuple[Vec, Vec]:
    """The edge's first and last points, in its own direction."""
    first, last = TopoDS_Vertex(), TopoDS_Vertex()
    ShapeAnalysis.FindBounds_s(edge, first, last)
    start, end = (Vec(*BRep_Tool.Pnt_s(v).Coord()) for v in (first, last))
    return start, end


def is_cylinder(face: TopoDS_Face) -> bool:
    return BRepAdaptor_Surface(face).GetType() == GeomAbs_SurfaceType.GeomAbs_Cylinder


def is_valid(shape: Shape) -> bool:
    """OpenCASCADE's full check of the shape (geometry included), on all cores."""
    return BRepCheck_Analyzer(shape, True, True).IsValid()


def volume(shape: Shape) -> float:
    """The volume of a solid [mm³]."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass()


def area_centre(face: Shape) -> Vec:
    """The centre of a face's area [mm]."""
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return Vec(*props.CentreOfMass().Coord())


def bounding_box(shape: Shape) -> tuple[float, float, float, float, float, float]:
    """(xmin, ymin, zmin, xmax, ymax, zmax) of the shape's exact bounding box [mm]."""
    bb = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, bb)
    return bb.Get()


def is_inside(shape: Shape, p: Point, tolerance: float = 1e-6) -> bool:
    """Whether point p is inside the solid or on its boundary (within ``tolerance`` [mm])."""
    where = BRepClass3d_SolidClassifier(shape)
    where.Perform(_pnt(p), tolerance)
    return where.State() == TopAbs_State.TopAbs_IN or where.IsOnAFace()


def distance(a: Shape, b: Shape) -> float:
    """The least distance between two shapes [mm] (0 where they touch or overlap)."""
    d = BRepExtrema_DistShapeShape()
    d.SetMultiThread(True)
    d.LoadS1(a)
    d.LoadS2(b)
    d.Perform()
    if not d.IsDone():
        raise RuntimeError("distance: OpenCASCADE found none")
    return d.Value()
