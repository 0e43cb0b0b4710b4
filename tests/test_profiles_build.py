"""Issue #22's acceptance for profiles: a printer (0.6 mm nozzle, 180 mm cube) and a filament (E = 1900 MPa,
yield 40 MPa) that rjcad has never seen build a joint and a finger whose clearances and walls follow the
documented rule, whose springs give the asked stiffness with that modulus (checked against the rod model wound
finer, and against the paper's linear formula K = E·b·t³/(12·L)), and which PrusaSlicer slices with the 0.6 mm
nozzle, supports off, without a road in mid-air."""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest
from test_profiles import MATERIAL_SOFT, PRINTER_06

from rjcad.spring import rod

FINGER = """\
printer = "p06.toml"
material = "soft.toml"

[defaults]
preload_deg = 90
rotation_deg = 90

[[joint]]
stiffness_nmm_per_rad = 5.2

[[joint]]
stiffness_nmm_per_rad = 7.8

[[joint]]
stiffness_nmm_per_rad = 10.4
"""
PRUSA = shutil.which("prusa-slicer")


@pytest.fixture
def profiles(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    (tmp_path / "p06.toml").write_text(PRINTER_06)
    (tmp_path / "soft.toml").write_text(MATERIAL_SOFT)
    (tmp_path / "finger.toml").write_text(FINGER)
    return tmp_path


def _spring_is_right(s: dict, asked: float, springs: int) -> None:
    """The spring of a manifest, wound again by the rod model on a finer mesh, gives the asked stiffness with
    E = 1900 MPa, and the linear formula agrees within the large-rotation correction."""
    assert s["material"] == "soft"
    theta = math.radians(s["preload_deg"] + s["rotation_deg"])
    res = rod.spiral_windup(
        s["inner_radius_mm"],
        s["pitch_mm"],
        s["turns"],
        s["width_mm"],
        s["thickness_mm"],
        1900.0,
        end=s["end"],
        sense=s["loading_sense"],
        theta_max=theta,
        steps=math.ceil(theta / math.radians(2.5)),
        per_turn=100,
    )
    slope = (res.torque[-1] - np.interp(math.radians(s["preload_deg"]), res.theta, res.torque)) / math.radians(
        s["rotation_deg"]
    )
    assert springs * slope == pytest.approx(asked, rel=0.006)
    linear = 1900.0 * s["width_mm"] * s["thickness_mm"] ** 3 / (12 * s["length_mm"])
    assert springs * linear == pytest.approx(asked, rel=0.05)
    assert res.stress.max() <= 40.0 / s["safety_factor"] * 1.002
    assert res.first_contact is None


def _check(cli, out, name):
    code, text, _err = cli(
        "check", out / f"{name}.3mf", "--manifest", out / f"{name}.json", "--slicer", "prusa", "--json"
    )
    rep = json.loads(text)
    failed = [c for c in rep["checks"] if c["passed"] is False]
    assert code == 0 and not failed, failed
    slicer = next(c for c in rep["checks"] if c["name"] == "slicer")
    assert "0.6 mm nozzle, 0.3 mm layers" in slicer["detail"], slicer["detail"]  # both printers here
    feature = next(c for c in rep["checks"] if c["name"] == "min_feature")
    assert feature["limit"] == pytest.approx(1.2)  # two 0.6 mm roads
    return rep


@pytest.mark.skipif(PRUSA is None, reason="prusa-slicer is not installed")
def test_an_unseen_printer_and_filament_build_a_joint_that_prints(profiles, cli):
    out = profiles / "joint"
    code, text, err = cli(
        "joint", "--printer", profiles / "p06.toml", "--material", profiles / "soft.toml", "--out", out
    )
    assert code == 0, err
    assert f"printer p06: your profile {profiles / 'p06.toml'}" in text
    m = json.loads((out / "joint.json").read_text())
    assert m["printer"] == "p06" and m["material"] == "soft"
    assert m["printer_profile"]["nozzle_mm"] == 0.6 and m["printer_profile"]["min_wall_mm"] == 1.2
    assert m["clearance_mm"] == pytest.approx(0.6)  # 0.40 (the material's default at 0.4 mm) × 0.6/0.4
    assert m["measured_min_gap_mm"] >= 0.6 - 0.02
    t = m["spring"]["thickness_mm"]
    assert t >= 1.2 - 1e-9 and t / 0.6 == pytest.approx(round(t / 0.6))  # whole roads of 0.6 mm
    _spring_is_right(m["spring"], 5.2, m["spring"].get("springs", 1))
    _check(cli, out, "joint")


@pytest.mark.skipif(PRUSA is None, reason="prusa-slicer is not installed")
def test_an_unseen_printer_and_filament_build_a_finger_that_prints(profiles, cli):
    out = profiles / "finger"
    code, _text, err = cli("finger", profiles / "finger.toml", "--out", out, "--no-png")
    assert code == 0, err
    m = json.loads((out / "finger.json").read_text())
    assert m["printer_profile"]["bed_mm"] == [180.0, 180.0, 180.0]
    for j, asked in zip(m["joints"], (5.2, 7.8, 10.4)):
        _spring_is_right(j["spring"], asked, j["spring"].get("springs", 1))
    rep = _check(cli, out, "finger")
    bed = next(c for c in rep["checks"] if c["name"] == "bed")
    assert bed["limit"] == [180.0, 180.0, 180.0] and max(bed["value"][:2]) <= 180.0


@pytest.mark.skipif(PRUSA is None, reason="prusa-slicer is not installed")
def test_a_printer_imported_from_prusaslicer_builds_a_joint_that_prints(profiles, cli):
    from rjcad.io.prusaslicer import printer_names

    name = "Original Prusa i3 MK3S & MK3S+ 0.6 nozzle"
    if name not in {n for n, _ in printer_names()}:
        pytest.skip(f"{name!r} is not in this PrusaSlicer's bundles")
    code, _text, err = cli("profiles", "import-prusaslicer", name, "--out", profiles / "mk3s.toml")
    assert code == 0, err
    out = profiles / "joint"
    code, _text, err = cli("joint", "--printer", profiles / "mk3s.toml", "--material", "petg", "--out", out)
    assert code == 0, err
    m = json.loads((out / "joint.json").read_text())
    assert m["printer_profile"]["bed_mm"] == [250.0, 210.0, 210.0] and m["printer_profile"]["nozzle_mm"] == 0.6
    assert m["clearance_mm"] == pytest.approx(0.45 * 0.6 / 0.4)
    _check(cli, out, "joint")
