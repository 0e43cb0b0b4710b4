"""rjcad check on purpose-made meshes: each broken one must fail the right check, with a location."""

import json
import math
import shutil

import numpy as np
import pytest
import trimesh
from mesh_tools import box, cyl, difference, union

from rjcad.check import BadInput, run_checks


def hinge(obstacle=False):
    """A print-in-place hinge: a plate with a pin (ground) and a tube with an arm (moving)."""
    ground = union(box((-12, -12, 0), (12, 12, 2)), cyl(2.0, 0, 14))
    if obstacle:  # a post on the plate, in the arm's path at 60°
        a = math.radians(60)
        ground = union(ground, cyl(1.5, 0, 12, 11 * math.cos(a), 11 * math.sin(a)))
    tube = difference(cyl(5.0, 2.4, 12), cyl(2.25, 2.0, 12.5))
    moving = union(tube, box((4, -2, 2.4), (16, 2, 12)))
    return {"ground": ground, "moving": moving}


def manifest_for(bodies, rotation=90.0, joint=True):
    man = {
        "bodies": [{"name": n, "volume_mm3": float(m.volume)} for n, m in bodies.items()],
        "clearance_mm": 0.25,
        "printer": "generic-0.4",
    }
    if joint:
        man.update(
            {"moving_body": "moving", "axis_point_mm": [0, 0, 0], "axis_dir": [0, 0, 1], "rotation_deg": rotation}
        )
    return man


def write(tmp_path, bodies, name="mesh", joint=True):
    path = tmp_path / f"{name}.stl"
    trimesh.util.concatenate(list(bodies.values())).export(str(path))
    man = tmp_path / f"{name}.json"
    man.write_text(json.dumps(manifest_for(bodies, joint=joint)))
    return path, man


def failed(rep):
    return [c.name for c in rep.checks if c.passed is False]


def test_stacked_hinge_passes_every_check_but_overhang(tmp_path):
    path, man = write(tmp_path, hinge())
    rep = run_checks(path, manifest=man)
    assert failed(rep) == ["overhang"], [(c.name, c.detail) for c in rep.checks if c.passed is False]
    assert rep.get("clearance").value == pytest.approx(0.25, abs=0.005)
    assert rep.get("motion").passed is True and "poses" in rep.get("motion").detail
    assert rep.get("bodies").value == 2 and "matched to the manifest's bodies by volume" in rep.get("bodies").detail
    assert rep.get("slicer").passed is None and "skipped" in rep.get("slicer").detail
    # the tube and its arm start 0.4 mm above the plate: they would print onto it
    o = rep.get("overhang")
    assert "moving, other body" in o.detail and "ground 0.40 mm below" in o.detail
    assert o.where[2] == pytest.approx(2.4) and np.hypot(*o.where[:2]) <= 12 * math.sqrt(2)


def test_printable_pair_passes_everything(tmp_path):
    from test_check_print import printable_pair

    parts = printable_pair()
    path, man = write(tmp_path, parts, joint=False)
    rep = run_checks(path, manifest=man)
    assert rep.passed, [(c.name, c.detail) for c in rep.checks if c.passed is False]
    assert rep.get("overhang").passed is True


def test_hole_fails_watertight_with_its_location(tmp_path):
    b = hinge()
    g = b["ground"]
    # punch a hole: drop the faces near the top of the pin
    centres = g.triangles_center
    keep = ~(centres[:, 2] > 13.99)  # the pin's top cap
    g.update_faces(keep)
    g.remove_unreferenced_vertices()
    rep = run_checks(b)
    assert "watertight" in failed(rep)
    where = np.array(rep.get("watertight").where)
    assert abs(where[2] - 14.0) < 0.2 and np.linalg.norm(where[:2]) < 2.1


def test_bodies_too_close_fail_clearance_between_them():
    a, b = box((0, 0, 0), (10, 10, 10)), box((10.1, 0, 0), (20, 10, 10))
    rep = run_checks({"a": a, "b": b}, clearance=0.25)
    assert failed(rep) == ["clearance"]
    c = rep.get("clearance")
    assert c.value == pytest.approx(0.1, abs=1e-3) and c.limit == pytest.approx(0.23)
    assert 9.9 < c.where[0] < 10.2


def test_overlapping_bodies_fail_clearance():
    a, b = box((0, 0, 0), (10, 10, 10)), box((9, 2, 2), (20, 8, 8))
    rep = run_checks({"a": a, "b": b}, clearance=0.25)
    c = rep.get("clearance")
    assert c.passed is False and "overlap" in c.detail
    assert 9 <= c.where[0] <= 10 and 2 <= c.where[1] <= 8


def test_thin_wall_fails_min_feature_at_the_wall():
    body = union(box((0, 0, 0), (20, 20, 4)), box((9.9, 0, 4), (10.1, 20, 12)))  # a 0.2 mm fin
    rep = run_checks({"part": body}, printer="generic-0.4")
    c = rep.get("min_feature")
    assert c.passed is False and "wall" in c.detail
    assert c.value == pytest.approx(0.2, abs=0.03) and c.limit == 0.8
    assert 9.8 <= c.where[0] <= 10.2 and c.where[2] >= 4


def test_narrow_gap_inside_a_body_fails_min_feature():
    body = union(box((0, 0, 0), (20, 20, 2)), box((0, 0, 2), (9.95, 20, 10)), box((10.05, 0, 2), (20, 20, 10)))
    rep = run_checks({"part": body}, printer="generic-0.4")
    c = rep.get("min_feature")
    assert c.passed is False and "gap" in c.detail and c.value == pytest.approx(0.1, abs=0.02)


def test_collision_at_60_degrees_fails_motion(tmp_path):
    b = hinge(obstacle=True)
    path, man = write(tmp_path, b)
    rep = run_checks(path, manifest=man)
    c = rep.get("motion")
    assert c.passed is False
    assert 40 <= c.value <= 62  # the arm (2 mm half-width, 16 mm long) meets the post at 60°
    assert "first contact at joint 1, 4" in c.detail  # the arm's edge reaches the post ≈ 18° before its centre line
    ang = math.degrees(math.atan2(c.where[1], c.where[0]))
    assert 45 <= ang <= 70
    assert rep.get("clearance").passed  # at rest all is well: only the sweep finds it


def test_too_big_for_the_bed():
    rep = run_checks({"slab": box((0, 0, 0), (300, 50, 5))}, printer="generic-0.4")
    c = rep.get("bed")
    assert c.passed is False and c.value[0] == pytest.approx(300)


def test_bed_accepts_swapped_xy_and_reports_lift():
    rep = run_checks({"slab": box((0, 0, 3), (50, 210, 8))}, printer="dimension-elite")
    assert rep.get("bed").passed is False  # 210 > 203 either way
    rep = run_checks({"slab": box((0, 0, 3), (50, 200, 8))}, printer="dimension-elite")
    c = rep.get("bed")
    assert c.passed and "move it by" in c.detail


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer not installed")
def test_slicer_passes_a_printable_mesh_and_fails_one_it_cannot_slice():
    from test_check_print import printable_pair

    good = run_checks(printable_pair(), slicer="prusa")
    s = good.get("slicer")
    assert s.passed is True and s.value == 0 and "PrusaSlicer" in s.detail and "supports off" in s.detail
    bad = run_checks({"slab": box((0, 0, 0), (300, 300, 5))}, slicer="prusa")
    s = bad.get("slicer")
    assert s.passed is False and "fit" in s.detail.lower()


def test_slicer_missing_is_skipped_never_passed(monkeypatch):
    import rjcad.check.slicer as chk

    monkeypatch.setattr(chk.shutil, "which", lambda name: None)
    rep = run_checks(hinge(), slicer="prusa")
    s = rep.get("slicer")
    assert s.passed is None and "not installed" in s.detail


def test_cli_exit_codes_and_json(tmp_path, cli):
    from test_check_print import printable_pair

    path, man = write(tmp_path, printable_pair(), joint=False)
    code, out, _ = cli(["check", str(path), "--manifest", str(man), "--json"])
    assert code == 0, out
    d = json.loads(out)
    assert d["passed"] is True
    assert {c["name"] for c in d["checks"]} == {
        "watertight",
        "manifold",
        "bodies",
        "clearance",
        "motion",
        "min_feature",
        "bed",
        "overhang",
        "slicer",
    }
    for c in d["checks"]:
        assert set(c) >= {"name", "passed", "value", "limit", "where", "detail"}
    bpath, bman = write(tmp_path, hinge(obstacle=True), "bad")
    code, out, _ = cli(["check", str(bpath), "--manifest", str(bman)])
    assert code == 1 and "FAIL" in out and "motion" in out
    code, _, _ = cli(["check", str(path), "--bodies", "3"])
    assert code == 1


@pytest.mark.parametrize("case", ["missing", "text", "empty", "manifest"])
def test_bad_input_exit_2_one_line(case, tmp_path, cli):
    path, man = write(tmp_path, hinge())
    args = [str(path)]
    if case == "missing":
        args = [str(tmp_path / "nope.stl")]
    elif case == "text":
        t = tmp_path / "notes.stl"
        t.write_text("these are my notes, not a mesh\n" * 20)
        args = [str(t)]
    elif case == "empty":
        e = tmp_path / "empty.stl"
        e.write_bytes(b"\0" * 80 + (0).to_bytes(4, "little"))
        args = [str(e)]
    else:
        m = json.loads(man.read_text())
        m["bodies"].append({"name": "tendon_guide", "volume_mm3": 1234.0})
        man.write_text(json.dumps(m))
        args = [str(path), "--manifest", str(man)]
    code, out, err = cli(["check", *args])
    assert code == 2, (out, err)
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_3mf_names_are_used(tmp_path):
    b = hinge()
    scene = trimesh.Scene()
    for n, m in b.items():
        scene.add_geometry(m, node_name=n, geom_name=n)
    p = tmp_path / "h.3mf"
    p.write_bytes(scene.export(file_type="3mf"))
    rep = run_checks(p, manifest=manifest_for(b))
    assert sorted(rep.body_names) == ["ground", "moving"] and failed(rep) == ["overhang"]
    assert "3MF" in rep.get("bodies").detail


def test_api_rejects_empty_input():
    with pytest.raises(BadInput):
        run_checks([])
