import json
import math

import pytest

PAPER = ["spring", "--stiffness", "5.2", "--rotation", "90", "--preload", "90"]


def test_json_has_the_pinned_keys(cli):
    code, out, err = cli(PAPER + ["--json"])
    assert code == 0, err
    d = json.loads(out)
    for key in ("width_mm", "thickness_mm", "length_mm", "inner_radius_mm", "pitch_mm", "turns",
                "outer_radius_mm", "spring_stiffness_nmm_per_rad", "joint_stiffness_nmm_per_rad",
                "max_stress_mpa", "allowed_stress_mpa", "min_coil_gap_mm", "material", "end"):
        assert key in d, key
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(5.2, rel=0.005)
    assert d["spring_stiffness_nmm_per_rad"] == pytest.approx(2.6, rel=0.005)
    assert d["max_stress_mpa"] <= d["allowed_stress_mpa"]
    assert d["rotation_deg"] == 90 and d["preload_deg"] == 90


def test_degrees_at_the_cli_radians_inside(cli):
    _, out, _ = cli(PAPER + ["--json"])
    a = json.loads(out)
    _, out, _ = cli(["spring", "--stiffness", "5.2", "--rotation", "45", "--preload", "135", "--json"])
    b = json.loads(out)
    # same total wind-up (180°): same stress and width; the wound-gap target is the same too
    assert a["max_stress_mpa"] == pytest.approx(b["max_stress_mpa"])
    assert a["width_mm"] == b["width_mm"]


def test_readable_table(cli):
    code, out, _ = cli(PAPER)
    assert code == 0
    for label in ("width b", "thickness t", "length L", "pitch p", "turns n", "outer radius",
                  "joint stiffness", "peak stress", "allowed stress", "coil gap"):
        assert label in out
    assert "5.2000" in out


def test_options_change_the_design(cli):
    _, out, _ = cli(PAPER + ["--json", "--end", "clamped", "--printer", "dimension-elite",
                             "--material", "PETG", "--safety-factor", "2"])
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
