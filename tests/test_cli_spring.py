import json
import math

import pytest

PAPER = ["spring", "--stiffness", "5.2", "--rotation", "90", "--preload", "90"]


def test_json_has_the_pinned_keys(cli):
    code, out, err = cli(PAPER + ["--json"])
    assert code == 0, err
    d = json.loads(out)
    for key in (
        "width_mm",
        "thickness_mm",
        "length_mm",
        "inner_radius_mm",
        "pitch_mm",
        "turns",
        "outer_radius_mm",
        "spring_stiffness_nmm_per_rad",
        "joint_stiffness_nmm_per_rad",
        "max_stress_mpa",
        "allowed_stress_mpa",
        "min_coil_gap_mm",
        "material",
        "end",
        "first_contact_deg",
        "rod_stiffness_nmm_per_rad",
        "formula_stiffness_nmm_per_rad",
        "peak_stress_mpa",
        "pin_force_n",
    ):
        assert key in d, key
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
    assert d["rod_stiffness_nmm_per_rad"] == d["joint_stiffness_nmm_per_rad"]  # the rod model's, per joint
    assert d["first_contact_deg"] is None and d["min_coil_gap_mm"] >= 0.25 and d["end"] == "clamped"
    assert d["spring_stiffness_nmm_per_rad"] == pytest.approx(2.6, rel=0.005)
    assert d["max_stress_mpa"] <= d["allowed_stress_mpa"]
    assert d["rotation_deg"] == 90 and d["preload_deg"] == 90


def test_degrees_at_the_cli_radians_inside(cli):
    _, out, _ = cli(PAPER + ["--json"])
    a = json.loads(out)
    _, out, _ = cli(["spring", "--stiffness", "5.2", "--rotation", "45", "--preload", "135", "--json"])
    b = json.loads(out)
    assert (a["rotation_deg"], a["preload_deg"]) == (90, 90) and (b["rotation_deg"], b["preload_deg"]) == (45, 135)
    # same total wind-up (180°) and stiffness: the same torque at 180°
    for d in (a, b):
        assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
        assert d["max_torque_nmm"] == pytest.approx(5.2 * math.pi, rel=0.02)


def test_readable_table(cli):
    code, out, _ = cli(PAPER)
    assert code == 0
    for label in (
        "width b",
        "thickness t",
        "length L",
        "pitch p",
        "turns n",
        "outer radius",
        "joint stiffness",
        "formula stiffness",
        "peak stress",
        "allowed stress",
        "coil gap",
        "first contact",
        "pin force",
        "rod model",
    ):
        assert label in out
    line = next(x for x in out.splitlines() if x.strip().startswith("joint stiffness"))
    assert float(line.split()[2]) == pytest.approx(5.2, rel=0.005)
    assert "clamped outer end" in out


def test_plot_draws_the_torque_curve_and_the_wound_shape(cli, tmp_path):
    png = tmp_path / "spring.png"
    code, out, err = cli(PAPER + ["--plot", str(png), "--json"])
    assert code == 0, err
    json.loads(out)  # the JSON stays clean
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000
    bad = tmp_path / "a_file"
    bad.write_text("x")
    code, out, err = cli(PAPER + ["--plot", str(bad / "spring.png")])
    assert code == 2 and out == "" and err.count("\n") == 1 and "--plot" in err


def test_coil_contact_refusal_says_where_and_what_to_change(cli):
    code, out, err = cli(
        [
            "spring",
            "--stiffness",
            "2",
            "--rotation",
            "180",
            "--preload",
            "150",
            "--end",
            "pinned",
            "--inner-radius-max",
            "3",
            "--max-outer-radius",
            "40",
        ]
    )
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "coils touch at" in err and "lower the preload or the rotation" in err


def test_options_change_the_design(cli):
    _, out, _ = cli(
        PAPER
        + ["--json", "--end", "clamped", "--printer", "dimension-elite", "--material", "PETG", "--safety-factor", "2"]
    )
    d = json.loads(out)
    assert d["end"] == "clamped" and d["printer"] == "dimension-elite" and d["material"] == "petg"
    assert d["allowed_stress_mpa"] == pytest.approx(44.0 / 2)


@pytest.mark.parametrize(
    "extra, param",
    [
        (["--stiffness", "-1"], "stiffness"),
        (["--stiffness", "0"], "stiffness"),
        (["--stiffness", "nan"], "stiffness"),
        (["--rotation", "400"], "rotation"),
        (["--material", "unobtainium"], "material"),
        (["--printer", "toaster"], "printer"),
        (["--end", "glued"], "end"),
        (["--safety-factor", "0.5"], "safety_factor"),
        (["--stiffness", "abc"], "stiffness"),
    ],
)
def test_bad_input_one_line_exit_2_no_traceback(extra, param, cli):
    code, out, err = cli(PAPER + extra)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert param in lines[0]
    assert "Traceback" not in err


def test_unknown_material_lists_the_known_ones(cli):
    _, _, err = cli(PAPER + ["--material", "unobtainium"])
    assert "absplus-p430" in err and "ultem-9085" in err


def test_infeasible_names_the_binding_constraint(cli):
    code, out, err = cli(PAPER + ["--max-outer-radius", "6"])
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert "outer radius" in err and "--max-outer-radius" in err


def test_missing_stiffness(cli):
    code, _, err = cli(["spring"])
    assert code == 2 and "--stiffness" in err and err.count("\n") == 1


def test_debug_shows_the_traceback(cli):
    code, _, err = cli(PAPER + ["--stiffness", "-1", "--debug"])
    assert code == 2
    assert "Traceback" in err and "stiffness" in err.strip().splitlines()[-1]


def test_config_file_and_override(tmp_path, cli):
    cfg = tmp_path / "spring.toml"
    cfg.write_text('stiffness_nmm_per_rad = 7.8\nrotation_deg = 90\npreload_deg = 90\nmaterial = "pla"\n')
    code, out, err = cli(["spring", "--config", str(cfg), "--json"])
    assert code == 0, err
    d = json.loads(out)
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(7.8, rel=0.005) and d["material"] == "pla"
    _, out, _ = cli(["spring", "--config", str(cfg), "--stiffness", "5.2", "--json"])
    assert json.loads(out)["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)


def test_config_unknown_key_and_missing_file(tmp_path, cli):
    cfg = tmp_path / "spring.toml"
    cfg.write_text("stiffness_nmm_per_rad = 5.2\nstifness = 3\n")
    code, _, err = cli(["spring", "--config", str(cfg)])
    assert code == 2 and "stifness" in err and "known keys" in err and err.count("\n") == 1
    code, _, err = cli(["spring", "--config", str(tmp_path / "nope.toml")])
    assert code == 2 and "not found" in err


def test_template_is_the_papers_joint(cli, root):
    tpl = root / "templates" / "spring.toml"
    code, out, err = cli(["spring", "--config", str(tpl), "--json"])
    assert code == 0, err
    d = json.loads(out)
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
    assert d["rotation_deg"] == 90 and d["preload_deg"] == 90 and d["material"] == "absplus-p430"


def test_console_script_end_to_end(cli_process):
    ok = cli_process(PAPER + ["--json"], timeout=120)
    assert ok.returncode == 0, ok.stderr
    assert math.isclose(json.loads(ok.stdout)["joint_stiffness_nmm_per_rad"], 5.2, rel_tol=0.005)
    bad = cli_process(PAPER + ["--rotation", "400"], timeout=120)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.count("\n") == 1 and "rotation" in bad.stderr and "Traceback" not in bad.stderr


def test_one_spring_with_a_coil_gap_is_the_default_desktop_joints_spring(cli):
    """`--springs 1 --min-gap 0.4` designs exactly the spring the default (desktop) joint prints."""
    from rjcad.design.params import JointParams

    code, out, err = cli(PAPER + ["--springs", "1", "--min-gap", "0.4", "--json"])
    assert code == 0, err
    d = json.loads(out)
    want = JointParams().spring.to_dict()
    for key in ("width_mm", "thickness_mm", "length_mm", "inner_radius_mm", "pitch_mm", "springs"):
        assert d[key] == pytest.approx(want[key]), key
    assert d["springs"] == 1 and d["spring_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
    assert d["min_coil_gap_mm"] >= 0.4 - 1e-9
    code, out, _ = cli(PAPER + ["--springs", "1", "--min-gap", "0.4"])
    assert "(one spring)" in out.splitlines()[0]


@pytest.mark.parametrize("springs", [1, 2])
def test_the_plot_draws_the_joint_torque_of_its_springs(springs):
    """The torque panel's rod curve has the joint's slope over the working range, for one spring or two."""
    import numpy as np

    from rjcad.api import design_spring
    from rjcad.plotting import pyplot
    from rjcad.spring.plot import _torque_panel

    design = design_spring(stiffness=3.0, rotation_deg=60, preload_deg=60, springs=springs).design
    fig, ax = pyplot().subplots()
    _torque_panel(ax, design)
    theta, torque = (np.asarray(a, float) for a in ax.lines[0].get_data())
    req = design.requirement
    lo, hi = np.degrees(req.preload), np.degrees(req.max_windup)
    slope = (np.interp(hi, theta, torque) - np.interp(lo, theta, torque)) / np.radians(hi - lo)
    assert slope == pytest.approx(design.joint_stiffness, rel=0.02)
    assert slope == pytest.approx(3.0, rel=0.02)
    pyplot().close(fig)
