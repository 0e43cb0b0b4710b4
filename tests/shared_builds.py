"""Designs built once per test process and shared by every test that reads them (issue #33).

``joint_build(p)`` is ``rjcad.cad.build.build(p)`` kept by the parameters (``finger_build(template)`` the same
for a finger); ``joint_files(p)`` writes the
``joint.stl`` and ``joint.json`` of ``p`` once, the bytes ``write_joint`` writes (no STEP, 3MF, GLB or PNG: no
check reads them), from the kept build if there is one, else from a build it drops; ``checked(stl, manifest,
slicer=...)`` is ``rjcad.check.run_checks`` kept by the sha256 of the bytes it reads and its arguments, so that
two tests checking the same joint slice it once (a test-side stand-in for a G-code cache). Under pytest-xdist
each worker keeps its own. What they return is shared: read it, never change it.
"""

from __future__ import annotations

import atexit
import hashlib
import json
import shutil
import tempfile
from pathlib import Path

#: repr(JointParams) → JointBuild; repr → directory holding joint.stl and joint.json; digest → Report.
_BUILDS: dict = {}
_FILES: dict = {}
_REPORTS: dict = {}
#: Designs this process built here, times a test got one already built; reports run, times one was handed out again.
STATS = {"built": 0, "reused": 0, "checked": 0, "check reused": 0}


def joint_build(p):
    """The built joint of ``p`` (``rjcad.cad.build.build``), built on the first call only."""
    from rjcad.cad.build import build

    key = repr(p)
    if key in _BUILDS:
        STATS["reused"] += 1
    else:
        _BUILDS[key] = build(p)
        STATS["built"] += 1
    return _BUILDS[key]


def finger_build(template: dict):
    """The built finger of ``template`` (a finger template as a dict; ``build_finger_model``), built on the first
    call only."""
    from rjcad.cad.build import build_finger_model
    from rjcad.design.finger_params import FingerParams

    key = "finger " + repr(sorted(template.items()))
    if key in _BUILDS:
        STATS["reused"] += 1
    else:
        _BUILDS[key] = build_finger_model(FingerParams.from_dict(template))
        STATS["built"] += 1
    return _BUILDS[key]


def joint_files(p) -> Path:
    """A directory holding the joint of ``p`` as ``joint.stl`` and ``joint.json``, written on the first call only."""
    from rjcad.cad.mesh_export import stl_bytes

    key = repr(p)
    if key not in _FILES:
        b = _BUILDS.get(key)  # kept only when a test asked joint_build for it: the files are enough here
        if b is None:
            from rjcad.cad.build import build

            b = build(p)
            STATS["built"] += 1
        else:
            STATS["reused"] += 1
        d = Path(tempfile.mkdtemp(prefix="rjcad-shared-"))
        atexit.register(shutil.rmtree, d, True)
        (d / "joint.stl").write_bytes(stl_bytes(list(b.meshes.values())))
        (d / "joint.json").write_text(json.dumps(b.manifest.to_json(), indent=2) + "\n")
        _FILES[key] = d
    return _FILES[key]


def checked(stl, manifest=None, **kwargs):
    """``run_checks(stl, manifest=manifest, **kwargs)`` on files, run once per content and arguments."""
    from rjcad.check import run_checks

    digest = hashlib.sha256()
    for path in (stl, manifest):
        digest.update(Path(path).read_bytes() if path is not None else b"-")
        digest.update(b"\0")
    digest.update(repr(sorted(kwargs.items())).encode())
    key = digest.hexdigest()
    if key in _REPORTS:
        STATS["check reused"] += 1
    else:
        STATS["checked"] += 1
        _REPORTS[key] = run_checks(str(stl), manifest=None if manifest is None else str(manifest), **kwargs)
    return _REPORTS[key]
