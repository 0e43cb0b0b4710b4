"""Property tests: every answer of the optimiser is right, or it says clearly why there is none."""

import math

import pytest
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st
from spring_reference import brute_force

from rjcad import DEG
from rjcad import spring as sp
from rjcad.errors import InfeasibleDesign, ParameterError
from rjcad.materials import MATERIALS, PRINTERS
from rjcad.spring import optimise as opt

requirements = st.builds(
    sp.SpringRequirement,
    joint_stiffness=st.floats(0.2, 120.0),
    rotation=st.floats(5.0, 360.0).map(lambda d: d * DEG),
    preload=st.floats(0.0, 360.0).map(lambda d: d * DEG),
    material=st.sampled_from(sorted(MATERIALS)),
    printer=st.sampled_from(sorted(PRINTERS)),
    safety_factor=st.floats(1.0, 3.0),
    end=st.sampled_from(["pinned", "clamped"]),
    width_min=st.floats(0.5, 3.0),
    width_max=st.floats(3.0, 15.0),
    inner_radius_min=st.floats(1.5, 5.0),
    inner_radius_max=st.floats(5.0, 12.0),
    outer_radius_max=st.floats(5.0, 40.0),
    min_turns=st.floats(0.5, 3.0),
)


def assert_meets_every_constraint(d: sp.SpringDesign):
    """The rod model's verdict (the design's own check) and the geometry rules, re-derived here."""
    req = d.requirement
    pr = req.printer_spec
    assert all(met for _, _, met in d.constraint_report().values()), d.constraint_report()
    assert abs(d.joint_stiffness / req.joint_stiffness - 1) <= 0.005
    assert d.max_stress <= req.material_spec.yield_strength_mpa / req.safety_factor * (1 + 1e-9)
    assert d.min_coil_gap >= pr.min_gap_mm - 1e-9 and d.first_contact is None
    assert d.thickness >= pr.min_wall_mm - 1e-9
    steps = d.thickness / pr.thickness_step_mm
    assert abs(steps - round(steps)) < 1e-6
    assert d.turns >= req.min_turns - 1e-9
    assert req.width_min - 1e-9 <= d.width <= req.width_max + 1e-9
    assert req.inner_radius_min - 1e-9 <= d.inner_radius <= req.inner_radius_max + 1e-9
    assert d.inner_radius + d.pitch * d.turns + d.thickness / 2 <= req.outer_radius_max + 1e-9
    assert abs(sp.archimedean_length(d.inner_radius, d.pitch, d.turns) / d.length - 1) < 1e-9


#: Above the tiniest springs (KNOWN_MISSES: K = 1 N·mm/rad in 5–6 mm envelopes) and short of the far wind-ups
#: (FAR_WOUND_MISSES: 343–349°): both open.
SPRINGS_ABOVE_THE_THINNEST_WALL = requirements.filter(
    lambda r: r.joint_stiffness >= 5.0 and r.preload + r.rotation <= 240 * DEG
)


@pytest.mark.slow  # many full rod-model verifications: full suite only (fast lane < 2 min)
@settings(max_examples=60)
@given(requirements)
def test_optimiser_is_right_or_says_why(req):
    """Every answer meets every constraint; a refusal is one sentence naming the binding constraint."""
    try:
        d = opt.design_spring(req)
    except InfeasibleDesign as e:
        event(f"infeasible: {e.constraint}")
        assert e.constraint in opt.CONSTRAINTS
        assert str(e)  # one clear sentence naming the binding constraint
        assert "\n" not in str(e)
        return
    event("feasible")
    assert_meets_every_constraint(d)


@pytest.mark.slow
@settings(max_examples=40)
@given(SPRINGS_ABOVE_THE_THINNEST_WALL)
def test_optimiser_is_the_smallest_or_rightly_infeasible(req):
    """Above the thinnest-wall regime (KNOWN_MISSES): never a false "infeasible" from the search (no design with
    a 1 % margin on a fine grid with the same surrogate physics; a refusal by the rod model's own check is the rod
    model's word), and the smallest: the grid (every layer of width, 120 pitches) finds nothing more than 3 %
    smaller that meets every constraint with a 1 % margin."""
    try:
        opt.design_spring(req)
    except InfeasibleDesign as e:
        if not str(e).startswith("rod-model check"):
            assert brute_force(req, margin=0.01) == math.inf
        return
    assert opt._optimise_one(req)["outer_radius"][0] <= brute_force(req, margin=0.01) * 1.03 + 1e-9


#: Requirements where the optimiser is known to be wrong (found by the test above, 2026-11-27): a small, soft spring
#: whose envelope (outer radius 5–6 mm, hub 3–5 mm) leaves room for one strip at the printer's thinnest wall. The
#: search says "infeasible" (its pick's coil gap 0.24997 mm < 0.25) or answers 4.80 mm, where a grid of every
#: layer of width and 120 pitches finds 4.57–4.60 mm with a 1 % margin. Causes: a cell stopped by the fixed
#: point's ROUNDS keeps a pitch chosen for the length before its last polish; the width factors sample a wide
#: width range coarsely. Fixing either moves other designs (the paper check's among them): open.
KNOWN_MISSES = [
    dict(preload=5 * DEG, width_max=6.0),
    dict(preload=10 * DEG, width_max=6.0),
    dict(preload=10 * DEG, width_max=3.0),
    dict(preload=69 * DEG, width_max=3.0, outer_radius_max=6.0),  # 4.45 mm against the grid's 4.22
]


def _tiny_spring(**fields) -> sp.SpringRequirement:
    """The known cases' requirement: a 1 N·mm/rad joint turning 5° on the Dimension Elite, pinned, hub ≤ 5 mm."""
    base = dict(joint_stiffness=1.0, rotation=5 * DEG, printer="dimension-elite", safety_factor=1.0, end="pinned")
    return sp.SpringRequirement(**base, width_min=1.0, inner_radius_max=5.0, **fields)


#: Far-wound springs (preload + rotation 343–349°, clamped) where the optimiser's answer is larger than the grid's
#: smallest by 9 % and 3.1 % (16.56 against 15.19 mm; 18.11 against 17.56 mm): found by the test above run past
#: 240° (2026-11-27). Open.
FAR_WOUND_MISSES = [
    dict(
        joint_stiffness=19.085,
        rotation=6.2 * DEG,
        preload=343.33 * DEG,
        material="abs-m30",
        printer="generic-0.4",
        width_min=1.3975,
        width_max=10.3033,
        inner_radius_min=1.9,
        inner_radius_max=5.9272,
        outer_radius_max=19.085,
        min_turns=2.2347,
    ),
    dict(
        joint_stiffness=5.0,
        rotation=171.5 * DEG,
        preload=171.5 * DEG,
        material="petg",
        printer="dimension-elite",
        safety_factor=1.7119,
        width_min=1.5,
        width_max=3.0,
        inner_radius_min=4.3243,
        inner_radius_max=6.2067,
        outer_radius_max=29.1989,
        min_turns=1.5,
    ),
]


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="the optimiser is 3–9 % above the smallest far-wound spring (open)")
@pytest.mark.parametrize("case", FAR_WOUND_MISSES)
def test_far_wound_misses_of_the_optimiser(case):
    req = sp.SpringRequirement(**{"end": "clamped", **case})
    assert opt.design_spring(req).outer_radius <= brute_force(req, margin=0.01) * 1.03 + 1e-9


@pytest.mark.xfail(strict=True, reason="the optimiser misses the smallest spring in the tightest envelopes (open)")
@pytest.mark.parametrize("case", KNOWN_MISSES)
def test_known_misses_of_the_optimiser(case):
    req = _tiny_spring(material="abs-m30", inner_radius_min=3.0, min_turns=1.0, **{"outer_radius_max": 5.0, **case})
    best = brute_force(req, margin=0.01)
    assert best < math.inf
    d = opt.design_spring(req)  # raises InfeasibleDesign for the first: an xfail too
    assert d.outer_radius <= best * 1.03 + 1e-9


#: Requirements on which the optimiser or the rod model once raised instead of answering or refusing in one line
#: (found by the property test above in CI, 2026-11-27: "math domain error", "rod solve did not converge at
#: λ = 0.9788", "cannot convert float NaN to integer"): a 0.5 N·mm/rad PA12 spring wound 242–244° in a 5–6 mm
#: envelope. The rod model's corrections reached a strip of about one turn whose torque falls over the rotation
#: (it snaps through); such a design is now refused for its stiffness, naming the snap-through.
FAR_WOUND_TINY_SPRINGS = [
    dict(preload=239 * DEG, inner_radius_min=1.5, outer_radius_max=5.0, min_turns=0.5),
    dict(preload=239 * DEG, inner_radius_min=2.0, outer_radius_max=6.0, min_turns=1.0),
    dict(preload=237 * DEG, inner_radius_min=2.0, outer_radius_max=6.0, min_turns=1.0),
]


@pytest.mark.parametrize("case", FAR_WOUND_TINY_SPRINGS)
def test_far_wound_tiny_springs_are_answered_or_refused_in_one_line(case):
    req = _tiny_spring(material="pa12", width_max=3.0, **case)
    try:
        assert_meets_every_constraint(opt.design_spring(req))
    except InfeasibleDesign as e:
        assert e.constraint in opt.CONSTRAINTS
        assert "\n" not in str(e) and str(e).startswith("rod-model check: ")


def test_a_snapping_strip_is_refused_for_its_stiffness():
    """The second case: the rod model finds no equilibrium near the end of the wind-up; the refusal says so."""
    req = _tiny_spring(material="pa12", width_max=3.0, **FAR_WOUND_TINY_SPRINGS[1])
    with pytest.raises(InfeasibleDesign, match=r"no equilibrium at \d+° of the 244° wind-up.*snaps through") as e:
        opt.design_spring(req)
    assert e.value.constraint == "stiffness"


@settings(max_examples=30)
@given(st.floats(0.2, 60.0), st.floats(5.0, 180.0), st.floats(0.0, 180.0))
def test_feasible_requirements_of_the_paper_family(K, rot, pre):
    req = sp.SpringRequirement(K, rot * DEG, pre * DEG, outer_radius_max=200.0, width_max=30.0)
    try:
        d = opt.design_spring(req)
    except InfeasibleDesign:
        assume(False)
    assert_meets_every_constraint(d)


@settings(max_examples=60)
@given(
    st.one_of(
        st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not (0 < x <= 1e4)), st.just(float("nan"))
    )
)
def test_bad_stiffness_always_rejected(K):
    try:
        sp.SpringRequirement(K, math.pi / 2)
    except ParameterError as e:
        assert e.parameter == "stiffness"
    else:
        raise AssertionError(f"stiffness {K} accepted")


@settings(max_examples=40)
@given(st.floats(360.0001, 1e6))
def test_rotation_over_a_turn_rejected(rot):
    try:
        sp.SpringRequirement(5.2, rot * DEG)
    except ParameterError as e:
        assert e.parameter == "rotation"
    else:
        raise AssertionError(f"rotation {rot} accepted")
