"""The desktop layout with a two-arm spring (issue 36, part 2): parameters, layout, manifest, the built joint's
checks."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from shared_builds import checked, joint_build, joint_files

from rjcad import DEG
from rjcad.cad.build import joint_entry, preview_sections, seating_text
from rjcad.design.finger_params import FingerParams
from rjcad.design.params import JointParams
from rjcad.errors import ParameterError, RjcadError


@pytest.fixture(scope="module")
def p():
    """A two-arm joint the default envelope holds: 45° of rotation on a 35° preload (80° of wind-up)."""
    return JointParams(rotation=45 * DEG, preload=35 * DEG, arms=2)


def test_two_arms_keep_the_coil_and_key_gaps_and_balance_the_hub(p):
    d = p.spring
    assert d.arms == 2 and d.joint_stiffness == pytest.approx(p.stiffness, rel=0.005)
    g = d.requirement.gap_min
    assert d.min_coil_gap >= g and p.key_gap >= g
    assert d.rod.hub_force <= 0.05 * d.rod.arm_force and d.rod.arm_force > 0


def test_the_wound_envelope_covers_both_arms(p):
    env = p.wound
    prof = np.array(env.moving_profile)
    half = len(prof) // 2
    np.testing.assert_allclose(prof, np.roll(prof, half), atol=1e-9)  # the second arm: the first turned by 180°
    assert -env.ground_x_min == pytest.approx(env.r_max, abs=0.5)


def test_manifest_records_the_arms_and_both_keys(p):
    e = joint_entry(p, "ground", "moving", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    assert e.extra["arms"] == 2 and e.spring["arms"] == 2
    keys = e.extra["spring_end"]["keys"]
    assert [k["socket_ray_deg"] for k in keys] == [180.0, 0.0]
    assert [k["printed_ray_deg"] for k in keys] == pytest.approx([215.0, 35.0])
    assert e.extra["spring_end"]["min_gap_arm_to_other_key_mm"] >= p.clearance_mm
    assert "+X" in preview_sections(p)[0][0] and "two keys" in seating_text(p)


def test_one_arm_manifest_has_no_arms_keys():
    e = joint_entry(JointParams(), "ground", "moving", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    assert "arms" not in e.extra and "keys" not in e.extra["spring_end"] and "arms" not in e.spring


@pytest.mark.parametrize(("kw", "text"), [({"arms": 3}, "1 or 2"), ({"arms": 2, "layout": "stacked"}, "desktop")])
def test_bad_arms_in_one_line(kw, text):
    with pytest.raises(ParameterError, match=text) as e:
        JointParams(**kw)
    assert str(e.value).startswith("arms = ") and "\n" not in str(e.value)


def test_the_default_joint_refuses_two_arms_naming_why():
    with pytest.raises(RjcadError, match="two arms: each arm's end force shifts its coil pack"):
        JointParams(arms=2)


def test_a_finger_joint_table_takes_arms():
    data = {"joint": [{"stiffness_nmm_per_rad": 5.2, "rotation_deg": 45, "preload_deg": 35, "arms": 2}]}
    fp = FingerParams.from_dict(data)
    assert fp.joints[0].arms == 2
    with pytest.raises(ParameterError, match=r"joint\[1\]\.arms"):
        FingerParams.from_dict({"joint": [{"stiffness_nmm_per_rad": 5.2, "arms": "two"}]})


def test_the_two_arm_joint_passes_every_check_with_supports_off(p):
    """Built and checked as `rjcad joint --arms 2` writes it: one watertight joint, free over its range, printable
    without support; both keys in the section of the preview."""
    joint_build(p)
    out = joint_files(p)
    slicer = "prusa" if shutil.which("prusa-slicer") else None
    rep = checked(out / "joint.stl", out / "joint.json", slicer=slicer)
    failed = {c.name: c.detail for c in rep.checks if c.passed is False}
    assert not failed, failed
    names = {c.name for c in rep.checks if c.passed}
    assert {"watertight", "manifold", "bodies", "clearance", "motion", "min_feature", "overhang"} <= names
    assert math.isclose(p.spring.thickness, 0.8)


def test_cli_joint_arms_2_refuses_the_default_joint_in_one_line(cli, tmp_path):
    r = cli("joint", "--arms", "2", "--out", str(tmp_path / "j"))
    assert r.code == 2 and len(r.err.strip().splitlines()) == 1
    assert "two arms" in r.err and not (tmp_path / "j").exists()
    r = cli("joint", "--arms", "3", "--out", str(tmp_path / "j"))
    assert r.code == 2 and "arms = 3" in r.err
