import math

import numpy as np
import pytest
from spring_reference import brute_force

from rjcad import DEG
from rjcad import spring as sp
from rjcad.errors import InfeasibleDesign, ParameterError
from rjcad.materials import get_material, get_printer
from rjcad.spring import optimise as opt
from rjcad.spring import rod


def paper_requirement(**kw):
    base = dict(joint_stiffness=5.2, rotation=90 * DEG, preload=90 * DEG, material="absplus-p430")
    base.update(kw)
    return sp.SpringRequirement(**base)


def test_paper_joint_is_feasible_and_meets_every_constraint():
    req = paper_requirement()
    d = opt.design_spring(req)
    E, yield_ = 2200.0, 31.0
    assert d.end == "clamped"
    # stiffness: the rod model's slope over the working range 90° → 180°, wound again here (public API)
    res = rod.spiral_windup(
        d.inner_radius,
        d.pitch,
        d.turns,
        d.width,
        d.thickness,
        E,
        end="clamped",
        sense="unwind",
        theta_max=math.pi,
        steps=36,
    )
    slope = (res.torque[-1] - np.interp(math.pi / 2, res.theta, res.torque)) / (math.pi / 2)
    assert slope == pytest.approx(2.6, rel=0.005) and d.spring_stiffness == pytest.approx(slope, rel=1e-3)
    assert d.joint_stiffness == pytest.approx(5.2, rel=0.005)
    # the closed form c·E·b·t³/(12L) with c = 1 (clamped) is reported beside it
    assert d.formula_stiffness == pytest.approx(E * d.width * d.thickness**3 / (12 * d.length))
    # stress: the rod model's peak over 0..180° within yield/1.5
    assert res.stress.max() == pytest.approx(d.max_stress, rel=2e-3) and d.max_stress <= yield_ / 1.5
    # printable: t ≥ 0.8 mm (2 × 0.4 nozzle) and a whole number of 0.4 mm roads
    assert d.thickness >= 0.8 - 1e-12
    assert d.thickness / 0.4 == pytest.approx(round(d.thickness / 0.4), abs=1e-9)
    # width a whole number of 0.2 mm layers, inside the bounds
    assert d.width / 0.2 == pytest.approx(round(d.width / 0.2), abs=1e-9)
    assert 1.0 <= d.width <= 10.0
    # geometry consistent: exact spiral length equals L; r_out = r_in + p·n
    k = d.pitch / (2 * math.pi)
    from scipy.integrate import quad

    length, _ = quad(lambda phi: math.hypot(d.inner_radius + k * phi, k), 0, 2 * math.pi * d.turns)
    assert length == pytest.approx(d.length, rel=1e-9)
    # coil gap over the whole wind-up, rod model: ≥ the printer's 0.25 mm, no contact
    assert res.gap.min() >= 0.25 - 2e-3 and res.first_contact is None
    assert d.min_coil_gap == pytest.approx(res.coil_gap.min(), abs=2e-3)
    assert d.turns >= 1.0
    assert d.outer_radius == pytest.approx(d.inner_radius + d.pitch * d.turns + d.thickness / 2)
    assert d.outer_radius <= 20.0
    assert all(met for _, _, met in d.constraint_report().values())
    # the search is optimal: no brute-force design (same surrogate physics) is smaller by more than 3 %
    assert opt._optimise_one(req)["outer_radius"][0] <= brute_force(req, margin=0.01) * 1.03


def test_paper_joint_json_keys():
    d = opt.design_spring(paper_requirement()).to_dict()
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
        "loading_sense",
        "verified",
    ):
        assert key in d
    assert d["joint_stiffness_nmm_per_rad"] == pytest.approx(2 * d["spring_stiffness_nmm_per_rad"])
    assert d["rod_stiffness_nmm_per_rad"] == d["joint_stiffness_nmm_per_rad"]
    assert d["end"] == "clamped" and d["material"] == "absplus-p430" and d["loading_sense"] == "unwind"
    assert d["first_contact_deg"] is None and d["peak_stress_mpa"] == d["max_stress_mpa"]


def test_clamped_end_needs_less_spring_than_pinned():
    pinned = opt.design_spring(paper_requirement(end="pinned"))
    clamped = opt.design_spring(paper_requirement(end="clamped"))
    assert clamped.outer_radius < pinned.outer_radius
    assert clamped.width < pinned.width


def test_papers_printer_allows_thinner_strips():
    req = paper_requirement(printer="dimension-elite")
    d = opt.design_spring(req)
    assert d.thickness < 0.8  # thinner than two 0.4 mm roads: this printer varies its roads (0.05 mm steps)
    assert d.thickness / 0.05 == pytest.approx(round(d.thickness / 0.05), abs=1e-9)
    assert opt._optimise_one(req)["outer_radius"][0] <= brute_force(req, margin=0.01) * 1.03


def test_inner_radius_lower_bound_is_used_and_respected():
    d = opt.design_spring(paper_requirement(inner_radius_min=4.5))
    assert d.inner_radius == pytest.approx(4.5)


def test_stress_binding_error_message():
    req = paper_requirement(joint_stiffness=100.0, rotation=150 * DEG, width_max=3.0, outer_radius_max=500.0)
    with pytest.raises(InfeasibleDesign) as e:
        opt.design_spring(req)
    assert e.value.constraint == "stress"
    msg = str(e.value)
    assert "MPa allowed at t =" in msg and "stronger material" in msg
    assert brute_force(req, margin=0.01) == math.inf


def test_outer_radius_binding_error_message():
    req = paper_requirement(outer_radius_max=6.0)
    with pytest.raises(InfeasibleDesign) as e:
        opt.design_spring(req)
    assert e.value.constraint == "outer_radius"
    assert "outer radius" in str(e.value) and "6 mm allowed" in str(e.value)
    assert brute_force(req, margin=0.01) == math.inf


def test_turns_binding_error_message():
    req = paper_requirement(joint_stiffness=40.0, rotation=20 * DEG, preload=0.0, min_turns=3.0, width_max=3.0)
    with pytest.raises(InfeasibleDesign) as e:
        opt.design_spring(req)
    assert e.value.constraint == "turns"
    assert brute_force(req, margin=0.01) == math.inf


def test_inner_radius_binding_error_message():
    req = paper_requirement(inner_radius_min=1.0, inner_radius_max=2.0)
    with pytest.raises(InfeasibleDesign) as e:
        opt.design_spring(req)
    assert e.value.constraint == "inner_radius"
    assert "3·t" in str(e.value)


def test_width_binding_error_message():
    req = paper_requirement(width_min=1.0, width_max=1.5)
    with pytest.raises(InfeasibleDesign) as e:
        opt.design_spring(req)
    assert e.value.constraint == "width"


@pytest.mark.parametrize(
    "kw, param",
    [
        (dict(joint_stiffness=-1.0), "stiffness"),
        (dict(joint_stiffness=0.0), "stiffness"),
        (dict(joint_stiffness=float("nan")), "stiffness"),
        (dict(rotation=400 * DEG), "rotation"),
        (dict(rotation=0.0), "rotation"),
        (dict(preload=-5 * DEG), "preload"),
        (dict(safety_factor=0.9), "safety_factor"),
        (dict(material="unobtainium"), "material"),
        (dict(printer="nope"), "printer"),
        (dict(end="glued"), "end"),
        (dict(width_min=5.0, width_max=4.0), "width_max"),
        (dict(inner_radius_min=5.0, inner_radius_max=4.0), "inner_radius_max"),
        (dict(outer_radius_max=float("inf")), "max_outer_radius"),
    ],
)
def test_bad_requirements_name_the_parameter(kw, param):
    with pytest.raises(ParameterError) as e:
        paper_requirement(**kw)
    assert e.value.parameter == param
    assert str(e.value).startswith(param)


def test_rotation_error_speaks_degrees():
    with pytest.raises(ParameterError) as e:
        paper_requirement(rotation=400 * DEG)
    assert "400 deg" in str(e.value) and "360 deg" in str(e.value)


def test_vectorised_optimiser_matches_scalar_designs():
    K_joint = np.array([2.0, 5.2, 7.8, 10.4, 12.0])
    rot = np.array([60, 90, 90, 90, 120]) * DEG
    pre = np.array([90, 90, 90, 90, 45]) * DEG
    kw = dict(
        material=get_material("absplus-p430"),
        printer=get_printer("generic-0.4"),
        allowed_stress=31.0 / 1.5,
        end="clamped",
    )
    res = opt.optimise_arrays(K_joint / 2, rot + pre, rotation=rot, **kw)
    for i in range(len(K_joint)):
        one = opt.optimise_arrays(K_joint[i] / 2, rot[i] + pre[i], rotation=rot[i], **kw)
        assert res["feasible"][i] and one["feasible"][0]
        for key in ("outer_radius", "width", "thickness", "pitch", "length", "spring_stiffness"):
            assert res[key][i] == pytest.approx(one[key][0], rel=1e-12), key
        # and design_spring starts from that same spring (the rod model's check then keeps or adjusts it)
        d = opt.design_spring(paper_requirement(joint_stiffness=K_joint[i], rotation=rot[i], preload=pre[i]))
        assert d.thickness == one["thickness"][0]
        assert d.outer_radius >= one["outer_radius"][0] - 1e-9


def test_stiffer_joint_of_the_paper_finger_is_feasible():
    # the paper's finger uses 5.2 × [1, 1.5, 2]
    for K in (5.2, 7.8, 10.4):
        d = opt.design_spring(paper_requirement(joint_stiffness=K))
        assert d.joint_stiffness == pytest.approx(K, rel=0.005)


def test_design_round_trips_through_its_json():
    d = opt.design_spring(paper_requirement())
    back = opt.design_from_dict(d.to_dict(), d.requirement)
    assert back.to_dict() == d.to_dict()
