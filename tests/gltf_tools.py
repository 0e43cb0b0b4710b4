"""The Khronos glTF validator (npm package ``gltf-validator``) for the tests, and a GLB read back by body.

The validator is installed once with npm into ``~/.cache/rjcad-tests/gltf-validator`` (``$XDG_CACHE_HOME`` if set),
under a file lock so that test workers do not install it twice; a test that needs it is skipped, with the reason,
when node or npm is missing or the install fails (no network). ``tests/gltf_validate.js`` runs it.
"""

from __future__ import annotations

import fcntl
import io
import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

#: The validator's npm release (the newest: 2.0.0-dev.3.10, Khronos glTF-Validator compiled to JavaScript).
VALIDATOR = "gltf-validator@2.0.0-dev.3.10"
SCRIPT = Path(__file__).resolve().parent / "gltf_validate.js"


def validator_dir() -> Path:
    """The folder holding ``node_modules/gltf-validator`` (installed on first use); skips the test without npm."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("node or npm not installed (apt-get install npm): the glTF validator comes from the npm registry")
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "rjcad-tests"
    folder = cache / VALIDATOR.replace("@", "-")
    cache.mkdir(parents=True, exist_ok=True)
    with open(cache / "gltf-validator.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / "node_modules" / "gltf-validator" / "package.json").is_file():
            run = subprocess.run(
                [npm, "install", "--prefix", str(folder), "--no-audit", "--no-fund", VALIDATOR],
                capture_output=True,
                text=True,
                timeout=300,
            )
            if run.returncode != 0:
                pytest.skip(f"npm install {VALIDATOR} failed: {run.stderr.strip()[-300:]}")
    return folder


def validate(*files: Path) -> dict[str, dict]:
    """The validator's report of each file (every issue listed), by file name."""
    run = subprocess.run(
        ["node", str(SCRIPT), str(validator_dir()), *map(str, files)],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    return {Path(k).name: v for k, v in json.loads(run.stdout).items()}


def counts(report: dict) -> dict[str, int]:
    """Errors, warnings, infos and hints of one report."""
    issues = report["issues"]
    return {k: issues[f"num{k.capitalize()}"] for k in ("errors", "warnings", "infos", "hints")}


def glb_bodies(data: bytes) -> tuple[dict, dict]:
    """A GLB's JSON and its nodes' meshes (trimesh, in the file's frame and units), by node name."""
    import trimesh

    from rjcad.cad.mesh_export import glb_json_chunk

    doc = json.loads(glb_json_chunk(data))
    scene = trimesh.load(io.BytesIO(data), file_type="glb", process=False)
    meshes = {}
    for node in doc["nodes"]:
        matrix, geometry = scene.graph[node["name"]]
        assert np.allclose(matrix, np.eye(4)), node["name"]  # the vertices hold the frame: no node transform
        meshes[node["name"]] = scene.geometry[geometry]
    return doc, meshes
