"""Issue 36: the finger's physics takes each joint's friction from its own bearing model (rjcad.physics.bearing_band).

The finger's solver gets a linear band per joint, f0 + γ±·(θ + θ0), fitted to the bearing's friction. What the
solver then does is checked here against a simulator written for the test: at the tension the finger's run
reports, each slipping joint's angle is found directly from its own bearing, r·T = K·(θ + θ0) ± μ·S(θ, T), with
S from the bearing's contact solve at that very tension (no band, no fit, no self-consistent drive).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from rjcad.design.finger_params import DEFAULT_FINGER, PAPER_FINGER, FingerParams
from rjcad.design.params import JointParams
from rjcad.physics import bearing as B
from rjcad.physics.bearing_band import JointLocked, band, with_bearing_friction
from rjcad.physics.finger import CLOSING, OPENING, FingerModel, model_from_template, simulate_stroke


def _stiffness(p: JointParams) -> float:
    """The springs' linear stiffness, the finger model's K [N·mm/rad]."""
    return p.springs * p.spring.rod.stiffness


def _exact_angle(p: JointParams, mu: float, tension: float, s: int, springs, contacts) -> float:
    """θ_j where r·T = K·(θ + θ0) + s·μ·S(θ, T) for this T (the joint slipping in direction s; K the finger
    model's, so that only the friction differs); the stop where the balance lies beyond it."""

    def h(theta: float) -> float:
        state = B.solve(contacts, [B.tendon_load(p, tension, theta), *springs.loads(theta)], 1.0)
        return p.moment_arm * tension - _stiffness(p) * (theta + p.preload) - s * mu * state.friction_torque

    lo, hi = h(0.0), h(p.rotation)
    if lo * hi > 0:
        return p.rotation if lo > 0 else 0.0
    return float(brentq(h, 0.0, p.rotation, xtol=1e-7))


def _model_of(joints) -> FingerModel:
    """The finger model of these designs: the springs' own stiffness and the design's preload, range and arm."""
    return FingerModel(
        stiffness=tuple(_stiffness(p) for p in joints),
        preload=tuple(p.preload for p in joints),
        rotation=tuple(p.rotation for p in joints),
        moment_arm=tuple(p.moment_arm for p in joints),
    )


def test_the_band_fits_the_bearings_friction_and_a_tendon_closes_harder_than_it_opens():
    """The default desktop joint at μ 0.3: the linear band is within 1 % of the bearing's largest friction; the
    tendon's own load on the bearing adds to the tension while pulling, so γ⁺ > γ⁻ (docs/bearing.md)."""
    b = band(JointParams(), 0.3)
    assert b.largest < 0.01 * b.largest_friction
    assert b.gamma_pos > 2 * b.gamma_neg > 0
    assert band(JointParams(), 0.0).largest_friction == 0.0


@pytest.mark.parametrize("mu, within_deg", [(0.3, 1.0), (0.4, 5.0)])
def test_the_fingers_closure_is_each_joints_own_bearing_balance(mu, within_deg):
    """The default finger's three joints with their bearing bands at μ: every reading where a joint slips
    (closing while pulled, opening while released) puts it where its own bearing balances the tension of that
    reading, within 1° at μ 0.3, on both branches; at μ 0.4, near joint 1's lock (0.416), the linear band is
    off by up to 5 % of the friction, and the angles by up to 5° (docs/bearing.md)."""
    joints = FingerParams.from_dict(DEFAULT_FINGER).joints
    model, bands = with_bearing_friction(_model_of(joints), joints, mu)
    c = simulate_stroke(model, 30.0, steps=120)
    springs = [B.spring_forces(p) for p in joints]
    contacts = [B.contacts_of(p) for p in joints]
    checked, worst = 0, 0.0
    for i, p in enumerate(joints):
        for state, s in ((CLOSING, 1), (OPENING, -1)):
            rows = np.flatnonzero(c.state[:, i] == state)
            for k in rows[:: max(1, len(rows) // 6)]:
                want = _exact_angle(p, mu, float(c.joint_tension[k, i]), s, springs[i], contacts[i])
                worst = max(worst, math.degrees(abs(c.theta[k, i] - want)))
                checked += 1
    assert checked >= 24  # every joint, both ways
    assert worst < within_deg
    fit = max(b.largest / b.largest_friction for b in bands)
    assert fit < 0.015 if mu < 0.4 else 0.03 < fit < 0.06


def test_bearing_friction_changes_which_joint_closes_first():
    """Frictionless, the default finger's distal joint lags (its spring is the stiffest); with the bearing's
    friction at the assumed μ 0.4, the proximal joint lags (its bearing is the most loaded: the tendon pulls
    highest above its collar) and the tendon needs many times the tension."""
    joints = FingerParams.from_dict(DEFAULT_FINGER).joints
    bare = _model_of(joints)
    rough, _ = with_bearing_friction(bare, joints, 0.4)
    free, held = simulate_stroke(bare, 25.0, steps=100), simulate_stroke(rough, 25.0, steps=100)
    assert np.argmin(free.theta[100]) == 2 and np.argmin(held.theta[100]) == 0
    assert held.tension[100] > 5 * free.tension[100]


def test_a_joint_that_locks_is_named():
    joints = FingerParams.from_dict(DEFAULT_FINGER).joints
    with pytest.raises(JointLocked, match=r"joint 1: its bearing locks at μ = 0\.5"):
        with_bearing_friction(_model_of(joints), joints, 0.5)


def test_the_paper_finger_on_its_pins_has_a_narrow_band():
    """The paper's finger (stacked, on pins) at μ 0.4: its bands are a few N·mm, below the paper's own γ± (1.89,
    3.15 N·mm/rad: docs/bearing.md says why the pin's load path cannot make them)."""
    m = model_from_template(PAPER_FINGER)
    joints = FingerParams.from_dict(PAPER_FINGER).joints
    _, bands = with_bearing_friction(m, joints, 0.4)
    assert all(b.gamma_pos < 1.89 and b.gamma_neg < 3.15 and b.largest_friction < 6.0 for b in bands)


# ---- the CLI ---------------------------------------------------------------------------------------------------


def test_simulate_finger_with_bearing_friction(cli, root):
    r = cli("simulate", "finger", root / "templates" / "finger.toml", "--friction", "bearing", "--mu", "0.3", "--json")
    assert r.code == 0, r.err
    d = json.loads(r.out)
    assert [b["mu"] for b in d["bearing_friction"]] == [0.3] * 3
    assert d["bearing_friction"][0]["gamma_pos_nmm_per_rad"] == pytest.approx(14.04, abs=0.05)
    text = cli("simulate", "finger", root / "templates" / "finger.toml", "--friction", "bearing", "--mu", "0.3")
    assert text.code == 0 and text.out.count("bearing band at μ 0.3") == 3 and "RMS" in text.out


@pytest.mark.parametrize(
    "args, said",
    [
        (["--mu", "0.3"], "--mu: only with --friction bearing"),
        (["--friction", "bearing", "--engine", "mujoco"], "MuJoCo's joint friction is a constant"),
        (["--friction", "bearing", "--compare"], "rjcad's engine only"),
        (["--friction", "bearing", "--mu", "3"], "--mu"),
        (["--friction", "bearing", "--mu", "0.5"], "too high for this finger: joint 1: its bearing locks"),
        (["--friction", "bearing", "--object", "cylinder:diameter=30,x=20,y=25", "--engine", "mujoco"], "MuJoCo's"),
    ],
)
def test_what_cannot_take_the_bearings_friction_is_one_line(cli, root, args, said):
    r = cli("simulate", "finger", root / "templates" / "finger.toml", *args)
    assert r.code == 2 and said in r.err and "Traceback" not in r.err and r.out == ""


# ---- where the bearing locks --------------------------------------------------------------------------------


def test_the_locking_mu_is_where_the_self_consistent_drive_fails():
    """bearing.locking_mu, from the tendon's load alone, against the self-consistent drive (bearing.driven, a
    fixed point with the springs' loads too): at 0.95× it every pose turns, at 1.01× some pose locks."""
    p = FingerParams.from_dict(DEFAULT_FINGER).joints[0]
    lock = B.locking_mu(p)
    assert 0.3 < lock < 0.6
    poses = np.linspace(0.0, p.rotation, 13)
    springs = B.spring_forces(p)
    for t in poses:
        B.driven(p, 0.95 * lock, float(t), 1, springs=springs)
    locked = 0
    for t in poses:
        try:
            B.driven(p, 1.01 * lock, float(t), 1, springs=springs)
        except B.BearingLocked:
            locked += 1
    assert locked >= 1


def test_the_stacked_pin_locks_where_its_radius_says():
    """On its pin (no tilt), the eye carries the tendon's T on the pin's surface: Σ N·ρ = ρ_pin·T (up to the
    36-point ring's facets), so it locks at μ = r/ρ_pin: about 3, far above dry plastic."""
    p = JointParams(layout="stacked")
    rho = {round(c.radius, 9) for c in B.contacts_of(p) if c.surface == "pin"}
    r_pin = next(iter(rho))
    lock = B.locking_mu(p)
    assert (
        p.moment_arm / r_pin * math.cos(math.pi / B.AZIMUTHS) * (1 - 1e-9) <= lock <= p.moment_arm / r_pin * (1 + 1e-9)
    )


def test_a_grasp_with_the_bearings_friction(cli, root):
    """simulate finger --object with --friction bearing: the grasp's solver takes the bands (its JSON lists them),
    the API's grasp gives the same closure, and at μ 0.3 and 10 N the default finger wraps the cylinder less."""
    import rjcad

    cyl = ("--object", "cylinder:diameter=30,x=20,y=25", "--json")
    bare = json.loads(cli("simulate", "finger", root / "templates" / "finger.toml", *cyl).out)
    r = cli("simulate", "finger", root / "templates" / "finger.toml", *cyl, "--friction", "bearing", "--mu", "0.3")
    assert r.code == 0, r.err
    rough = json.loads(r.out)
    assert len(rough["bearing_friction"]) == 3
    assert sum(rough["theta_deg"][-1]) < sum(bare["theta_deg"][-1]) - 30
    api = rjcad.grasp(root / "templates" / "finger.toml", rjcad.Cylinder(x=20, y=25, diameter=30), bearing_mu=0.3)
    np.testing.assert_allclose(api.to_dict()["theta_deg"], rough["theta_deg"], atol=1e-9)
