"""The mesh side of the exports (no OpenCASCADE): meshes from triangle arrays, STL, 3MF, GLB, the preview PNG
and the atomic write of a set; the B-rep side (tessellation, measurements, STEP) is ``rjcad.cad.export``. A process that has only the arrays (``rjcad.cad.process``) writes with this alone.
trimesh is imported where it is used, so that the B-rep side (and a process that only builds) does not load
it (0.6 s with SciPy's spatial package)."""

from __future__ import annotations

import io
import os
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING
from xml.sax.saxutils import escape

import numpy as np

from rjcad.io.outputs import write_set

if TYPE_CHECKING:
    import trimesh

#: Tessellation: OCCT's linear deflection, relative to each edge's and face's size (``export.triangulate`` passes
#: it as relative), and the angular deflection δ [rad]. The angle governs on
#: curved faces: a chord sags by R·(1 − cos δ/2) = 1.25e-3·R, 2.5 µm on a 2 mm pin, 0.03 mm on the desktop cup's
#: roof (a cone up to R ≈ 23 mm), the default joint's worst (tests/test_joint.py measures it on the built bodies).
MESH_TOLERANCE = 0.01
MESH_ANGULAR_TOLERANCE = 0.1


def prepare(png: bool = True) -> None:
    """Import what meshing, the gap measurement and the files need (trimesh, manifold3d, and with ``png`` the
    renderer's VTK modules, and its off-screen context started): 1.0–1.3 s that the ``rjcad`` program spends
    while its CAD process builds."""
    import manifold3d  # noqa: F401
    import trimesh  # noqa: F401

    if png:
        from rjcad.cad.render import warm_up

        warm_up()


def mesh_of(vertices: np.ndarray, faces: np.ndarray) -> trimesh.Trimesh:
    """A trimesh with merged vertices (watertight when the B-rep was) of unmerged triangle arrays."""
    import trimesh

    return trimesh.Trimesh(vertices, faces, process=True)


def stl_bytes(meshes: list[trimesh.Trimesh]) -> bytes:
    """All bodies in one binary STL."""
    import trimesh

    return trimesh.util.concatenate(meshes).export(file_obj=None, file_type="stl")


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
    model = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<model unit="millimeter" xml:lang="en-US" '
        'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">\n'
        f'<resources><object id="1" name="{_q(name)}" type="model"><mesh>'
        f"<vertices>{''.join(verts)}</vertices><triangles>{''.join(tris)}</triangles>"
        '</mesh></object></resources>\n<build><item objectid="1"/></build>\n</model>\n'
    )
    config = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        "<config>",
        ' <object id="1" instances_count="1">',
        f'  <metadata type="object" key="name" value="{_q(name)}"/>',
    ]
    for part, first, last in parts:
        config += [
            f'  <volume firstid="{first}" lastid="{last}">',
            f'   <metadata type="volume" key="name" value="{_q(part)}"/>',
            '   <metadata type="volume" key="volume_type" value="ModelPart"/>',
            "  </volume>",
        ]
    config += [" </object>", "</config>", ""]
    types = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
        '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
        '<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
        '<Default Extension="config" ContentType="text/xml"/></Types>\n'
    )
    rels = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
        '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
        'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>\n'
    )
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for entry, text in (
            ("[Content_Types].xml", types),
            ("_rels/.rels", rels),
            ("3D/3dmodel.model", model),
            (THREEMF_PARTS_CONFIG, "\n".join(config)),
        ):
            z.writestr(_zip_entry(entry), text)
    return buf.getvalue()


def preview_png(
    meshes: dict[str, trimesh.Trimesh],
    title: str,
    lines: Sequence[np.ndarray] = (),
    colours: dict[str, str] | None = None,
    sections: Sequence[tuple[str, tuple[float, float, float], tuple[float, float, float]]] = (),
) -> bytes:
    """Preview: a shaded, depth-correct isometric view plus plane sections (label, origin, normal); PNG bytes
    (rendered off-screen by ``rjcad.cad.render``)."""
    from rjcad.cad.render import preview_png as render

    return render(meshes, title, lines, colours, sections)


def glb_bytes(meshes: dict[str, trimesh.Trimesh], colours: dict[str, str] | None = None) -> bytes:
    """A binary glTF (GLB) of the bodies, one named node and mesh each, at their modelled positions [mm];
    each body's material in its preview colour (linear, as glTF says). Web and AR viewers read it (and ``rjcad
    view`` embeds it)."""
    import trimesh

    from rjcad.cad.render import PALETTE, rgb

    scene = trimesh.Scene()
    for i, (name, m) in enumerate(meshes.items()):
        colour = (colours or {}).get(name, PALETTE[i % len(PALETTE)])
        linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb(colour)]  # glTF: linear
        mat = trimesh.visual.material.PBRMaterial(
            name=name, baseColorFactor=[*linear, 1.0], metallicFactor=0.0, roughnessFactor=0.7
        )
        body = trimesh.Trimesh(m.vertices, m.faces, process=False, visual=trimesh.visual.TextureVisuals(material=mat))
        scene.add_geometry(body, node_name=name, geom_name=name)
    return scene.export(file_type="glb")


def write_outputs(
    out_dir: str | os.PathLike, files: dict[str, bytes | str], remove: tuple[str, ...] = ()
) -> list[Path]:
    """Write the files as one set (``rjcad.io.outputs.write_set``: all or none, an earlier run untouched);
    everything is built before the first write. ``remove``: names of the set this run does not write."""
    return write_set(out_dir, files, remove)
