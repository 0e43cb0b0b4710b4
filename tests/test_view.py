"""`rjcad view`'s pieces (which joints move which body, the tendon's owners, its errors) and what each command
imports (a command pays only for what it needs). The page itself is tested in Chromium in test_finger.py."""

import json
import re
import subprocess
import sys

import pytest

from rjcad.errors import RjcadError
from rjcad.view import SAME_FRAME, chains, glb_frame, tendon_owner

JOINTS = [
    {"parent": "base", "child": "link1", "axis_point_mm": [0.0, 0, 0], "axis_dir": [0, 0, 1]},
    {"parent": "link1", "child": "link2", "axis_point_mm": [40.0, 0, 0], "axis_dir": [0, 0, 1]},
    {"parent": "link2", "child": "distal", "axis_point_mm": [80.0, 0, 0], "axis_dir": [0, 0, 1]},
]


def test_each_body_moves_with_the_joints_between_the_root_and_it():
    assert chains(JOINTS) == {"base": [], "link1": [0], "link2": [0, 1], "distal": [0, 1, 2]}
    shuffled = [JOINTS[2], JOINTS[0], JOINTS[1]]  # the manifest's order does not matter
    assert chains(shuffled) == {"base": [], "link1": [1], "link2": [1, 2], "distal": [1, 2, 0]}


def test_tendon_points_move_with_the_body_they_run_through():
    path = [[-20.0, 6, 5], [-0.5, 6, 5], [0.5, 6, 5], [39.0, 6, 5], [41.0, 6, 5], [120.0, 6, 5]]
    assert tendon_owner(path, JOINTS) == ["base", "base", "link1", "link1", "link2", "distal"]


def test_view_refuses_a_manifest_without_its_glb(cli, tmp_path, root):
    man = tmp_path / "finger.json"
    man.write_text((root / "tests" / "data" / "manifest_v0_finger.json").read_text())
    r = cli("view", str(man), "--out", str(tmp_path / "page"))
    assert r.code == 2 and r.err.count("\n") == 1 and r.err.startswith("rjcad: error:"), r.err
    assert "finger.glb: not found" in r.err
    assert not (tmp_path / "page").exists()


def test_the_page_takes_the_glbs_frame_from_the_glb():
    """The map from the manifest's frame (mm, +Z up) into the GLB's is what the GLB's asset.extras state (metres,
    +Y up); an rjcad GLB written before it stated one (trimesh's, mm, +Z up) is in the manifest's frame."""
    import numpy as np
    import trimesh

    from rjcad.cad.mesh_export import GLTF_FRAME, glb_bytes

    box = trimesh.creation.box((10, 10, 10))
    frame = glb_frame(glb_bytes({"base": box}))
    assert frame == GLTF_FRAME["source_to_gltf_matrix"]
    m = np.array(frame).reshape(4, 4).T  # column-major, as three.js's Matrix4.fromArray reads it
    assert np.allclose(m @ [0, 0, 1000, 1], [0, 1, 0, 1]) and np.allclose(m @ [1000, 0, 0, 1], [1, 0, 0, 1])
    older = trimesh.Scene({"base": box}).export(file_type="glb")
    assert glb_frame(older) == SAME_FRAME


@pytest.mark.parametrize(
    "damage, why",
    [
        (lambda g: g[:40], "not a GLB (its header is not that of a glTF 2 binary of its length)"),
        (lambda g: g[:20] + b"[" + g[21:], "not valid JSON (Expecting"),  # its JSON broken
        (lambda g: g.replace(b'"source_to_gltf_matrix":[0.001', b'"source_to_gltf_matrix":["xyz"'), "16 finite"),
    ],
)
def test_view_refuses_a_damaged_glb_in_one_line(cli, tmp_path, root, damage, why):
    """A GLB cut short, with broken JSON or a frame that is not 16 numbers: one error line naming it, no page."""
    import trimesh

    from rjcad.cad.mesh_export import glb_bytes

    man = tmp_path / "finger.json"
    man.write_text((root / "tests" / "data" / "manifest_v0_finger.json").read_text())
    (tmp_path / "finger.glb").write_bytes(damage(glb_bytes({"base": trimesh.creation.box((10, 10, 10))})))
    with pytest.raises(RjcadError, match=re.escape(why)):  # ViewerError, or the JSON reader's
        glb_frame((tmp_path / "finger.glb").read_bytes())
    r = cli("view", str(man), "--out", str(tmp_path / "page"))
    assert r.code == 2 and r.err.count("\n") == 1 and r.err.startswith("rjcad: error:"), r.err
    assert f"{tmp_path / 'finger.glb'}: " in r.err and why in r.err
    assert not (tmp_path / "page").exists()


@pytest.mark.parametrize("option, value", [("--stroke", "0"), ("--stroke", "nan"), ("--mu-t", "5")])
def test_view_refuses_bad_options_naming_them(cli, tmp_path, option, value):
    r = cli("view", str(tmp_path / "finger.json"), option, value)
    assert r.code == 2 and option in r.err and r.err.count("\n") == 1, r.err


IMPORTS = """
import json, sys
from rjcad.cli import main
try:
    main(sys.argv[2:])
except SystemExit as e:
    assert e.code == 0, e.code
top = sorted({m.split(".")[0] for m in sys.modules})
open(sys.argv[1], "w").write(json.dumps(top))
"""


def imported(root, tmp_path, *argv) -> set[str]:
    """Top-level packages a new process has imported after running `rjcad ARGV`."""
    out = tmp_path / "modules.json"
    subprocess.run(
        [sys.executable, "-c", IMPORTS, str(out), *argv], cwd=root, check=True, capture_output=True, timeout=120
    )
    return set(json.loads(out.read_text()))


HEAVY = {"OCP", "vtk", "vtkmodules", "matplotlib", "trimesh", "manifold3d"}


@pytest.mark.fast_lane
def test_light_commands_import_no_cad_no_plotting(root, tmp_path):
    """Fast lane on purpose (about 3 s: two short processes): the import budget of the quick commands is what
    a refactor breaks without noticing."""
    spring = imported(root, tmp_path, "spring", "--config", "templates/spring.toml", "--json")
    # scipy, yes: the rod model's banded solve is scipy.linalg.lapack's dgbsv (rjcad.spring.banded)
    assert not spring & HEAVY, spring & HEAVY
    sim = imported(root, tmp_path, "simulate", "finger", "--json")
    # numba, yes: the finger's one solver is compiled (rjcad.physics.finger_path); numba's import loads scipy
    assert not sim & HEAVY, sim & HEAVY
    # the joint's relaxation filter loads scipy.signal only when a relaxation time is given (1.1 s)
    joint = imported(root, tmp_path, "simulate", "joint", "--rotation", "90", "--json")
    assert not joint & (HEAVY | {"scipy", "numba"}), joint & (HEAVY | {"scipy", "numba"})


def test_the_joint_build_imports_no_matplotlib_and_check_no_cad(root, tmp_path):
    """The preview is VTK's: building and rendering a joint loads OpenCASCADE and VTK but no matplotlib;
    checking it loads no CAD kernel, VTK or matplotlib."""
    mods = imported(root, tmp_path, "joint", "--out", str(tmp_path / "joint"))
    assert "OCP" in mods and "vtkmodules" in mods and not mods & {"cadquery", "matplotlib"}
    assert (tmp_path / "joint" / "joint.png").stat().st_size > 10_000
    check = imported(
        root,
        tmp_path,
        "check",
        str(tmp_path / "joint" / "joint.3mf"),
        "--manifest",
        str(tmp_path / "joint" / "joint.json"),
    )
    assert "trimesh" in check and not check & {"OCP", "vtk", "vtkmodules", "matplotlib"}
