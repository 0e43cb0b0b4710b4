"""Inverse finger design: reachable targets end within 1° in the requested order with joints the builder
accepts; unreachable ones say why, and the numbers in the message are true."""

import math
import tomllib

import numpy as np
import pytest

from rjcad.design.params import JointParams
from rjcad.errors import InfeasibleDesign, ParameterError, RjcadError
from rjcad.physics import finger as fm
from rjcad.physics.inverse import _printable_scale, arm_range, design_finger

DEG = math.pi / 180


def buildable(k, preload, rotation, arm):
    try:
        JointParams(stiffness=k, preload=preload, rotation=rotation, tendon_moment_arm=arm)
    except RjcadError:
        return False
    return True


@pytest.mark.parametrize(
    "target, stroke, sequence",
    [
        ([90, 20, 20], 12, "proximal-first"),  # preloads cannot be proportional: only proximal-first reaches it
        ([30, 60, 90], 15, "simultaneous"),
        ([40, 70], 14, "proximal-first"),
        ([100, 80, 60, 40], 30, "simultaneous"),
    ],
)
def test_reachable_targets_end_within_a_degree_in_order(target, stroke, sequence):
    d = design_finger(target, stroke, sequence)
    # re-simulate independently from the written template's physics keys
    import tomllib

    m = fm.model_from_template(tomllib.loads(d.template()))
    c = fm.simulate_stroke(m, stroke, 300)
    assert np.degrees(c.theta[300]) == pytest.approx(target, abs=1.0)
    on = fm.onset_tendon(c, 0.1 * DEG)
    if sequence == "proximal-first":
        assert on[0] < on[1:].min() - 0.02 * stroke and np.ptp(on[1:]) < 0.02 * stroke
    else:
        assert np.ptp(on) < 0.02 * stroke
    # every joint is one the builder accepts (printable spring, preload, rotation, arm)
    for k, p, r, a in zip(d.stiffness, d.preload, d.rotation, d.moment_arm):
        assert buildable(k, p, r, a)


def test_simultaneous_start_of_very_different_targets_is_refused_with_the_reason():
    with pytest.raises(InfeasibleDesign) as e:
        design_finger([90, 20, 20], 12, "simultaneous")
    msg = str(e.value)
    assert "joint 2 (20°)" in msg and "joint 1 (90°)" in msg and "proximal-first" in msg


#: A softest-joint stiffness that makes the stiffer joints unprintable: in the default (desktop) layout one
#: spring carries a joint's whole stiffness, and past about 40 N·mm/rad (at 50-65° preload, 90° rotation) its
#: strip needs an outer radius over the 20 mm limit. Every stiffness down to the builder's 0.2 prints.
TOO_STIFF = 40.0


@pytest.mark.slow  # many full rod-model verifications: full suite only (fast lane < 2 min)
def test_unprintable_stiffness_message_is_true():
    with pytest.raises(InfeasibleDesign) as e:
        design_finger([65, 50, 50], 25, base_stiffness=TOO_STIFF)
    msg = str(e.value)
    assert f"joint 2 would need K = {TOO_STIFF * 1.3:.2f}" in msg and "no printable spring" in msg
    assert "stiffest" in msg
    stiffest = float(msg.split("gives ")[1].split(" ")[0])
    arm = 25 / math.radians(165)
    # the quoted stiffest spring is printable, and a little more is not
    assert buildable(stiffest, 50 * DEG, 90 * DEG, arm)
    assert not buildable(stiffest * 1.1, 50 * DEG, 90 * DEG, arm)
    assert not buildable(TOO_STIFF * 1.3, 50 * DEG, 90 * DEG, arm)
    # and the range it suggests does work
    hi = float(msg.split("stiffness of ")[1].split("-")[1].split(" ")[0])
    d = design_finger([65, 50, 50], 25, base_stiffness=hi * 0.98)
    assert max(abs(x) for x in d.end_error_deg) < 1.0


@pytest.mark.slow  # many full rod-model verifications: full suite only (fast lane < 2 min)
def test_preferred_stiffness_is_rescaled_to_the_nearest_printable_one():
    q = np.array([1.0, 1.3, 1.3])
    th0 = np.radians([65, 50, 50])
    rot = np.radians([90, 90, 90])
    k, notes = _printable_scale(TOO_STIFF, q, th0, rot, 8.68, "absplus-p430", "generic-0.4", strict=False)
    assert k < TOO_STIFF and notes and "rescaled" in notes[0]
    assert all(buildable(k * qi, p, r, 8.68) for qi, p, r in zip(q, th0, rot))
    assert not all(buildable(k * 1.05 * qi, p, r, 8.68) for qi, p, r in zip(q, th0, rot))  # the nearest one


@pytest.mark.parametrize("span", [(0, 89), (0, 83), (5, 89), (17, 18), (40, 40), (9, 10), (3, 70), None])
def test_the_printable_span_is_the_one_every_grid_point_gives(monkeypatch, span):
    """printable_stiffness tries a coarse grid and bisects the span's edges: on a builder that accepts exactly the
    grid points ``span`` (inclusive; None: none), it gives what trying every grid point gives, in fewer tries."""
    from rjcad.physics import inverse

    ks = np.geomspace(*inverse.STIFFNESS_RANGE, 90)
    tried = []

    def fake(k, *args):
        i = int(np.argmin(np.abs(np.log(ks / k))))
        tried.append(i)
        return None if span is not None and span[0] <= i <= span[1] else RjcadError("no")

    monkeypatch.setattr(inverse, "_buildable", fake)
    inverse.printable_stiffness.cache_clear()
    try:
        got_ks, ok = inverse.printable_stiffness(1.0, 1.5, 8.0, "m", "p")
    finally:
        inverse.printable_stiffness.cache_clear()
    want = np.array([span is not None and span[0] <= i <= span[1] for i in range(90)])
    assert np.array_equal(got_ks, ks) and np.array_equal(ok, want)
    hit_coarse = span is not None and any(span[0] <= i <= span[1] for i in [*range(0, 90, inverse.COARSE), 89])
    assert len(tried) <= (25 if hit_coarse else 90 + 13)


def test_arm_limits_come_from_the_builder():
    lo, hi = arm_range("absplus-p430", "generic-0.4")
    assert buildable(5.2, 90 * DEG, 90 * DEG, lo + 1e-6) and not buildable(5.2, 90 * DEG, 90 * DEG, lo - 0.01)
    assert hi == 15.0
    with pytest.raises(InfeasibleDesign, match=r"moment arm of 2\.\d\d mm"):
        design_finger([65, 50, 50], 8)


def test_the_written_template_is_accepted_by_the_finger_builder(tmp_path):
    from rjcad.design.finger_params import FingerParams

    d = design_finger([90, 20, 20], 12, "proximal-first")
    p = tmp_path / "f.toml"
    p.write_text(d.template())
    fp = FingerParams.from_toml(p)
    assert [j.stiffness for j in fp.joints] == pytest.approx(d.stiffness, abs=1e-4)
    assert [j.moment_arm for j in fp.joints] == pytest.approx(d.moment_arm, abs=1e-4)


# ---------------------------------------------------------------- the paper's finger as a target (from test_physics.py)


@pytest.mark.parametrize("sequence", ["simultaneous", "proximal-first"])
def test_inverse_design_reaches_the_target(sequence, tmp_path):
    from rjcad.design.finger_params import FingerParams
    from rjcad.physics.inverse import design_finger

    d = design_finger([65, 50, 50], 25, sequence)
    assert max(abs(e) for e in d.end_error_deg) < 1.0
    on = d.onset_mm
    if sequence == "proximal-first":
        assert on[0] < on[1] - 1.0 and abs(on[1] - on[2]) < 0.5
    else:
        assert max(on) - min(on) < 0.5
    # the template it writes is a valid finger for the builder, and re-simulates to the target
    path = tmp_path / "f.toml"
    path.write_text(d.template())
    fp = FingerParams.from_toml(path)
    assert [round(p.stiffness, 3) for p in fp.joints] == [round(k, 3) for k in d.stiffness]
    m = fm.model_from_template(tomllib.loads(path.read_text()))
    c = fm.simulate_stroke(m, 25, 400)
    assert np.degrees(c.theta[400]) == pytest.approx([65, 50, 50], abs=1.0)


@pytest.mark.slow  # the longest test of the fast lane (a search over moment arms before it gives up)
def test_inverse_design_unreachable_targets_say_why():
    from rjcad.physics.inverse import design_finger

    with pytest.raises(InfeasibleDesign, match="moment arm"):
        design_finger([65, 50, 50], 80)
    with pytest.raises(InfeasibleDesign, match="no printable spring"):
        design_finger([65, 50, 50], 25, base_stiffness=TOO_STIFF)
    with pytest.raises(ParameterError):
        design_finger([65, 150, 50], 25)
