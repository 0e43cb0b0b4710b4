"""Digest of rjcad's deterministic outputs, to show that a refactor changes none of them.

Runs the commands whose outputs are promised byte-identical across a behaviour-preserving change
(`make demo`'s finger, `rjcad joint`, `rjcad spring --json`, `rjcad identify` on the example
campaign, `rjcad life --json`) into a temporary folder and prints one JSON object: file → sha256.

    python tools/output_digest.py > before.json   # on the old commit
    python tools/output_digest.py > after.json    # on the new one
    diff before.json after.json                   # no output: byte-identical

``--v0-manifests`` digests manifests as schema version 0 wrote them (see ``_as_v0``), to compare
across the change that introduced ``rjcad.io.manifest`` (version 1).

The temporary folder's path is replaced by `{tmp}` in what the commands print. Where
OpenCASCADE's parallel booleans and meshing are not deterministic from run to run (the same
triangles in another order, coordinates that differ by 1e-17 mm), the digest compares what is:
an STL's triangles sorted, coordinates to 1e-6 mm; a STEP file without its header's FILE_NAME
(a date and a path), numbers to 1e-9; a 3MF by each object's name and sorted triangles (its zip
holds dates and its XML random UUIDs). A PNG is compared by its pixels, so that dropping the
matplotlib version from its metadata is not a change. Everything else is byte for byte.
"""

from __future__ import annotations

import hashlib
import io
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = {
    "finger": ["finger", "templates/finger.toml", "--out", "{tmp}/finger"],
    "joint": ["joint", "--out", "{tmp}/joint"],
    "spring": ["spring", "--config", "templates/spring.toml", "--json"],
    "spring_clamped": [
        "spring",
        "--stiffness",
        "8",
        "--rotation",
        "60",
        "--preload",
        "45",
        "--end",
        "clamped",
        "--material",
        "petg",
        "--json",
    ],
    "spring_table": ["spring", "--config", "templates/spring.toml"],
    "identify": [
        "identify",
        "examples/paper_campaign/campaign.toml",
        "--json",
        "{tmp}/identify.json",
        "--report",
        "{tmp}/identify",
    ],
    "life": ["life", "--json"],
}

_STEP_HEADER = re.compile(rb"FILE_NAME\([^;]*;", re.S)
_FLOAT = re.compile(rb"-?\d+\.\d*(?:E[-+]?\d+)?")


def _sorted_triangles(v) -> bytes:
    rows = np.round(np.asarray(v, dtype=np.float64), 6) + 0.0
    return rows[np.lexsort(rows.T[::-1])].tobytes()


def _round(m: re.Match) -> bytes:
    return b"%.9g" % (round(float(m.group()), 9) + 0.0)


def _as_v0(data: bytes) -> bytes:
    """A manifest as schema version 0 wrote it: without ``schema_version`` (and, for a joint, its
    ``joints`` list), the measured gap to 1e-6 mm (float32 → float64 meshes moved it by 1e-7)."""
    m = json.loads(data)
    if not isinstance(m, dict) or "bodies" not in m:
        return data
    if m.pop("schema_version", None) is not None and "moving_body" in m:
        m.pop("joints", None)
    if "measured_min_gap_mm" in m:
        m["measured_min_gap_mm"] = round(m["measured_min_gap_mm"], 6)
    return (json.dumps(m, indent=2) + "\n").encode()


def digest(data: bytes, name: str, v0: bool = False) -> str:
    """sha256 of a file's bytes, after the normalisations above."""
    if v0 and name.endswith(".json"):
        data = _as_v0(data)
    if name.endswith(".step"):
        data = _STEP_HEADER.sub(b"FILE_NAME();", data)
        data = _FLOAT.sub(_round, data)
    if name.endswith(".png"):
        with Image.open(io.BytesIO(data)) as im:
            data = f"{im.mode} {im.size}".encode() + im.tobytes()
    if name.endswith(".stl"):
        tri = np.frombuffer(data[84:], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", 9), ("a", "<u2")]))
        data = data[:84] + _sorted_triangles(tri["v"])
    if name.endswith(".3mf"):
        scene = trimesh.load(io.BytesIO(data), file_type="3mf", process=False)
        data = b"".join(
            n.encode() + _sorted_triangles(g.triangles.reshape(-1, 9)) for n, g in sorted(scene.geometry.items())
        )
    return hashlib.sha256(data).hexdigest()


def main() -> None:
    v0 = "--v0-manifests" in sys.argv[1:]
    out: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for key, args in COMMANDS.items():
            argv = [sys.executable, "-m", "rjcad", *(a.format(tmp=tmp) for a in args)]
            run = subprocess.run(argv, cwd=ROOT, capture_output=True, check=True)
            out[f"{key}:stdout"] = digest(run.stdout.replace(tmp.encode(), b"{tmp}"), "")
        for f in sorted(Path(tmp).rglob("*")):
            if f.is_file():
                out[str(f.relative_to(tmp))] = digest(f.read_bytes(), f.name, v0)
    json.dump(out, sys.stdout, indent=1, sort_keys=True)
    print()


if __name__ == "__main__":
    main()
