"""Printer and material profiles as TOML data (issue #22): the built-in files give exactly the values rjcad had
hard-coded before, the derivation rule gives a new nozzle its limits, a user's file is found by path or by name
in the user's folder (and wins a clash), and a bad file is one line naming the file and the key."""

from __future__ import annotations

import json
import math
import re

import pytest

from rjcad.design.params import JointParams
from rjcad.errors import ParameterError, RjcadError
from rjcad.materials import MATERIALS, PRINTERS, Printer, from_manifest, get_material, get_printer, profile_entries

#: The values rjcad/materials.py held in code before they became data (commit 3ec1ccc): printer key →
#: (nozzle, road width, layer, min wall, min gap, min vertical gap, thickness step, soluble, bed).
OLD_PRINTERS = {
    "generic-0.4": (0.4, 0.4, 0.2, 0.8, 0.25, 0.4, 0.4, False, (220.0, 220.0, 250.0)),
    "dimension-elite": (0.3, 0.5, 0.178, 0.5, 0.25, 0.25, 0.05, True, (203.0, 203.0, 305.0)),
}
#: material key → (E, yield, density, desktop clearance at 0.4 mm).
OLD_MATERIALS = {
    "absplus-p430": (2200.0, 31.0, 1.04, 0.40),
    "abs-m30": (2413.0, 33.0, 1.04, 0.40),
    "pla": (3000.0, 35.0, 1.24, 0.35),
    "petg": (2100.0, 44.0, 1.27, 0.45),
    "pa12": (1400.0, 43.0, 1.01, 0.45),
    "ultem-9085": (2400.0, 69.0, 1.34, 0.45),
}

PRINTER_06 = """\
name = "Test printer, 0.6 mm nozzle"
nozzle_mm = 0.6
layer_mm = 0.3
first_layer_mm = 0.3
bed_mm = [180, 180, 180]
soluble_support = false
"""
MATERIAL_SOFT = """\
name = "Soft test filament"
youngs_modulus_mpa = 1900
yield_mpa = 40
density_g_cm3 = 1.2
"""


@pytest.fixture
def home(tmp_path, monkeypatch):
    """An empty user config folder (platformdirs reads XDG_CONFIG_HOME): no profile of the machine's user leaks in."""
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    return tmp_path / "config" / "rjcad"


def test_built_in_files_hold_the_values_that_were_in_code(home):
    assert set(PRINTERS) == set(OLD_PRINTERS) and set(MATERIALS) == set(OLD_MATERIALS)
    for key, old in OLD_PRINTERS.items():
        p = get_printer(key)
        got = (
            p.nozzle_mm,
            p.extrusion_width_mm,
            p.layer_height_mm,
            p.min_wall_mm,
            p.min_gap_mm,
            p.min_gap_vertical_mm,
            p.thickness_step_mm,
            p.soluble_support,
            p.build_volume_mm,
        )
        assert got == old, key  # exact: the same floats, so every default output is unchanged
        assert p.builtin and p.file.endswith(f"rjcad/data/printers/{key}.toml") and p.ref == key
        assert p.first_layer_mm == p.layer_height_mm
    for key, old in OLD_MATERIALS.items():
        m = get_material(key)
        assert (m.youngs_modulus_mpa, m.yield_strength_mpa, m.density_g_cm3, m.desktop_clearance_mm) == old, key
        assert m.builtin and len(m.source) > 20


def test_generic_printer_is_the_rule_itself_and_the_papers_printer_overrides_it():
    assert get_printer("generic-0.4").overrides == ()  # nothing typed: every limit from the rule
    assert set(get_printer("dimension-elite").overrides) == {
        "extrusion_width_mm",
        "min_wall_mm",
        "min_gap_mm",
        "min_gap_vertical_mm",
        "thickness_step_mm",
    }


def test_every_value_in_a_built_in_file_has_its_source_on_its_line():
    from rjcad.materials import DATA

    for f in sorted(DATA.glob("*/*.toml")):
        for line in f.read_text().splitlines():
            if "=" in line and not line.startswith("#") and not line.startswith(("name", "source")):
                assert "#" in line, f"{f.name}: {line!r} has no source comment"


@pytest.mark.parametrize(
    ("nozzle", "layer", "wall", "gap", "vgap"),
    [
        (0.4, 0.2, 0.8, 0.25, 0.4),
        (0.6, 0.3, 1.2, 0.375, 0.6),
        (0.25, 0.1, 0.5, 0.15625, 0.2),
        (0.8, 0.4, 1.6, 0.5, 0.8),
    ],
)
def test_the_rule_derives_walls_and_gaps_from_the_nozzle_and_layer(nozzle, layer, wall, gap, vgap):
    p = Printer.from_profile(
        {"name": "x", "nozzle_mm": nozzle, "layer_mm": layer, "bed_mm": [200, 200, 200], "soluble_support": False}, "x"
    )
    assert p.extrusion_width_mm == nozzle and p.thickness_step_mm == nozzle
    assert p.min_wall_mm == pytest.approx(wall) and p.min_gap_mm == pytest.approx(gap)
    assert p.min_gap_vertical_mm == pytest.approx(vgap)
    assert p.first_layer_mm == layer
    # the clearance between bodies grows with the nozzle from the material's value at 0.4 mm, never below the gap
    petg = get_material("petg")
    assert p.desktop_clearance(petg) == pytest.approx(max(0.45 * nozzle / 0.4, gap))


def test_an_override_replaces_only_its_own_limit():
    p = Printer.from_profile(
        {
            "name": "x",
            "nozzle_mm": 0.6,
            "layer_mm": 0.2,
            "bed_mm": [200, 200, 200],
            "soluble_support": False,
            "min_gap_mm": 0.5,
        },
        "x",
    )
    assert p.min_gap_mm == 0.5 and p.min_wall_mm == 1.2 and p.overrides == ("min_gap_mm",)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (PRINTER_06.replace("nozzle_mm", "nozle_mm"), ["nozle_mm", "unknown key", "nozzle_mm"]),
        (PRINTER_06.replace("bed_mm = [180, 180, 180]\n", ""), ["bed_mm", "is required"]),
        (PRINTER_06.replace("false", '"no"'), ["soluble_support", "true or false"]),
        (PRINTER_06.replace("0.6", "0"), ["nozzle_mm", "0.1"]),
        (PRINTER_06.replace("[180, 180, 180]", "[180, 180]"), ["bed_mm", "three numbers"]),
        (PRINTER_06.replace("layer_mm = 0.3", "layer_mm = 0.7"), ["layer_mm", "the nozzle"]),
        ("nozzle_mm = [", ["not valid TOML"]),
    ],
)
def test_a_bad_printer_file_is_one_line_naming_the_file_and_key(home, tmp_path, cli, text, words):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    with pytest.raises(RjcadError) as e:
        get_printer(str(f))
    msg = str(e.value)
    assert "bad.toml" in msg and all(w in msg for w in words), msg
    code, _out, err = cli("spring", "--stiffness", "5.2", "--printer", str(f))
    assert code == 2 and err.count("\n") == 1 and "bad.toml" in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (MATERIAL_SOFT.replace("yield_mpa", "yeild_mpa"), ["yeild_mpa", "unknown key"]),
        (MATERIAL_SOFT.replace("1900", "-5"), ["youngs_modulus_mpa"]),
        (MATERIAL_SOFT.replace("density_g_cm3 = 1.2\n", ""), ["density_g_cm3", "is required"]),
        (MATERIAL_SOFT.replace("1900", "true"), ["youngs_modulus_mpa", "number"]),
        (MATERIAL_SOFT.replace("40", '"40"'), ["yield_mpa", "must be a number"]),
    ],
)
def test_a_bad_material_file_is_refused_naming_the_key(home, tmp_path, text, words):
    f = tmp_path / "mine.toml"
    f.write_text(text)
    with pytest.raises(RjcadError) as e:
        get_material(str(f))
    assert "mine.toml" in str(e.value) and all(w in str(e.value) for w in words), str(e.value)


def test_a_missing_profile_file_and_an_unknown_name_are_one_line_each(home, cli):
    code, _, err = cli("spring", "--stiffness", "5.2", "--printer", "nowhere/mk4.toml")
    assert code == 2 and "no such printer profile file" in err and err.count("\n") == 1
    code, _, err = cli("spring", "--stiffness", "5.2", "--material", "unobtainium")
    assert code == 2 and "known materials:" in err and "path of a material profile" in err


def test_a_profile_by_path_designs_with_its_values(home, tmp_path):
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    (tmp_path / "soft.toml").write_text(MATERIAL_SOFT)
    p = JointParams(printer=str(tmp_path / "p06.toml"), material=str(tmp_path / "soft.toml"))
    assert p.printer == str((tmp_path / "p06.toml").resolve())  # found again by its path (sweep workers too)
    assert p.printer_spec.key == "p06" and not p.printer_spec.builtin
    assert p.material_spec.youngs_modulus_mpa == 1900.0
    assert p.clearance_mm == pytest.approx(0.40 * 0.6 / 0.4)  # the material's default clearance, scaled
    t = p.spring.thickness
    assert t / 0.6 == pytest.approx(round(t / 0.6)) and t >= 1.2 - 1e-12  # whole 0.6 mm roads, two at least


def test_a_name_in_the_user_folder_is_found_and_wins_over_the_built_in(home, cli):
    (home / "printers").mkdir(parents=True)
    (home / "printers" / "generic-0.4.toml").write_text(PRINTER_06.replace("0.6 mm", "mine"))
    (home / "materials").mkdir(parents=True)
    (home / "materials" / "My_PETG.toml").write_text(MATERIAL_SOFT)
    p = get_printer("generic-0.4")
    assert p.nozzle_mm == 0.6 and not p.builtin and p.file == str(home / "printers" / "generic-0.4.toml")
    assert get_material("my-petg").youngs_modulus_mpa == 1900.0
    assert get_material("Soft test filament").key == "my-petg"  # by its name too
    code, out, _ = cli("profiles", "--json")
    listed = json.loads(out)
    assert listed["user_dir"] == str(home)
    generic = [r for r in listed["printers"] if r["name"] == "generic-0.4"]
    assert len(generic) == 1 and generic[0]["from"] == "yours, over the built-in" and generic[0]["nozzle_mm"] == 0.6
    assert {r["name"] for r in listed["materials"]} == set(MATERIALS) | {"my-petg"}
    code, out, _ = cli("profiles")
    assert code == 0 and "yours, over the built-in" in out and str(home) in out
    code, out, _ = cli("spring", "--stiffness", "5.2", "--material", "my-petg")
    assert code == 0 and f"material my-petg: your profile {home / 'materials' / 'My_PETG.toml'}" in out


def test_show_prints_a_printers_derived_limits_and_says_which_it_was_given(home, tmp_path, cli, monkeypatch):
    """`rjcad profiles show`: a printer file's values and the rule's limits (each marked derived or set), the
    clearance per material; a file in the working folder printed as its relative path."""
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("profiles", "show", "p06.toml")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == "printer p06: Test printer, 0.6 mm nozzle (yours, p06.toml)"
    assert re.search(r"thinnest wall\s+1\.2\s+mm \(derived: 2·w\)", out)
    assert re.search(r"gap side by side\s+0\.375\s+mm \(derived: 5/8 · nozzle\)", out)
    assert "absplus-p430 0.600, " in out and "pla 0.525," in out  # 0.40 and 0.35 at 0.4 mm, × 0.6/0.4
    code, out, _ = cli("profiles", "show", "Dimension_Elite")  # a name: case, '_' and '-' as everywhere
    assert code == 0 and "(built-in, rjcad/data/printers/dimension-elite.toml)" in out
    assert re.search(r"thinnest wall\s+0\.5\s+mm \(set in the file\)", out)
    code, out, _ = cli("profiles", "show", "dimension-elite", "--json")
    d = json.loads(out)
    assert d["kind"] == "printer" and d["builtin"] and d["min_wall_mm"] == 0.5


def test_show_prints_a_material_and_refuses_an_unknown_name_in_one_line(home, tmp_path, cli):
    code, out, _ = cli("profiles", "show", "pla")
    assert code == 0 and out.startswith("material pla: PLA (built-in, rjcad/data/materials/pla.toml)\n")
    assert re.search(r"yield\s+35\s+MPa", out)
    (tmp_path / "soft.toml").write_text(MATERIAL_SOFT)
    code, out, _ = cli("profiles", "show", str(tmp_path / "soft.toml"), "--json")
    assert code == 0 and json.loads(out)["kind"] == "material" and json.loads(out)["youngs_modulus_mpa"] == 1900
    code, out, err = cli("profiles", "show", "nope")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "'nope'" in err


def test_the_list_prints_no_machine_folder_for_the_built_in_profiles(home, cli):
    code, out, _ = cli("profiles")
    assert code == 0 and "(rjcad/data/printers/generic-0.4.toml)" in out and "(rjcad/data/materials/pla.toml)" in out


def test_a_profile_named_in_a_design_file_is_taken_from_that_files_folder(home, tmp_path, cli, monkeypatch):
    d = tmp_path / "designs"
    d.mkdir()
    (d / "p06.toml").write_text(PRINTER_06)
    (d / "spring.toml").write_text('stiffness_nmm_per_rad = 5.2\nprinter = "p06.toml"\n')
    monkeypatch.chdir(tmp_path)  # not the design file's folder
    code, out, err = cli("spring", "--config", str(d / "spring.toml"), "--json")
    assert code == 0, err
    assert json.loads(out)["printer"] == "p06" and json.loads(out)["thickness_mm"] >= 1.2 - 1e-12


def test_a_manifest_embeds_a_users_profiles_and_is_read_with_them_elsewhere(home, tmp_path):
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    (tmp_path / "soft.toml").write_text(MATERIAL_SOFT)
    prn, mat = get_printer(str(tmp_path / "p06.toml")), get_material(str(tmp_path / "soft.toml"))
    extra = json.loads(json.dumps(profile_entries(prn, mat)))  # as a manifest file holds it
    assert extra["printer_profile"]["file"] == str(tmp_path / "p06.toml")
    (tmp_path / "p06.toml").unlink()  # another machine: the file is not there
    back = from_manifest("printers", "p06", extra)
    assert isinstance(back, Printer)
    for k in ("nozzle_mm", "min_wall_mm", "min_gap_mm", "min_gap_vertical_mm", "build_volume_mm", "first_layer_mm"):
        assert getattr(back, k) == getattr(prn, k), k
    assert from_manifest("materials", "soft", extra).youngs_modulus_mpa == 1900.0
    assert profile_entries(get_printer("generic-0.4"), get_material("pla")) == {}  # built-in: nothing added


def test_a_joint_longer_than_the_bed_is_refused_before_building(home, tmp_path, cli):
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    code, _, err = cli(
        "joint", "--printer", str(tmp_path / "p06.toml"), "--link-length", "100", "--out", tmp_path / "o"
    )
    assert code == 2 and "link_length" in err and "90 mm" in err and "bed" in err
    assert not (tmp_path / "o").exists()


def test_a_finger_longer_than_the_bed_is_refused_before_building(home, tmp_path, cli):
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    code, _, err = cli("finger", "--printer", str(tmp_path / "p06.toml"), "--out", tmp_path / "o")
    assert code == 2 and err.count("\n") == 1 and not (tmp_path / "o").exists()
    t = tmp_path / "long.toml"
    t.write_text(
        'printer = "p06.toml"\n[defaults]\nstiffness_nmm_per_rad = 5.2\n' + "[[joint]]\nlink_length_mm = 70\n" * 3
    )
    code, _, err = cli("finger", str(t), "--out", tmp_path / "o")
    assert code == 2 and "the finger lies straight on the bed" in err and "180 mm" in err
    assert not (tmp_path / "o").exists()


def test_clearance_limit_grows_with_the_nozzle(home, tmp_path):
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    p = JointParams(printer=str(tmp_path / "p06.toml"), material="petg")
    assert p.clearance_mm == pytest.approx(0.675)  # 0.45 at 0.4 mm × 0.6/0.4: above the 0.6 mm of a 0.4 nozzle
    with pytest.raises(ParameterError, match="clearance"):
        JointParams(clearance=0.65)  # a 0.4 mm nozzle's range still ends at 0.6 mm
    assert math.isclose(JointParams().clearance_mm, 0.40)


def test_import_prusaslicer_writes_a_profile_rjcad_reads_and_says_so(home, tmp_path, cli):
    from rjcad.io.prusaslicer import printer_names, profiles_dir

    try:
        names = printer_names(profiles_dir())
    except RjcadError:
        pytest.skip("PrusaSlicer's vendor profiles are not installed")
    name = (
        next(n for n, _ in names if "MK3S" in n and "0.4" not in n)
        if any("MK3S" in n for n, _ in names)
        else names[0][0]
    )
    code, out, err = cli("profiles", "import-prusaslicer", name, "--out", tmp_path)
    assert code == 0, err
    assert "printer profile written to" in out and name in out
    (written,) = tmp_path.glob("*.toml")  # named after the printer
    assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*\.toml", written.name), written.name
    p = get_printer(str(written))
    assert p.name == name and 0.1 < p.nozzle_mm <= 1.2 and p.min_wall_mm == 2 * p.nozzle_mm


def test_import_prusaslicer_without_its_profiles_is_one_line(home, tmp_path, cli):
    code, _out, err = cli("profiles", "import-prusaslicer", "MK3S", "--out", tmp_path / "x", "--profiles-dir", tmp_path)
    assert code == 2 and err.count("\n") == 1 and "apt-get install prusa-slicer" in err
    assert not (tmp_path / "x").exists()


def test_a_printer_too_short_for_the_joint_is_refused_before_building(home, tmp_path, cli):
    (tmp_path / "flat.toml").write_text(PRINTER_06.replace("[180, 180, 180]", "[180, 180, 20]"))
    code, _, err = cli("joint", "--printer", tmp_path / "flat.toml", "--out", tmp_path / "o")
    assert code == 2 and "build height, 20 mm" in err and not (tmp_path / "o").exists()
