"""``rjcad simulate finger --object``, a template's ``[[object]]`` tables and ``rjcad.grasp``: the closure on
objects at the command line and in the API (a one-joint finger, a few readings: fast)."""

from __future__ import annotations

import json

import pytest

import rjcad

ONE_JOINT = """material = "absplus-p430"
printer = "generic-0.4"
[[joint]]
stiffness_nmm_per_rad = 5.2
preload_deg = 90
link_length_mm = 44
"""
CYL = "cylinder:diameter=20,x=30,y=25,mu=0.3"
STEPS = ("--steps", "10")


@pytest.fixture
def one(tmp_path):
    path = tmp_path / "one.toml"
    path.write_text(ONE_JOINT)
    return path


@pytest.fixture
def run(cli):
    """``rjcad simulate finger ARGS…`` in this process."""
    return lambda *args: cli("simulate", "finger", *args)


def test_one_object_json_keys_and_types(run, one):
    r = run(one, "--object", CYL, "--json", *STEPS)
    assert r.code == 0, r.err
    out = json.loads(r.out)
    n = len(out["tension_n"])
    assert n == 10 and out["tension_n"][0] == 0.0 and out["tension_n"][-1] == pytest.approx(10.0)
    assert len(out["theta_deg"]) == len(out["tendon_mm"]) == len(out["contacts"]) == n
    final = out["contacts"][-1]
    assert [c["body"] for c in final] == ["link1"]
    for key, kind in (("point_mm", list), ("normal_force_n", float), ("tangential_force_n", float)):
        assert isinstance(final[0][key], kind)
    assert final[0]["normal_force_n"] > 0
    g = out["grasp"]
    assert g["phalanges_in_contact"] == [1] and g["enveloping"] is True and g["ejected"] is False
    assert g["max_tension_n"] == pytest.approx(10.0)
    assert isinstance(g["quality"]["epsilon"], float) and "Ferrari-Canny" in g["quality"]["definition"]


def test_two_objects_text_and_max_tension(run, one):
    r = run(one, "--object", CYL, "--object", "box:w=10,h=10,x=120,y=0", "--max-tension", "4", *STEPS)
    assert r.code == 0, r.err
    assert "object 1: cylinder 20 mm at (30, 25) mm, fixed, μ 0.3; touched by link1" in r.out
    assert "object 2: box 10 × 10 mm at (120, 0) mm, fixed, μ 0; touched by nothing" in r.out
    assert "tension 4.00 N" in r.out and "link1 on object 1 at (" in r.out
    assert "enveloping yes, ejected no, ε = " in r.out


def test_template_objects_and_the_stroke_stop(run, one, tmp_path):
    one.write_text(ONE_JOINT + '[[object]]\nkind = "cylinder"\ndiameter_mm = 20\nx_mm = 30\ny_mm = 25\n')
    r = run(one, "--json", *STEPS)
    assert r.code == 0, r.err
    full = json.loads(r.out)
    assert full["object_specs"] == [
        {"kind": "cylinder", "diameter_mm": 20.0, "x_mm": 30.0, "y_mm": 25.0, "mu": 0.0, "free": False}
    ]
    both = json.loads(run(one, "--object", "box:w=10,h=10,x=120,y=0", "--json", *STEPS).out)
    assert [o["kind"] for o in both["object_specs"]] == ["cylinder", "box"]  # --object adds to the template's
    stop = full["tendon_mm"][3] - 1e-9
    short = json.loads(run(one, "--json", "--stroke", stop, *STEPS).out)
    n = len(short["tendon_mm"])
    assert n < len(full["tendon_mm"]) and short["tendon_mm"] == full["tendon_mm"][:n]  # the same ramp, cut short
    assert short["tendon_mm"][-1] >= stop > max(short["tendon_mm"][:-1])


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("--object", "sphere:diameter=20,x=1,y=2"), "--object"),
        (("--object", "cylinder:diameter=nan,x=30,y=25"), "--object diameter"),
        (("--object", "cylinder:x=30,y=25"), "needs diameter"),
        (("--object", "cylinder:diameter=20,x=30,y=25,x=4"), "x is given twice"),
        (("--object", "cylinder:diameter=1e9,x=30,y=25"), "cylinder diameter"),
        (("--object", "cylinder:diameter=20,x=30,y=25,free"), "cylinder mass"),
        (("--object", CYL, "--max-tension", "0"), "--max-tension"),
        (("--max-tension", "5"), "--max-tension"),
    ],
)
def test_bad_input_is_one_line_exit_2(run, one, args, named):
    r = run(one, *args)
    assert r.code == 2, r.err
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rjcad: error: ") and named in lines[0], r.err


def test_bad_template_object_is_refused_on_load(run, one):
    one.write_text(ONE_JOINT + '[[object]]\nkind = "cylinder"\ndiameter_mm = 20\nx_mm = 30\ny_mm = 25\nz_mm = 1\n')
    r = run(one, "--json")
    assert r.code == 2 and "one.toml: object[1].z_mm" in r.err
    with pytest.raises(rjcad.ParameterError, match=r"object\[1\]\.z_mm"):
        rjcad.finger_params(one)


def test_plot_writes_a_png(run, one, tmp_path):
    png = tmp_path / "g.png"
    r = run(one, "--object", CYL, "--object", "box:w=8,h=6,x=60,y=20,angle=30", "--plot", png, *STEPS)
    assert r.code == 0, r.err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


def test_api_grasp_of_a_file_and_the_objects(run, one):
    box = rjcad.Box(120, 0, 10, 10, angle_deg=90)
    assert box.angle == pytest.approx(1.5707963267948966) and box.corners()[0] == pytest.approx([125, -5])
    g = rjcad.grasp(one, [rjcad.Cylinder(30, 25, diameter=20, mu=0.3), box], steps=10)
    assert isinstance(g, rjcad.Grasp) and g.verdict().enveloping and g.touch_order == [1]
    cli = json.loads(run(one, "--object", CYL, "--object", "box:w=10,h=10,x=120,y=0,angle=90", "--json", *STEPS).out)
    assert g.to_dict()["theta_deg"] == cli["theta_deg"]  # the API is the command's closure
    with pytest.raises(rjcad.ParameterError, match="objects"):
        rjcad.grasp(one, ["cylinder:diameter=20,x=30,y=25"], steps=10)  # type: ignore[list-item]


def test_compare_differences_are_zero_for_the_same_closure(run, one):
    from rjcad.physics.grasp_run import compare_grasps

    g = rjcad.grasp(one, rjcad.Cylinder(30, 25, diameter=20), steps=10)
    other = rjcad.grasp(one, rjcad.Cylinder(30, 25, diameter=20), steps=10, max_tension_n=20.0)
    other.engine = "mujoco"
    d = compare_grasps(g, other)
    assert d["contact_sets"] == {"rjcad": ["link1/object1"], "mujoco": ["link1/object1"], "same": True}
    f = d["normal_forces"][0]
    assert f["mujoco_normal_force_n"] > f["rjcad_normal_force_n"] > 0  # a harder pull presses harder
    assert f["difference_n"] == pytest.approx(f["mujoco_normal_force_n"] - f["rjcad_normal_force_n"])
    assert d["max_abs_theta_deg"] >= 0 and len(d["theta_deg"]) == 1


def test_mujoco_engine(run, one):
    pytest.importorskip("mujoco")
    r = run(one, "--object", CYL, "--compare", "--json", *STEPS)
    assert r.code == 0, r.err
    out = json.loads(r.out)
    assert set(out) == {"rjcad", "mujoco", "differences"} and out["mujoco"]["engine"] == "mujoco"
