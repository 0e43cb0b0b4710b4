"""`rjcad check` keeps stderr clean on meshes with degenerate (zero-area) or duplicated triangles: nothing on stderr
when the checks ran (pass or fail), one `rjcad: error:` line on bad input. trimesh warned there (its centre of mass
divides by the volume, the ray cones divided by a zero normal's length) and the warnings reached the terminal."""

import json

import numpy as np
import pytest
import trimesh
from mesh_tools import box
from test_check import hinge, manifest_for


def needle(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """The mesh, still closed, with a zero-area triangle: face (a, b, c) split at the midpoint m of a–b into
    (a, m, c) and (m, b, c), and the sliver (a, b, m) taking the edge a–b."""
    v, f = mesh.vertices, mesh.faces
    a, b, c = f[0]
    m = len(v)
    return trimesh.Trimesh(
        np.vstack([v, (v[a] + v[b]) / 2]), np.vstack([f[1:], [[a, m, c], [m, b, c], [a, b, m]]]), process=False
    )


def cube() -> trimesh.Trimesh:
    return box((0, 0, 0), (10, 10, 10))


def broken(case: str) -> trimesh.Trimesh:
    """A 10 mm cube damaged with degenerate or duplicated triangles (open or flat: some checks fail)."""
    c = cube()
    v, f = c.vertices, c.faces
    if case == "collinear":  # a zero-area triangle on an edge's midpoint
        return trimesh.Trimesh(np.vstack([v, (v[0] + v[1]) / 2]), np.vstack([f, [[0, 1, len(v)]]]), process=False)
    if case == "repeated_vertex":
        return trimesh.Trimesh(v, np.vstack([f, [[0, 0, 1]]]), process=False)
    if case == "duplicated_face":
        return trimesh.Trimesh(v, np.vstack([f, f[:1]]), process=False)
    if case == "all_duplicated":  # every body split off it is open or has no volume
        return trimesh.Trimesh(v, np.vstack([f, f]), process=False)
    assert case == "flat"  # nothing but one degenerate triangle
    return trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]], process=False)


def run(cli_process, path, *args):
    r = cli_process("check", str(path), *args, "--json")
    return r.returncode, r.stdout, r.stderr


@pytest.mark.parametrize("case", ["collinear", "repeated_vertex", "duplicated_face", "all_duplicated", "flat"])
@pytest.mark.parametrize("suffix", [".stl", ".3mf"])
def test_degenerate_or_duplicated_triangles_leave_stderr_empty(case, suffix, tmp_path, cli_process):
    path = tmp_path / f"{case}{suffix}"
    broken(case).export(str(path))
    code, out, err = run(cli_process, path)
    assert err == "", err
    assert code == 1, out  # a check failed (not bad input, not a crash)
    assert json.loads(out)["passed"] is False


def test_a_closed_mesh_with_a_zero_area_triangle_runs_every_check_silently(tmp_path, cli_process):
    bodies = hinge()
    bodies["ground"] = needle(bodies["ground"])
    path, man = tmp_path / "needle.stl", tmp_path / "needle.json"
    trimesh.util.concatenate(list(bodies.values())).export(str(path))
    man.write_text(json.dumps(manifest_for(bodies)))
    code, out, err = run(cli_process, path, "--manifest", str(man))
    assert err == "", err
    ran = {c["name"]: c["passed"] for c in json.loads(out)["checks"]}
    assert ran["watertight"] and ran["manifold"] and ran["clearance"] and ran["motion"], out
    assert ran["min_feature"] is not None and code in (0, 1)


def test_bad_input_on_a_degenerate_mesh_is_one_error_line(tmp_path, cli_process):
    path, man = tmp_path / "dup.stl", tmp_path / "dup.json"
    broken("all_duplicated").export(str(path))
    man.write_text(json.dumps({"bodies": [{"name": "cube", "volume_mm3": 1000.0}], "clearance_mm": 0.25}))
    code, out, err = run(cli_process, path, "--manifest", str(man))
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and err.startswith("rjcad: error: "), err
