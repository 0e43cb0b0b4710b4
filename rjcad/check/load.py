"""Reading the input: a mesh file's bodies (an STL's shells, a 3MF's named parts), the manifest, and which body is which."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import trimesh

from rjcad.check.report import BadInput
from rjcad.errors import RjcadError
from rjcad.io.manifest import Manifest, ManifestError
from rjcad.io.untrusted import check_zip, read_bytes

#: Where a 3MF names the parts of an object (PrusaSlicer's per-object config; rjcad writes it).
PARTS_CONFIG = "Metadata/Slic3r_PE_model.config"


def _parts_config(raw: bytes, label: str) -> dict[str, list[tuple[str, int, int]]]:
    """{object name: [(part name, first triangle, last triangle)]} from a 3MF's parts config ({} if none); BadInput
    for a part whose ``firstid``/``lastid`` are not whole numbers with 0 ≤ firstid ≤ lastid."""
    try:
        with zipfile.ZipFile(io.BytesIO(raw)) as z:
            if PARTS_CONFIG not in z.namelist():
                return {}
            root = ElementTree.fromstring(z.read(PARTS_CONFIG))
    except (zipfile.BadZipFile, ElementTree.ParseError, OSError):
        return {}
    out: dict[str, list[tuple[str, int, int]]] = {}
    for obj in root.iter("object"):
        meta = {m.get("key"): m.get("value") for m in obj.findall("metadata") if m.get("type") == "object"}
        vols = []
        for k, vol in enumerate(obj.findall("volume"), 1):
            vmeta = {m.get("key"): m.get("value") for m in vol.findall("metadata")}
            if vmeta.get("volume_type", "ModelPart") == "ModelPart":
                name = vmeta.get("name") or f"part{k}"
                vols.append((name, *_ids(vol.attrib.get("firstid"), vol.attrib.get("lastid"), name, label)))
        key = meta.get("name", obj.get("id"))
        if key is not None:  # an object with neither a name nor an id: no scene geometry is named None
            out[key] = vols
    return out


def _ids(first: str | None, last: str | None, part: str, label: str) -> tuple[int, int]:
    """A part's triangle range from its ``firstid``/``lastid`` attributes; BadInput unless 0 ≤ first ≤ last."""
    try:
        a, b = int(first or ""), int(last or "")
    except ValueError:
        a, b = -1, -1
    if not 0 <= a <= b:
        raise BadInput(
            f"{label}: {PARTS_CONFIG}: part {part!r}: firstid {first!r}, lastid {last!r}: must be whole numbers "
            "with 0 <= firstid <= lastid"
        )
    return a, b


def _scene_bodies(scene: trimesh.Scene, parts: dict, label: str) -> tuple[list[trimesh.Trimesh], list[str]]:
    """Every object of a 3MF scene placed by its build transform, split into its named parts if listed."""
    names, bodies = [], []
    for node in scene.graph.nodes_geometry:
        transform, geom_name = scene.graph[node]
        geom = scene.geometry[geom_name]
        if not isinstance(geom, trimesh.Trimesh) or not len(geom.faces):
            continue
        verts = trimesh.transform_points(geom.vertices, transform)
        ranges = parts.get(geom_name) or parts.get(str(geom.metadata.get("name", ""))) or []
        if not ranges:
            names.append(str(geom_name))
            bodies.append(trimesh.Trimesh(verts, geom.faces, process=True))
            continue
        for part, first, last in ranges:
            if last >= len(geom.faces):
                raise BadInput(
                    f"{label}: {PARTS_CONFIG}: part {part!r}: lastid {last} is past the object's {len(geom.faces)} "
                    "triangles"
                )
            faces = geom.faces[first : last + 1]
            used = np.unique(faces)
            remap = np.full(len(verts), -1, dtype=np.int64)
            remap[used] = np.arange(len(used))
            names.append(part)
            bodies.append(trimesh.Trimesh(verts[used], remap[faces], process=True))
    return bodies, names


def body_volume(mesh: trimesh.Trimesh) -> float:
    """A body's signed volume [mm³], as trimesh defines it (also for an open body): the flux of (x, 0, 0) through
    its triangles, Σ n_x·(x0 + x1 + x2)/6 with n = (v1 − v0) × (v2 − v0). trimesh's ``volume`` computes all the
    mass properties (3× slower on a big mesh) and divides by the volume for the centre of mass: a flat body
    (degenerate triangles, or each duplicated with both windings) then warns on stderr."""
    t = np.asarray(mesh.triangles, dtype=np.float64)
    n_x = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 0]
    return float(n_x @ t[:, :, 0].sum(axis=1) / 6.0)


def mesh_file(path: str | Path) -> Path:
    """``path`` if it names an existing .stl or .3mf file (before reading it), else BadInput."""
    p = Path(path)
    if not p.exists():
        raise BadInput(f"{p}: file not found")
    if p.suffix.lower() not in (".stl", ".3mf"):
        raise BadInput(f"{p}: not an .stl or .3mf file")
    return p


def load_bodies(path: str | Path) -> tuple[list[trimesh.Trimesh], list[str] | None]:
    """Bodies of an STL (connected components) or a 3MF (named parts, else named objects), and the names if any."""
    p = mesh_file(path)
    is_3mf = p.suffix.lower() == ".3mf"
    try:
        raw = read_bytes(p, "mesh")
        if is_3mf:
            check_zip(raw, str(p))
    except RjcadError as e:
        raise BadInput(str(e)) from None
    try:
        loaded = trimesh.load(io.BytesIO(raw), file_type=p.suffix.lower()[1:], process=not is_3mf, force=None)
    except Exception as e:  # trimesh raises many kinds on garbage
        raise BadInput(f"{p}: not a readable mesh ({type(e).__name__}: {e})".splitlines()[0]) from None
    for geom in loaded.geometry.values() if isinstance(loaded, trimesh.Scene) else [loaded]:
        faces, verts = getattr(geom, "faces", None), getattr(geom, "vertices", ())
        if faces is not None and len(faces) and (faces.min() < 0 or faces.max() >= len(verts)):
            raise BadInput(f"{p}: a triangle names a vertex the mesh does not have (index out of range)")
    if isinstance(loaded, trimesh.Scene):
        bodies, names = _scene_bodies(loaded, _parts_config(raw, str(p)) if is_3mf else {}, str(p))
        if not bodies:
            raise BadInput(f"{p}: the file holds no triangles")
        return bodies, names
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise BadInput(f"{p}: the file holds no triangles")
    # repair=False: trimesh's split otherwise fills each component's small holes, and the check would then
    # measure a mesh that is not the file (a missing triangle passed `watertight`)
    parts = loaded.split(only_watertight=False, repair=False)
    parts = sorted(parts, key=lambda b: -abs(body_volume(b)))
    return list(parts), None


def load_manifest(manifest: Manifest | dict | str | Path | None) -> Manifest | None:
    """The manifest from a JSON file (``Manifest.read``: errors name the file), a JSON object or a Manifest
    (None stays None)."""
    if isinstance(manifest, (str, Path)):
        return Manifest.read(manifest)
    return None if manifest is None else Manifest.coerce(manifest)


def name_bodies(bodies: list[trimesh.Trimesh], names: list[str] | None, manifest: Manifest | dict | None) -> list[str]:
    """Names for the bodies: the 3MF's, or the manifest's matched by volume (within 2 %)."""
    manifest = load_manifest(manifest)
    if manifest is None or manifest.bodies is None:
        return names or [f"body{i + 1}" for i in range(len(bodies))]
    if names is not None:
        missing = [b.name for b in manifest.bodies if b.name not in names]
        if missing:
            raise BadInput(f"manifest names body '{missing[0]}' that the mesh lacks (it has: {', '.join(names)})")
        return names
    out = [f"body{i + 1}" for i in range(len(bodies))]
    free = set(range(len(bodies)))
    for k, b in enumerate(manifest.bodies, 1):
        if b.volume_mm3 is None:
            raise ManifestError(f"bodies[{k}].volume_mm3", None, "is required to match the mesh's bodies by volume")
        name, vol = b.name, float(b.volume_mm3)
        best = min(free, key=lambda i: abs(abs(body_volume(bodies[i])) - vol), default=None)
        if best is None or abs(abs(body_volume(bodies[best])) - vol) > 0.02 * vol:
            raise BadInput(
                f"manifest names body '{name}' ({vol:.0f} mm³) that the mesh lacks: no body within 2 % of that volume"
            )
        out[best] = name
        free.discard(best)
    return out
