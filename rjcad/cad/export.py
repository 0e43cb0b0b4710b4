"""Meshes, measurements on the built geometry, and atomic STL/3MF/STEP/GLB/PNG/JSON export."""

from __future__ import annotations

import io
import math
import os
import tempfile
import zipfile
from pathlib import Path
from xml.sax.saxutils import escape

import cadquery as cq
import numpy as np
import trimesh
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopLoc import TopLoc_Location

from rjcad.outputs import write_set

#: Tessellation: OCCT's linear deflection, relative to each edge's and face's size (CadQuery's ``Shape.mesh``
#: passes it as relative, and ``triangulate`` keeps that), and the angular deflection δ [rad]. The angle governs on
#: curved faces: a chord sags by R·(1 − cos δ/2) = 1.25e-3·R, 2.5 µm on a 2 mm pin, 0.03 mm on the desktop cup's
#: roof (a cone up to R ≈ 23 mm), the default joint's worst (tests/test_joint.py measures it on the built bodies).
MESH_TOLERANCE = 0.01
MESH_ANGULAR_TOLERANCE = 0.1


def triangulate(shape: cq.Shape, tolerance: float = MESH_TOLERANCE,
                angular_tolerance: float = MESH_ANGULAR_TOLERANCE) -> tuple[np.ndarray, np.ndarray]:
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


def to_mesh(shape: cq.Shape, tolerance: float = MESH_TOLERANCE,
            angular_tolerance: float = MESH_ANGULAR_TOLERANCE) -> trimesh.Trimesh:
    """Tessellate a solid into a trimesh with merged vertices (watertight when the B-rep is)."""
    v, f = triangulate(shape, tolerance, angular_tolerance)
    return trimesh.Trimesh(v, f, process=True)


def segment_inside(shape: cq.Shape, start, end) -> list[tuple[float, float]]:
    """Parameter ranges [mm from ``start``] where the segment start→end lies inside ``shape``."""
    a, b = cq.Vector(*start), cq.Vector(*end)
    common = shape.intersect(cq.Edge.makeLine(a, b))
    spans = []
    for e in common.Edges():
        s = sorted(((e.startPoint() - a).Length, (e.endPoint() - a).Length))
        spans.append((s[0], s[1]))
    return sorted(spans)


def measure_moment_arm(moving: cq.Shape, z_mid: float, line_diameter: float,
                       axis_point=(0.0, 0.0, 0.0), direction=(0.0, 1.0, 0.0)) -> float:
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
        if any(abs(abs(float(np.dot(d, d2))) - 1.0) < 1e-9 and np.linalg.norm(np.cross(c - p2, d2)) < radius * 2
               for p2, d2 in axes):
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
    for (_, d1), (_, d2) in zip(axes[:-1], axes[1:]):
        total += math.acos(min(1.0, abs(float(np.dot(d1, d2)))))
    return total


def stl_bytes(meshes: list[trimesh.Trimesh]) -> bytes:
    """All bodies in one binary STL."""
    return trimesh.util.concatenate(meshes).export(file_type="stl")


#: The 3MF part names PrusaSlicer reads (its own per-object config: one volume per triangle range).
THREEMF_PARTS_CONFIG = "Metadata/Slic3r_PE_model.config"


def _zip_entry(name: str) -> zipfile.ZipInfo:
    """A zip entry with a fixed date, so that the same meshes give the same bytes."""
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    return info


def _q(text) -> str:
    """Text escaped for an XML attribute value."""
    return escape(str(text), {'"': "&quot;"})


def threemf_bytes(meshes: dict[str, trimesh.Trimesh], name: str = "assembly") -> bytes:
    """A 3MF holding ONE object whose parts are the bodies, at their modelled positions.

    The object's mesh is every body's triangles in turn; ``Metadata/Slic3r_PE_model.config`` names
    each body's triangle range as a part (PrusaSlicer and its forks read it), so a slicer keeps the
    assembly together instead of arranging the bodies apart. Readers that ignore the config see one
    mesh of several shells; ``rjcad.check.load.load_bodies`` splits it by the config again.
    """
    verts, tris, parts, nv, nf = [], [], [], 0, 0
    for part, m in meshes.items():
        v = np.asarray(m.vertices, dtype=float)
        f = np.asarray(m.faces, dtype=np.int64)
        verts.append("".join(f'<vertex x="{x:.6f}" y="{y:.6f}" z="{z:.6f}"/>' for x, y, z in v))
        tris.append("".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in (f + nv).tolist()))
        parts.append((part, nf, nf + len(f) - 1))
        nv, nf = nv + len(v), nf + len(f)
    model = ('<?xml version="1.0" encoding="UTF-8"?>\n'
             '<model unit="millimeter" xml:lang="en-US" '
             'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">\n'
             f'<resources><object id="1" name="{_q(name)}" type="model"><mesh>'
             f'<vertices>{"".join(verts)}</vertices><triangles>{"".join(tris)}</triangles>'
             '</mesh></object></resources>\n<build><item objectid="1"/></build>\n</model>\n')
    config = ['<?xml version="1.0" encoding="UTF-8"?>', "<config>", ' <object id="1" instances_count="1">',
              f'  <metadata type="object" key="name" value="{_q(name)}"/>']
    for part, first, last in parts:
        config += [f'  <volume firstid="{first}" lastid="{last}">',
                   f'   <metadata type="volume" key="name" value="{_q(part)}"/>',
                   '   <metadata type="volume" key="volume_type" value="ModelPart"/>', "  </volume>"]
    config += [" </object>", "</config>", ""]
    types = ('<?xml version="1.0" encoding="UTF-8"?>\n'
             '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
             '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
             '<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
             '<Default Extension="config" ContentType="text/xml"/></Types>\n')
    rels = ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
            '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
            'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>\n')
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for entry, text in (("[Content_Types].xml", types), ("_rels/.rels", rels), ("3D/3dmodel.model", model),
                            (THREEMF_PARTS_CONFIG, "\n".join(config))):
            z.writestr(_zip_entry(entry), text)
    return buf.getvalue()


def step_bytes(solids: dict[str, cq.Shape], name: str) -> bytes:
    """A STEP file whose solids carry the given names (through an Assembly)."""
    assy = cq.Assembly(name=name)
    for n, s in solids.items():
        assy.add(s, name=n)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, f"{name}.step")
        assy.export(path, exportType="STEP")
        return Path(path).read_bytes()


def preview_png(meshes: dict[str, trimesh.Trimesh], title: str, lines: list[np.ndarray] = (),
                colours: dict[str, str] | None = None,
                sections: list[tuple[str, tuple[float, float, float], tuple[float, float, float]]] = ()) -> bytes:
    """Preview: a shaded, depth-correct isometric view plus plane sections (label, origin, normal); PNG bytes
    (rendered off-screen by ``rjcad.cad.render``)."""
    from rjcad.cad.render import preview_png as render

    return render(meshes, title, lines, colours, sections)


def glb_bytes(meshes: dict[str, trimesh.Trimesh], colours: dict[str, str] | None = None) -> bytes:
    """A binary glTF (GLB) of the bodies, one named node and mesh each, at their modelled positions [mm];
    each body's material in its preview colour (linear, as glTF says). Web and AR viewers read it (and ``rjcad
    view`` embeds it)."""
    from rjcad.cad.render import PALETTE, rgb

    scene = trimesh.Scene()
    for i, (name, m) in enumerate(meshes.items()):
        colour = (colours or {}).get(name, PALETTE[i % len(PALETTE)])
        linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb(colour)]  # glTF: linear
        mat = trimesh.visual.material.PBRMaterial(name=name, baseColorFactor=[*linear, 1.0],
                                                  metallicFactor=0.0, roughnessFactor=0.7)
        body = trimesh.Trimesh(m.vertices, m.faces, process=False,
                               visual=trimesh.visual.TextureVisuals(material=mat))
        scene.add_geometry(body, node_name=name, geom_name=name)
    return scene.export(file_type="glb")


def write_outputs(out_dir: str | os.PathLike, files: dict[str, bytes | str],
                  remove: tuple[str, ...] = ()) -> list[Path]:
    """Write the files as one set (``rjcad.outputs.write_set``: all or none, an earlier run untouched);
    everything is built before the first write. ``remove``: names of the set this run does not write."""
    return write_set(out_dir, files, remove)
