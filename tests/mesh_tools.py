"""Mesh helpers for the CAD tests: load bodies, manifold3d conversions, rigid rotations."""

import math

import manifold3d as m3
import numpy as np
import trimesh

from rjcad.check.mesh_checks import (
    to_manifold as manifold,  # the tests' name for it: float64, like the builder and check
)


def box(lo, hi) -> trimesh.Trimesh:
    """Axis-aligned box from corner ``lo`` to corner ``hi`` [mm]."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    b = trimesh.creation.box(extents=hi - lo)
    b.apply_translation((lo + hi) / 2)
    return b


def cyl(r, z0, z1, x=0.0, y=0.0, sections=256) -> trimesh.Trimesh:
    """Vertical cylinder of radius ``r`` from z0 to z1 about (x, y) [mm]; fine facets by default (a 2 mm pin in
    a 2.25 mm bore then measures within 0.001 mm of 0.25 mm)."""
    c = trimesh.creation.cylinder(radius=r, height=z1 - z0, sections=sections)
    c.apply_translation((x, y, (z0 + z1) / 2))
    return c


def difference(a, b) -> trimesh.Trimesh:
    """Boolean a − b by manifold3d (float64), as a processed trimesh."""
    m = (manifold(a) - manifold(b)).to_mesh64()
    return trimesh.Trimesh(np.asarray(m.vert_properties)[:, :3], np.asarray(m.tri_verts), process=True)


def union(*meshes) -> trimesh.Trimesh:
    """Boolean union by manifold3d (float64), as a processed trimesh."""
    m = m3.Manifold.batch_boolean([manifold(x) for x in meshes], m3.OpType.Add).to_mesh64()
    return trimesh.Trimesh(np.asarray(m.vert_properties)[:, :3], np.asarray(m.tri_verts), process=True)


def load_bodies(path) -> list[trimesh.Trimesh]:
    """Connected bodies of a mesh file, largest first."""
    mesh = trimesh.load(str(path), force="mesh", process=True)
    bodies = mesh.split(only_watertight=False)
    return sorted(bodies, key=lambda b: -abs(b.volume))


def rotate_about(man: m3.Manifold, point, direction, angle_rad: float) -> m3.Manifold:
    """Rigid rotation of a Manifold about the axis (point, direction)."""
    R = trimesh.transformations.rotation_matrix(angle_rad, direction, point)
    return man.transform(R[:3, :4])


def sweep_collisions(ground: m3.Manifold, moving: m3.Manifold, point, direction, lo: float, hi: float, step: float):
    """(angle, intersection volume, gap) for poses lo..hi every ≤ step rad."""
    n = max(1, math.ceil((hi - lo) / step))
    out = []
    for a in np.linspace(lo, hi, n + 1):
        mv = rotate_about(moving, point, direction, float(a))
        vol = (ground ^ mv).volume()
        out.append((float(a), vol, ground.min_gap(mv, 1.0)))
    return out


def chain_transforms(axes, thetas):
    """4x4 transforms of the child bodies of a serial chain at joint angles ``thetas``.

    axes: [(point, direction)] at rest, proximal first. Body k (k = 1..N, the child of
    joint k) moves by R_1(θ1)·R_2(θ2)·…·R_k(θk), each R_j about joint j's rest axis.
    """
    T = np.eye(4)
    out = []
    for (pt, d), th in zip(axes, thetas):
        T = T @ trimesh.transformations.rotation_matrix(float(th), d, pt)
        out.append(T.copy())
    return out


def posed(manifolds, axes, thetas):
    """Bodies [base, child1, …] moved to the joint angles ``thetas``."""
    Ts = chain_transforms(axes, thetas)
    return [manifolds[0]] + [m.transform(T[:3, :4]) for m, T in zip(manifolds[1:], Ts)]


def worst_overlap(bodies, pairs):
    """Largest intersection volume over the given body index pairs, and that pair."""
    worst = (0.0, None)
    for a, b in pairs:
        v = (bodies[a] ^ bodies[b]).volume()
        if v > worst[0]:
            worst = (v, (a, b))
    return worst


def read_step(path) -> dict:
    """The named parts of a STEP file's assembly, {name: shape}, in the file's order (OpenCASCADE's reader)."""
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_ShapeTool

    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    assert reader.ReadFile(str(path)) == IFSelect_ReturnStatus.IFSelect_RetDone
    assert reader.Transfer(doc)
    assemblies = TDF_LabelSequence()
    XCAFDoc_DocumentTool.ShapeTool_s(doc.Main()).GetFreeShapes(assemblies)
    named = {}
    for i in range(1, assemblies.Length() + 1):
        parts = TDF_LabelSequence()
        XCAFDoc_ShapeTool.GetComponents_s(assemblies.Value(i), parts)
        for j in range(1, parts.Length() + 1):
            name = TDataStd_Name()
            assert parts.Value(j).FindAttribute(TDataStd_Name.GetID_s(), name)
            named[name.Get().ToExtString()] = XCAFDoc_ShapeTool.GetShape_s(parts.Value(j))
    return named


def reimport_step(path, names) -> dict:
    """Re-import a STEP file in a fresh process: {name: [solid count, valid, volume]} for the named solids."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    code = f"""
import json, sys
sys.path.insert(0, {str(Path(__file__).parent)!r})
from mesh_tools import read_step
from rjcad.cad import occ
res = {{n: [len(occ.solids(s)), occ.is_valid(s), occ.volume(s)] for n, s in read_step({str(path)!r}).items()}}
print(json.dumps({{n: v for n, v in res.items() if n in {list(names)!r}}}))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])
