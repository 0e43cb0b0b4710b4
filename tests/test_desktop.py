"""The support-free desktop layout (issue #15): its geometry's invariants, and the built joint's checks."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from shared_builds import checked, joint_build, joint_files

from rjcad.design.layout_desktop import CONE_ANGLE, FACET_MARGIN, ROOF_NORMAL, T
from rjcad.design.params import JointParams
from rjcad.materials import get_printer


@pytest.fixture(scope="module")
def p():
    return JointParams(layout="desktop")


def test_default_layout_follows_the_printer_and_desktop_uses_the_material_clearance():
    # no soluble support: desktop with the material's clearance; the paper's printer: stacked, 0.25 mm
    assert JointParams().layout == "desktop" and JointParams().clearance == 0.40
    assert JointParams(printer="dimension-elite").layout == "stacked"
    assert JointParams(printer="dimension-elite").clearance == 0.25
    assert JointParams(layout="stacked").clearance == 0.25
    assert JointParams(layout="desktop", material="pla").clearance == 0.35
    assert JointParams(layout="desktop", material="petg").clearance == 0.45
    assert JointParams(layout="desktop", material="pla", clearance=0.3).clearance == 0.3


def test_desktop_refuses_a_pinned_end_in_one_line():
    from rjcad.errors import ParameterError

    with pytest.raises(ParameterError, match="end"):
        JointParams(layout="desktop", end="pinned")


def test_one_spring_carries_the_whole_joint_stiffness(p):
    d = p.spring
    assert p.springs == 1 and d.requirement.springs == 1
    assert d.joint_stiffness == pytest.approx(p.stiffness, rel=0.005)
    assert d.spring_stiffness == pytest.approx(p.stiffness, rel=0.005)
    # the coils keep the desktop clearance (not only the printer's minimum) over the whole wind-up
    assert d.min_coil_gap >= p.clearance - 1e-9 and d.first_contact is None


def test_cones_are_steeper_than_45_degrees_and_a_road_step_apart():
    assert CONE_ANGLE > math.radians(45.0)
    layer = get_printer("generic-0.4").layer_height_mm
    assert layer / T < 0.2  # each layer steps out less than the slicer check's h·tan 45°


def test_nested_cones_keep_the_clearance_along_their_normal(p):
    L = p.desktop
    normal = math.cos(CONE_ANGLE)
    for r in np.linspace(L.R_band, L.R_flare, 7):  # flare top under the roof's underside
        assert (L.roof_under(r) - L.flare_top(r)) * normal == pytest.approx(L.c + FACET_MARGIN)
    for r in np.linspace(L.R_bore, L.R_co, 7):  # arm's underside over the roof's top
        assert (L.arm_under(r) - L.roof_top(r)) * normal == pytest.approx(L.c + FACET_MARGIN)
    assert L.R_bore - L.R_band == pytest.approx(L.c + FACET_MARGIN)
    assert L.R_flare > L.R_bore  # the flare holds the hub down under the roof's bore
    assert (L.roof_top(0.0) - L.roof_under(0.0)) * normal == pytest.approx(ROOF_NORMAL)


def test_the_spring_and_its_lifted_key_fit_under_the_roof(p):
    L = p.desktop
    assert L.flare_bottom >= p.spring.width + p.gap_z - 1e-9
    assert L.z_w0 >= p.spring.width + L.seat + L.c  # the key, lifted over the tines, passes under the roof
    assert L.R_ci >= p.wound_radius + p.gap_internal - 1e-9  # the wound strip never reaches the wall
    assert L.R_ci > math.hypot(p.key_tip_radius, p.key_width) + L.c  # nor the printed key
    # the tendon runs above the lugs and the roof, beside the arm
    assert L.lug_top < L.z_t - p.tendon_diameter / 2
    assert L.w_arm < p.moment_arm - p.tendon_diameter / 2


def test_the_arm_plane_stays_above_the_roof_cone_everywhere(p):
    """The arm's underside is a plane in x; at (x, y) the roof's top is at radius ≥ x, i.e. lower."""
    L = p.desktop
    for x in np.linspace(L.R_band, L.R_co, 9):
        for y in np.linspace(-L.w_arm, L.w_arm, 5):
            r = math.hypot(x, y)
            plane = L.z_band[0] - (x - L.R_band) * T
            assert plane - L.roof_top(max(r, L.R_bore)) >= (L.c + FACET_MARGIN) / math.cos(CONE_ANGLE) - 1e-9


def test_the_desktop_joint_passes_every_check_with_supports_off(p):
    """Built and checked as a user would (the joint.stl and joint.json that `rjcad joint` writes; the build and the
    report shared with the other tests of this design): watertight, manifold, clearance, motion, min_feature,
    overhang, and (where PrusaSlicer is installed, as in CI) the supports-off slice read back layer by layer."""
    b = joint_build(p)
    out = joint_files(p)
    slicer = "prusa" if shutil.which("prusa-slicer") else None
    rep = checked(out / "joint.stl", out / "joint.json", slicer=slicer)
    failed = {c.name: c.detail for c in rep.checks if c.passed is False}
    assert not failed, failed
    names = {c.name for c in rep.checks if c.passed}
    assert {"watertight", "manifold", "clearance", "motion", "min_feature", "overhang"} <= names
    if slicer:
        assert "slicer" in names
    # min_feature names real features (#16): the thinnest wall is the spring's strip, the narrowest gap its coils
    import re as _re

    mf = rep.get("min_feature").detail
    wall = float(_re.search(r"thinnest wall ([\d.]+) mm in moving", mf).group(1))
    gap = float(_re.search(r"narrowest gap inside a body ([\d.]+) mm in moving", mf).group(1))
    assert wall == pytest.approx(p.spring.thickness, abs=0.02)
    assert gap == pytest.approx(p.spring.to_dict()["print_coil_gap_mm"], abs=0.02)
    m = b.manifest
    assert m["tendon_moment_arm_mm"] == pytest.approx(p.moment_arm, abs=0.05)
    assert m["joints"][0]["layout"]["layout"] == "desktop"
    # the physics reads this manifest as built: the one spring's (whole) stiffness, the preload, the measured
    # moment arm and wrap (a joint is a finger with one joint)
    from rjcad.physics.finger import load_finger_model, simulate_stroke

    model = load_finger_model(str(out / "joint.json"))
    assert model.stiffness == pytest.approx([m["joint_stiffness_nmm_per_rad"]]) and m["spring"]["springs"] == 1
    assert model.stiffness[0] == pytest.approx(p.stiffness, rel=0.005)
    assert model.moment_arm == pytest.approx([m["tendon_moment_arm_mm"]])
    assert model.wrap == pytest.approx([m["tendon_wrap_angle_rad"]]) and model.wrap[0] > 0
    assert model.preload == pytest.approx([p.preload])
    closure = simulate_stroke(model, 5.0, 100)
    # frictionless: the joint starts once r·T = K·θ0, then θ = stroke / r (tendon inextensible)
    assert math.degrees(closure.theta[100][0]) == pytest.approx(math.degrees(5.0 / model.moment_arm[0]), abs=0.5)


def _min_feature(mesh):
    from rjcad.check.feature import check_min_feature

    return check_min_feature([mesh], ["part"], get_printer("generic-0.4"), 0.02)


def test_min_feature_ignores_a_crease_but_not_a_slot():
    """Meshes made outside rjcad: a ring fused to a box that cuts slightly into it (a re-entrant crease at a
    shallow angle: no gap), and a block with a 0.1 mm slot (two walls facing each other: a real gap)."""
    ring = trimesh.creation.annulus(r_min=5.0, r_max=8.0, height=4.0)
    box = trimesh.creation.box((6.0, 6.0, 4.0))
    box.apply_translation((10.7, 0.0, 0.0))  # its face at x = 7.7 cuts the ring's outside
    crease = trimesh.boolean.union([ring, box], engine="manifold")
    assert _min_feature(crease).passed, _min_feature(crease).detail
    block = trimesh.creation.box((10.0, 10.0, 6.0))
    slot = trimesh.creation.box((0.1, 12.0, 5.0))
    slot.apply_translation((0.0, 0.0, 1.0))
    slotted = trimesh.boolean.difference([block, slot], engine="manifold")
    res = _min_feature(slotted)
    assert not res.passed and "gap inside a body" in res.detail and res.value == pytest.approx(0.1, abs=0.02)


desktop_designs = st.builds(
    JointParams,
    stiffness=st.floats(1.0, 14.0),
    rotation=st.floats(20.0, 110.0).map(math.radians),
    preload=st.floats(30.0, 120.0).map(math.radians),
    material=st.sampled_from(["absplus-p430", "abs-m30", "pla", "petg"]),
    link_length=st.floats(32.0, 70.0),
    layout=st.just("desktop"),
)


@pytest.mark.slow
@settings(
    max_examples=20,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    derandomize=True,
    phases=[Phase.explicit, Phase.generate],
)  # no shrinking: a build + slice per step
@given(st.data())
def test_random_desktop_designs_pass_every_check_with_supports_off(data):
    """Issue #15's acceptance: 20 random valid designs (stiffness, rotation, preload, material, link length) in
    the desktop layout pass overhang, the supports-off slice (PrusaSlicer) and every other check: watertight,
    manifold, bodies, clearance, motion over the full range, min_feature, bed."""
    from hypothesis import assume

    from rjcad.errors import InfeasibleDesign, ParameterError

    try:
        p = data.draw(desktop_designs)
    except (InfeasibleDesign, ParameterError):
        assume(False)
    slicer = "prusa" if shutil.which("prusa-slicer") else None
    out = joint_files(p)  # the joint.stl and joint.json that write_joint writes, built once per session
    rep = checked(out / "joint.stl", out / "joint.json", slicer=slicer)
    failed = {c.name: c.detail for c in rep.checks if c.passed is False}
    assert not failed, (p, failed)
    passed = {c.name for c in rep.checks if c.passed}
    assert {"watertight", "manifold", "bodies", "clearance", "motion", "min_feature", "bed", "overhang"} <= passed
    assert slicer is None or "slicer" in passed
