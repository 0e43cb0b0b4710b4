"""Reading the input: a mesh file's bodies, the manifest, and which body is which."""

from __future__ import annotations

import json
from pathlib import Path

import trimesh

from rjcad.check.report import BadInput
from rjcad.manifest import Manifest, ManifestError


def load_bodies(path: str | Path) -> tuple[list[trimesh.Trimesh], list[str] | None]:
    """Bodies of an STL (connected components) or a 3MF (named objects), and the names if any."""
    p = Path(path)
    if not p.exists():
        raise BadInput(f"{p}: file not found")
    if p.suffix.lower() not in (".stl", ".3mf"):
        raise BadInput(f"{p}: not an .stl or .3mf file")
    try:
        loaded = trimesh.load(str(p), process=True, force=None)
    except Exception as e:  # trimesh raises many kinds on garbage
        raise BadInput(f"{p}: not a readable mesh ({type(e).__name__}: {e})".splitlines()[0]) from None
    if isinstance(loaded, trimesh.Scene):
        names, bodies = [], []
        for name, geom in loaded.geometry.items():
            if isinstance(geom, trimesh.Trimesh) and len(geom.faces):
                names.append(str(name))
                bodies.append(geom)
        if not bodies:
            raise BadInput(f"{p}: the file holds no triangles")
        return bodies, names
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise BadInput(f"{p}: the file holds no triangles")
    parts = loaded.split(only_watertight=False)
    parts = sorted(parts, key=lambda b: -abs(b.volume))
    return list(parts), None


def load_manifest(manifest: Manifest | dict | str | Path | None) -> Manifest | None:
    """The manifest from a JSON file, a JSON object or a Manifest (None stays None)."""
    if isinstance(manifest, (str, Path)):
        try:
            manifest = json.loads(Path(manifest).read_text())
        except FileNotFoundError:
            raise BadInput(f"{manifest}: manifest not found") from None
        except json.JSONDecodeError as e:
            raise BadInput(f"{manifest}: manifest is not JSON ({e})") from None
    return None if manifest is None else Manifest.coerce(manifest)


def name_bodies(bodies: list[trimesh.Trimesh], names: list[str] | None,
                manifest: Manifest | dict | None) -> list[str]:
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
        best = min(free, key=lambda i: abs(abs(bodies[i].volume) - vol), default=None)
        if best is None or abs(abs(bodies[best].volume) - vol) > 0.02 * vol:
            raise BadInput(f"manifest names body '{name}' ({vol:.0f} mm³) that the mesh lacks: "
                           f"no body within 2 % of that volume")
        out[best] = name
        free.discard(best)
    return out
