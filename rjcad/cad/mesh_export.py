"""The mesh side of the exports (no OpenCASCADE): meshes from triangle arrays, STL, 3MF, GLB, the preview PNG
and the atomic write of a set; the B-rep side (tessellation, measurements, STEP) is ``rjcad.cad.export``. A process that has only the arrays (``rjcad.cad.process``) writes with this alone.
trimesh is imported where it is used, so that the B-rep side (and a process that only builds) does not load
it (0.6 s with SciPy's spatial package)."""

from __future__ import annotations

import io
import json
import os
import struct
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

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
    """Text escaped for an XML attribute value (&, <, > and ")."""
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


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


#: glTF's frame from rjcad's: glTF 2.0 says metres, +Y up, right-handed (+Z the asset's front); rjcad models in mm
#: with +Z up (the bed at z = 0) and +X along the finger. p_gltf [m] = GLTF_FROM_RJCAD · p_rjcad [mm]: a rotation of
#: −90° about X, (x, y, z) → (x, z, −y) (determinant +1, not a mirror: triangles keep their outward winding), times
#: 0.001 m/mm. The bed becomes y = 0 and rjcad's −Y the front.
GLTF_FROM_RJCAD = 0.001 * np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

#: What a GLB states about its frame, in ``asset.extras``: units, up axis, the frame it came from and the map from it
#: (4×4, column-major like a glTF node's ``matrix``), which ``rjcad view`` reads to place the manifest's axes [mm].
GLTF_FRAME = {
    "units": "m",
    "up": "+Y",
    "source_frame": "rjcad: mm, +Z up (the bed at z = 0), +X along the finger",
    "source_to_gltf_matrix": [*(float(v) for col in GLTF_FROM_RJCAD.T for v in (*col, 0.0)), *(0.0, 0.0, 0.0, 1.0)],
}

#: glTF's codes: component types, buffer view targets, GLB chunk types.
_FLOAT, _UINT16, _UINT32 = 5126, 5123, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_GLB_MAGIC, _JSON_CHUNK, _BIN_CHUNK = 0x46546C67, 0x4E4F534A, 0x004E4942


def _linear(colour: str) -> list[float]:
    """'#rrggbb' (sRGB) → glTF's linear base colour factor (r, g, b, 1): c/12.92 below 0.04045, else
    ((c + 0.055)/1.055)^2.4."""
    from rjcad.cad.render import rgb

    return [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb(colour)] + [1.0]


class _GlbBuffer:
    """The binary chunk being assembled: one buffer view per accessor, each at a 4-byte boundary."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.views: list[dict] = []
        self.accessors: list[dict] = []
        self.size = 0

    def accessor(self, data: np.ndarray, kind: str, target: int, bounds: bool) -> int:
        """Add ``data`` (rows of one VEC3 or SCALAR each) as a buffer view and its accessor; its index. ``bounds``:
        the accessor's min and max, the stored (float32) values exactly."""
        raw = data.tobytes()
        self.views.append({"buffer": 0, "byteOffset": self.size, "byteLength": len(raw), "target": target})
        self.parts.append(raw + b"\0" * (-len(raw) % 4))
        self.size += len(self.parts[-1])
        code = {np.dtype("<f4"): _FLOAT, np.dtype("<u2"): _UINT16, np.dtype("<u4"): _UINT32}[data.dtype]
        acc = {"bufferView": len(self.views) - 1, "componentType": code, "count": len(data), "type": kind}
        if bounds:
            acc |= {"min": data.min(axis=0).tolist(), "max": data.max(axis=0).tolist()}
        self.accessors.append(acc)
        return len(self.accessors) - 1


def glb_bytes(meshes: dict[str, trimesh.Trimesh], colours: dict[str, str] | None = None) -> bytes:
    """A binary glTF 2.0 (GLB) of the bodies, in glTF's frame (metres, +Y up: ``GLTF_FROM_RJCAD``), stated in
    ``asset.extras`` (``GLTF_FRAME``). One node per body, named by it, with its own mesh (positions and triangles;
    no normals: a viewer computes flat ones, as the spec says) and material, the body's preview colour (linear, as
    glTF says). Web and AR viewers read it, and ``rjcad view`` embeds it. Same meshes, same bytes.

    The rotation and scale are applied to the vertices, not held in a root node's matrix: a reader that takes
    the positions alone (or the accessors' min/max, which viewers use to frame and scale a model) still gets
    metres with +Y up, and the validator checks those bounds against the data."""
    from rjcad.cad.render import PALETTE

    buf = _GlbBuffer()
    nodes, gmeshes, materials = [], [], []
    for i, (name, m) in enumerate(meshes.items()):
        vertices = (np.asarray(m.vertices, dtype=float) @ GLTF_FROM_RJCAD.T).astype("<f4") + np.float32(0.0)  # no -0
        faces = np.asarray(m.faces).reshape(-1)
        faces = faces.astype("<u2" if len(vertices) <= 0xFFFF else "<u4")  # u16 up to 65534 (65535: restart)
        colour = (colours or {}).get(name, PALETTE[i % len(PALETTE)])
        attributes = {"POSITION": buf.accessor(vertices, "VEC3", _ARRAY_BUFFER, bounds=True)}
        indices = buf.accessor(faces, "SCALAR", _ELEMENT_ARRAY_BUFFER, bounds=False)
        gmeshes.append({"name": name, "primitives": [{"attributes": attributes, "indices": indices, "material": i}]})
        materials.append(
            {
                "name": name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": _linear(colour),
                    "metallicFactor": 0.0,
                    "roughnessFactor": 0.7,
                },
            }
        )
        nodes.append({"name": name, "mesh": i})
    doc = {
        "asset": {"version": "2.0", "generator": "rjcad", "extras": GLTF_FRAME},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": gmeshes,
        "materials": materials,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": buf.size}],
    }
    return _glb(json.dumps(doc, separators=(",", ":")).encode("utf-8"), b"".join(buf.parts))


def _glb(text: bytes, binary: bytes) -> bytes:
    """The GLB container: a 12-byte header, the JSON chunk (padded with spaces) and the binary chunk (with zeros),
    each chunk's length a multiple of 4."""
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return b"".join(
        (
            struct.pack("<III", _GLB_MAGIC, 2, total),
            struct.pack("<II", len(text), _JSON_CHUNK),
            text,
            struct.pack("<II", len(binary), _BIN_CHUNK),
            binary,
        )
    )


def glb_json_chunk(data: bytes) -> bytes:
    """The JSON chunk of a GLB (its first chunk, as the spec requires), as bytes; ``ValueError`` saying why if
    ``data`` is not a GLB version 2."""
    if len(data) < 20 or struct.unpack_from("<III", data) != (_GLB_MAGIC, 2, len(data)):
        raise ValueError("its header is not that of a glTF 2 binary of its length")
    length, kind = struct.unpack_from("<II", data, 12)
    if kind != _JSON_CHUNK or 20 + length > len(data):
        raise ValueError("its first chunk is not a whole JSON chunk")
    return data[20 : 20 + length]


def write_outputs(
    out_dir: str | os.PathLike, files: dict[str, bytes | str], remove: tuple[str, ...] = ()
) -> list[Path]:
    """Write the files as one set (``rjcad.io.outputs.write_set``: all or none, an earlier run untouched);
    everything is built before the first write. ``remove``: names of the set this run does not write."""
    return write_set(out_dir, files, remove)
