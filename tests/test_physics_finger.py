"""Finger statics: every step of a stroke checked against the equilibrium and stick-slip conditions
(independently of the solver), capstan factors both ways, gravity, slack, and the input files."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import minimize

from rjcad.errors import ParameterError, RjcadError
from rjcad.io.templates import PAPER_FINGER
from rjcad.physics import finger as fm

DEG = math.pi / 180
TOL = 1e-6  # N·mm


def frictional_finger(**kw):
    base = dict(
        stiffness=(5.2, 7.8, 10.4),
        preload=(60 * DEG, 45 * DEG, 30 * DEG),
        rotation=(90 * DEG,) * 3,
        moment_arm=(6.0, 7.0, 8.0),
        wrap=(0.45, 0.3, 0.3),
        mu_t=0.25,
        friction=(3.0, 2.0, 1.0),
        gamma=(1.0, 0.5, 0.5),
    )
    base.update(kw)
    return fm.FingerModel(**base)


def check_conditions(m: fm.FingerModel, c: fm.Closure):
    """The solver's answer must satisfy, at every step and joint, the conditions the model states."""
    K, th0, thmax, r = (np.array(v) for v in (m.stiffness, m.preload, m.rotation, m.moment_arm))
    f0, gp, gn = np.array(m.friction), np.array(m.gamma_pos), np.array(m.gamma_neg)
    for k in range(len(c.tendon_mm)):
        th = c.theta[k]
        drive = r * c.joint_tension[k]  # torque the tendon gives each joint
        spring = K * (th + th0) + fm.gravity_torques(m, th)  # with the links' weight at this reading's angles
        hi, lo = f0 + gp * (th + th0), f0 + gn * (th + th0)  # the band: closing needs hi, opening −lo
        net = drive - spring
        inside = (th > 1e-9) & (th < thmax - 1e-9)
        assert np.all((net[inside] <= hi[inside] + TOL) & (net[inside] >= -lo[inside] - TOL)), (k, net, hi, lo)
        assert np.all(net[th <= 1e-9] <= hi[th <= 1e-9] + TOL)  # the rest stop can only push back
        assert np.all(net[th >= thmax - 1e-9] >= -lo[th >= thmax - 1e-9] - TOL)
        if k:  # a joint that moved sits on the edge of its band, on the side of its motion
            moved = c.theta[k] - c.theta[k - 1]
            up, dn = (moved > 1e-9) & (th < thmax - 1e-9), (moved < -1e-9) & (th > 1e-9)
            assert np.allclose(net[up], hi[up], atol=1e-6)
            assert np.allclose(net[dn], -lo[dn], atol=1e-6)
        # the tendon: taut → Σ r·θ = t_d (inextensible); slack → T = 0 and the finger holds at least t_d
        if c.tension[k] > 0:
            assert r @ th == pytest.approx(c.tendon_mm[k], abs=1e-6)
        else:
            assert r @ th >= c.tendon_mm[k] - 1e-6
        assert c.tension[k] >= 0


def test_every_step_is_an_equilibrium_with_stick_slip():
    m = frictional_finger()
    c = fm.simulate_stroke(m, 22.0, 300)
    check_conditions(m, c)
    # stick is real: after the reversal joints 1 and 2 hold while the tendon moves (an inextensible tendon
    # lets only the joint whose band is left first open), and the actuator tension falls across the bands
    rev = 301
    assert np.all(c.state[rev : rev + 5, :2] == 0) and np.all(c.theta[rev : rev + 5, :2] == c.theta[300, :2])
    assert np.all(c.state[rev : rev + 5, 2] == -1)
    assert c.tension[rev] < 0.6 * c.tension[300]
    # a joint starts only once the tension reaching it leaves its band: later than without friction
    # (joint 3, the first to move, must start at once: the tendon is inextensible)
    free = fm.simulate_stroke(frictional_finger(friction=(0,) * 3, gamma=(0,) * 3), 22.0, 300)
    on, on_free = fm.onset_tendon(c, 0.1 * DEG), fm.onset_tendon(free, 0.1 * DEG)
    assert on[0] > on_free[0] + 2.0 and on[1] > on_free[1] + 0.3


def test_conditions_hold_with_gravity_and_a_slack_release():
    """With heavy links and wide bands, palm up, every reading meets every condition with the weight's torque at
    its own angles (the joints coupled through the weight, rjcad.physics.coupled). Without the weight the springs
    cannot overcome the friction on the way back: the tendon goes slack."""
    m = frictional_finger(
        friction=(12.0, 8.0, 6.0), link_mass=(20.0, 15.0, 10.0), gravity=(0.0, -1.0), preload=(30 * DEG,) * 3
    )
    c = fm.simulate_stroke(m, 25.0, 200)
    check_conditions(m, c)
    # the weight opens the finger on the way back: joint 1, stuck at 13.7° by its band alone, falls back to 0
    assert c.theta[-1, 0] == 0.0 and np.degrees(c.theta[:, 0]).max() > 13.0
    m0 = frictional_finger(friction=(12.0, 8.0, 6.0), preload=(30 * DEG,) * 3)
    c0 = fm.simulate_stroke(m0, 25.0, 200)
    check_conditions(m0, c0)
    assert np.any(c0.slack[201:])  # releasing, the springs cannot overcome the friction: the tendon goes slack


def test_release_path_differs_from_pull_path():
    m = frictional_finger()
    c = fm.simulate_stroke(m, 22.0, 300)
    pull, release = c.theta[:301], c.theta[301:][::-1]  # release[k] is at the same t_d as pull[k]
    assert np.max(np.abs(release - pull[:-1])) > 5 * DEG
    # the proximal joint (widest band) stays closed longer on the way back, the distal one (narrowest) opens
    # first: at the same t_d the release is more proximal, the tendon constraint keeping Σ r·θ the same
    assert np.all(release[:, 0] >= pull[:-1, 0] - 1e-9) and np.max(release[:, 0] - pull[:-1, 0]) > 20 * DEG
    assert np.all(release[:, 2] <= pull[:-1, 2] + 1e-9)


def test_capstan_factor_each_way():
    m = frictional_finger()
    c = fm.simulate_stroke(m, 22.0, 100)
    cum = np.cumsum(m.wrap)
    pull = np.array([p == "pull" for p in c.phase])
    rel = np.array([p == "release" for p in c.phase])
    assert c.joint_tension[pull] == pytest.approx(c.tension[pull, None] * np.exp(-m.mu_t * cum))
    assert c.joint_tension[rel] == pytest.approx(c.tension[rel, None] * np.exp(m.mu_t * cum))
    # the tension at the actuator is higher pulling than releasing at the same t_d
    assert np.all(c.tension[20:100] > c.tension[101:][::-1][20:100])


def test_gravity_torque_of_one_horizontal_link():
    m = fm.FingerModel((5.0,), (0.5,), (90 * DEG,), (6.0,), link_mass=(30.0,), link_length=(40.0,), gravity=(0.0, -1.0))
    assert fm.gravity_torques(m, np.array([0.0]))[0] == pytest.approx(30 * 9.81e-3 * 20.0)
    assert fm.gravity_torques(m, np.array([90 * DEG]))[0] == pytest.approx(0.0, abs=1e-9)
    # pointing down (gravity along +x): the weight pulls the link towards the axis, no torque either way
    m2 = fm.FingerModel((5.0,), (0.5,), (90 * DEG,), (6.0,), link_mass=(30.0,), gravity=(1.0, 0.0))
    assert fm.gravity_torques(m2, np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-9)


def test_gravity_slope_is_the_torques_derivative():
    """∂τ_i/∂θ_i of gravity_terms against central differences of gravity_torques (links off their axes too)."""
    m = fm.FingerModel(
        (5.0, 6.0, 7.0),
        (1.0, 1.0, 1.0),
        (1.5, 1.5, 1.5),
        (6.0, 6.0, 6.0),
        link_mass=(20.0, 15.0, 10.0),
        link_length=(40.0, 35.0, 30.0),
        link_com=((18.0, 2.0), (15.0, -1.0), (12.0, 3.0)),
        gravity=(0.6, 0.8),
    )
    rng = np.random.default_rng(5)
    for _ in range(5):
        th = rng.uniform(0, 1.5, 3)
        _, slope = fm.gravity_terms(m, th)
        for i in range(3):
            e = np.zeros(3)
            e[i] = 1e-6
            d = (fm.gravity_torques(m, th + e)[i] - fm.gravity_torques(m, th - e)[i]) / 2e-6
            assert slope[i] == pytest.approx(d, rel=1e-6, abs=1e-9)


@pytest.mark.parametrize("gravity", [(1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (-1.0, 0.0)])
def test_heavy_links_each_reading_is_an_equilibrium(gravity):
    """Links whose weight is stiffer than their springs (40/30/20 g on 40 mm links): every reading balances each
    free joint, r·T = K(θ + θ0) + τ_g(θ) to 1e-3 N·mm (and K(θ + θ0) + τ_g ≥ r·T at the straight stop, ≤ at the
    limit). With the weight taken at the previous angles only, these flipped by up to 90° from step to step."""
    m = fm.model_from_template(PAPER_FINGER)
    m = fm.FingerModel(
        m.stiffness,
        m.preload,
        m.rotation,
        m.moment_arm,
        link_mass=(40.0, 30.0, 20.0),
        link_length=m.link_length,
        gravity=gravity,
    )
    c = fm.simulate_stroke(m, 25.0, 250)
    K, th0, thmax, r, *_ = m.arrays()
    unbalanced = 0
    for th, T in zip(c.theta, c.tension):
        net = r * T - (K * (th + th0) + fm.gravity_torques(m, th))  # flexing torque left over [N·mm]
        free = (th > 1e-9) & (th < thmax - 1e-9)
        ok = np.where(free, np.abs(net) < 1e-3, np.where(th <= 1e-9, net < 1e-3, net > -1e-3))
        unbalanced += int(not ok.all())
    moved = np.degrees(np.abs(np.diff(c.theta, axis=0))).max()
    assert unbalanced == 0, unbalanced
    if gravity[0] >= 0 and gravity != (0.0, -1.0):  # hanging or palm down: one smooth branch, no snap
        assert moved < 1.0, moved


def small_manifest():
    """A two-joint manifest in the finger builder's format (only the keys the physics reads matter)."""
    spring = {"stiffness_nmm_per_rad": 2.6, "width_mm": 5.0, "thickness_mm": 0.8, "length_mm": 120.0}
    joints = []
    for i, (k, arm, wrap) in enumerate(((4.0, 6.5, 0.45), (6.0, 7.5, 0.0)), start=1):
        joints.append(
            {
                "parent": "base" if i == 1 else "link1",
                "child": "link1" if i == 1 else "distal",
                "axis_point_mm": [40.0 * (i - 1), 0, 0],
                "axis_dir": [0, 0, 1],
                "joint_stiffness_nmm_per_rad": k,
                "spring": spring,
                "preload_deg": 80,
                "rotation_deg": 95,
                "tendon_moment_arm_mm": arm,
                "tendon_wrap_angle_rad": wrap,
            }
        )
    return {
        "joints": joints,
        "tendon_length_mm": 110.0,
        "bodies": [
            {"name": "base", "volume_mm3": 9000.0, "mass_g": 9.4},
            {"name": "link1", "volume_mm3": 15000.0, "mass_g": 15.6},
            {"name": "distal", "volume_mm3": 8000.0, "mass_g": 8.3},
        ],
    }


def test_manifest_file_is_read_whole(tmp_path):
    p = tmp_path / "finger.json"
    p.write_text(json.dumps(small_manifest()))
    m = fm.load_finger_model(str(p), mu_t=0.2)
    assert m.stiffness == (4.0, 6.0) and m.moment_arm == (6.5, 7.5) and m.wrap == (0.45, 0.0)
    assert m.preload == pytest.approx((80 * DEG,) * 2) and m.rotation == pytest.approx((95 * DEG,) * 2)
    assert m.link_mass == (15.6, 8.3) and m.mu_t == 0.2  # the child body of each joint


@pytest.mark.parametrize(
    "edit, name",
    [
        (lambda d: d["joints"][1].pop("tendon_moment_arm_mm"), "joints[2].tendon_moment_arm_mm"),
        (lambda d: d["joints"][0].update(preload_deg="ninety"), "joints[1].preload_deg"),
        (lambda d: d.update(joints=[]), "joints"),
    ],
)
def test_bad_manifest_names_the_key(tmp_path, edit, name):
    d = small_manifest()
    edit(d)
    p = tmp_path / "finger.json"
    p.write_text(json.dumps(d))
    with pytest.raises(ParameterError) as e:
        fm.load_finger_model(str(p))
    assert e.value.parameter == name


def test_template_physics_keys_defaults_and_errors(tmp_path):
    t = tmp_path / "f.toml"
    t.write_text(
        'material = "pla"\nclearance_mm = 0.3\n[defaults]\npreload_deg = 80\n'
        "[[joint]]\nstiffness_nmm_per_rad = 5.2\n"
        "[[joint]]\nstiffness_nmm_per_rad = 7.8\ntendon_moment_arm_mm = 8.5\nrotation_deg = 100\n"
    )
    m = fm.load_finger_model(str(t))
    assert m.moment_arm == (6.0, 8.5) and m.wrap == (0.0, 0.0)  # 6 mm unless given, no wrap in a template
    assert m.preload == pytest.approx((80 * DEG,) * 2) and m.rotation == pytest.approx((90 * DEG, 100 * DEG))
    t.write_text("[[joint]]\nstiffness_nmm_per_rad = 5.2\n[[joint]]\npreload_deg = true\nstiffness_nmm_per_rad = 3\n")
    with pytest.raises(ParameterError, match=r"joint\[2\]\.preload_deg"):
        fm.load_finger_model(str(t))
    t.write_text("[[joint]\n")
    with pytest.raises(RjcadError, match="not valid TOML"):
        fm.load_finger_model(str(t))


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"rotation": (0.0,)}, "rotation"),
        ({"mu_t": -0.1}, "mu_t"),
        ({"friction": (-1.0,)}, "friction"),
        ({"moment_arm": (math.inf,)}, "moment_arm"),
        ({"damping": (-0.1,)}, "damping"),
        ({"cubic": (1.0, 2.0)}, "cubic"),
        ({"relax_time": 0.0}, "relax_time"),
    ],
)
def test_bad_model_parameters(kw, name):
    base = dict(stiffness=(5.0,), preload=(0.5,), rotation=(1.5,), moment_arm=(6.0,))
    base.update(kw)
    with pytest.raises(ParameterError) as e:
        fm.FingerModel(**base)
    assert e.value.parameter == name


def test_the_condition_checker_rejects_a_wrong_answer():
    """The checker has teeth: the frictionless answer is not an equilibrium of the frictional finger."""
    m = frictional_finger()
    wrong = fm.simulate_stroke(frictional_finger(friction=(0,) * 3, gamma=(0,) * 3), 22.0, 100)
    with pytest.raises(AssertionError):
        check_conditions(m, wrong)


# ---------------------------------------------------------------- the paper's finger: honest uncertainties


def test_fit_uncertainty_says_not_identified_when_it_is_not():
    from rjcad.physics.uncertainty import parameter_std as _std

    rng = np.random.default_rng(1)
    J = rng.normal(size=(3, 2))
    lb, ub = np.zeros(2), np.full(2, 10.0)
    x = np.array([2.0, 3.0])
    std, why = _std(J, x, lb, ub, ["a", "b"])
    assert std == pytest.approx(np.sqrt(np.diag(np.linalg.inv(J.T @ J)))) and why == ["", ""]
    std, why = _std(np.c_[J[:, :1], np.zeros(3)], x, lb, ub, ["a", "b"])
    assert np.isnan(std[1]) and why[1] == "no effect"  # no effect on the fit
    both, why = _std(
        np.c_[J[:, :1], 2 * J[:, :1], J[:, 1:]], np.r_[x, 1.0], np.zeros(3), np.full(3, 10.0), ["a", "b", "c"]
    )
    assert np.isnan(both[0]) and np.isnan(both[1]) and np.isfinite(both[2])  # two that trade off exactly
    assert why == ["trades off with b", "trades off with a", ""]
    std, why = _std(J, np.array([0.0, 3.0]), lb, ub, ["a", "b"])
    assert np.isnan(std[0]) and why[0] == "at its bound"  # on its bound: rejected by the data


def test_paper_finger_interval_scaled_by_the_misfit():
    """A fit that leaves 21.7° RMS against an assumed 2° error: its Jacobian σ is multiplied by √(χ²/dof)."""
    from rjcad.physics import paper_finger as pf

    common = pf._fit("moment arm (common)", *pf.FAMILIES["moment arm (common)"])
    chi2 = float(np.sum(((np.array(common.end_deg) - pf.MEASURED_DEG) / pf.ANGLE_SIGMA_DEG) ** 2))
    assert common.scale == pytest.approx(np.sqrt(chi2 / 2), rel=1e-3) and common.scale > 10
    assert "(σ ×" in pf._fmt_param(common, "r_mm")
    per_joint = pf._fit("moment arms per joint", *pf.FAMILIES["moment arms per joint"])
    assert per_joint.scale == 1.0  # three numbers, three parameters: no dof, the interval stays as computed
    along = pf._fit(pf.CAPSTAN_ALONG, *pf.FAMILIES[pf.CAPSTAN_ALONG])
    assert "rejected by the data" in pf._fmt_param(along, "mu_alpha")


def test_paper_finger_capstan_and_friction_verdicts():
    from rjcad.physics import paper_finger as pf

    common = pf._fit("moment arm (common)", *pf.FAMILIES["moment arm (common)"])
    base = pf._fit(pf.CAPSTAN_BASE, *pf.FAMILIES[pf.CAPSTAN_BASE])
    fric = pf._fit(pf.FRICTION, *pf.FAMILIES[pf.FRICTION])
    assert base.rms_deg == pytest.approx(common.rms_deg, abs=0.01) and np.isnan(base.std["mu_alpha"])
    # a tension factor alike at every joint does not move them: the fit leaves μα anywhere, so no number is given
    assert pf._fmt_param(base, "mu_alpha") == "mu_alpha: any value (not identified: no effect on the end angles)"
    assert fric.rms_deg < 0.5 and not fric.sequence_ok and np.argmin(fric.onset_mm) == 2
    assert np.isfinite(fric.std["r_mm"]) and np.isnan(fric.std["f1_nmm"])


# ---------------------------------------------------------------- the paper's three-joint finger (from test_physics.py)


def paper_model(**kw):
    return fm.FingerModel((5.2, 7.8, 10.4), (90 * DEG,) * 3, (90 * DEG,) * 3, (6.0,) * 3, **kw)


@pytest.mark.parametrize("t_d", [1.0, 5.0, 12.0, 20.0, 25.0])
def test_frictionless_equals_the_energy_minimum(t_d):
    m = fm.FingerModel(
        (5.2, 7.8, 10.4), (90 * DEG, 60 * DEG, 40 * DEG), (90 * DEG, 80 * DEG, 100 * DEG), (6.0, 7.0, 8.0)
    )
    c = fm.simulate_path(m, np.linspace(0, t_d, 60))
    K, th0, thmax, r = (np.array(v) for v in (m.stiffness, m.preload, m.rotation, m.moment_arm))
    res = minimize(
        lambda x: 0.5 * np.sum(K * (x + th0) ** 2),
        np.full(3, 0.1),
        method="SLSQP",
        bounds=list(zip([0] * 3, thmax)),
        constraints=[{"type": "eq", "fun": lambda x: r @ x - t_d}],
        options={"ftol": 1e-14, "maxiter": 500},
    )
    assert res.success
    assert c.theta[-1] == pytest.approx(res.x, abs=1e-4)
    assert fm.frictionless_optimum(m, t_d) == pytest.approx(res.x, abs=1e-4)


def test_capstan_makes_the_proximal_joint_start_first():
    equal = fm.FingerModel((5.0,) * 3, (60 * DEG,) * 3, (90 * DEG,) * 3, (6.0,) * 3, wrap=(0.3, 0.3, 0.3), mu_t=0.3)
    onset = fm.onset_tendon(fm.simulate_stroke(equal, 15, 300))
    assert onset[0] < onset[1] < onset[2]


def test_stick_slip_and_release_hysteresis():
    m = fm.FingerModel((5.2,), (60 * DEG,), (90 * DEG,), (6.0,), friction=(2.0,), gamma=(0.5,), tendon_stiffness=2.0)
    c = fm.simulate_stroke(m, 8.0, 200)
    pull = c.theta[:201, 0]
    release = c.theta[201:, 0][::-1]  # same t_d as pull[:-1]
    p = pull[:-1]
    assert np.all(release >= p - 1e-12)  # at a fixed t_d the release angle is never smaller ...
    moving = (p > 0.05) & (p < p.max() - 0.05)
    assert moving.sum() > 50 and np.all(release[moving] > p[moving] + 1e-3)  # ... and larger while it moves
    # stick: right after the reversal the joint holds while the tension drops across the friction band
    assert np.any(c.state[201:210, 0] == 0)
    assert np.all(c.tension >= 0)


def test_three_joint_release_is_more_closed_and_stuck_joints_slacken_the_tendon():
    # a compliant tendon: at the same t_d the release closes the finger more (Σ r·θ larger)
    m = paper_model(friction=(3.0,) * 3, gamma=(1.0,) * 3, tendon_stiffness=3.0)
    c = fm.simulate_stroke(m, 20, 400)
    r = np.array(m.moment_arm)
    for k in (150, 250, 350):
        assert r @ c.theta[800 - k] >= r @ c.theta[k] - 1e-9
    # friction above the preload torque (the paper's own numbers): the spring cannot reopen the joint
    stuck = fm.FingerModel((5.19,), (70 * DEG,), (90 * DEG,), (6.0,), friction=(10.39,))
    s = fm.simulate_stroke(stuck, 6.0, 100)
    assert s.theta[-1, 0] > 0.1 and s.slack[-1] and s.tension[-1] == 0.0


def test_joint_limits_respected_and_tension_never_negative():
    c = fm.simulate_stroke(paper_model(wrap=(0.5, 0.2, 0.2), mu_t=0.2, friction=(1.0,) * 3), 30, 300)
    assert np.all(c.theta >= -1e-12) and np.all(c.theta <= 90 * DEG + 1e-12)
    assert np.all(c.tension >= 0) and np.all(c.joint_tension >= 0)
    # the tension reaching a joint is the actuator's times the capstan factor
    pull = np.array([p == "pull" for p in c.phase])
    f = np.exp(-0.2 * np.cumsum([0.5, 0.2, 0.2]))
    assert c.joint_tension[pull] == pytest.approx(c.tension[pull, None] * f)


def test_gravity_holds_a_joint_back():
    flat = paper_model()
    heavy = paper_model(link_mass=(50.0, 50.0, 50.0), gravity=(0.0, -1.0))
    a = fm.simulate_stroke(flat, 10, 100).theta[100]
    b = fm.simulate_stroke(heavy, 10, 100).theta[100]
    assert not np.allclose(a, b)
    # with gravity along −y, lifting the links (flexing towards +y) costs torque: the tension rises
    assert fm.simulate_stroke(heavy, 10, 100).tension[100] > fm.simulate_stroke(flat, 10, 100).tension[100]


def test_paper_finger_design_model_is_far_from_the_measurement():
    from rjcad.physics.paper_finger import MEASURED_DEG, baseline

    end, onset, _ = baseline(6.0)
    assert end[0] == pytest.approx(90.0)  # the soft proximal joint hits its stop
    assert np.max(np.abs(end - MEASURED_DEG)) > 8
    assert onset[0] < onset[1] < onset[2]


def test_paper_finger_explanations():
    from rjcad.physics import paper_finger as pf

    common = pf._fit("moment arm (common)", *pf.FAMILIES["moment arm (common)"])
    arms = pf._fit("moment arms per joint", *pf.FAMILIES["moment arms per joint"])
    pre = pf._fit("moment arm + distal preloads lower", *pf.FAMILIES["moment arm + distal preloads lower"])
    assert common.rms_deg > 10  # one arm cannot explain it
    assert arms.rms_deg < 0.5 and arms.sequence_ok  # longer distal arms: exact, order kept
    assert arms.params["r1_mm"] < arms.params["r2_mm"] < arms.params["r3_mm"]
    assert pre.rms_deg < 0.5 and not pre.sequence_ok  # lower distal preloads fit the angles, not the order


def test_paper_finger_doc_is_generated_and_current(tmp_path, root):
    doc = (root / "docs" / "paper-finger.md").read_text()
    assert (root / "docs" / "paper-finger.png").stat().st_size > 10_000
    assert "Generated by `rjcad paper-finger`" in doc


@pytest.mark.slow
def test_paper_finger_doc_regenerates_identically(tmp_path, root):
    from rjcad.physics.paper_finger import write_doc

    write_doc(tmp_path)
    assert (tmp_path / "paper-finger.md").read_text() == (root / "docs" / "paper-finger.md").read_text()


def test_asymmetric_bands_every_step_is_an_equilibrium():
    m = frictional_finger(gamma=(), gamma_pos=(1.0, 0.5, 0.5), gamma_neg=(2.5, 1.5, 3.0))
    check_conditions(m, fm.simulate_stroke(m, 22.0, 300))


def test_asymmetric_tendon_friction_one_joint():
    """One joint, no pin friction: the tendon fixes θ = t_d/r, and the tension is (K + γ⁺)(θ + θ0)/r while
    pulling, (K − γ⁻)(θ + θ0)/r while releasing (paper Eq. 4 with the paper's γ⁺ 1.89, γ⁻ 3.15 N·mm/rad)."""
    K, th0, r, gp, gn = 5.2, 60 * DEG, 6.0, 1.89, 3.15
    m = fm.FingerModel((K,), (th0,), (90 * DEG,), (r,), gamma_pos=(gp,), gamma_neg=(gn,))
    c = fm.simulate_stroke(m, 6.0, steps=50)
    pull = np.array([p == "pull" for p in c.phase])
    th = c.tendon_mm / r
    assert c.theta[:, 0] == pytest.approx(th, abs=1e-9)
    k = pull & (th > 0.05)
    assert c.tension[k] == pytest.approx((K + gp) * (th[k] + th0) / r, rel=1e-9)
    k = ~pull & (th > 0.05) & (th < th.max() - 0.2)  # past the stick zone at the turn
    assert c.tension[k] == pytest.approx((K - gn) * (th[k] + th0) / r, rel=1e-9)


def test_gamma_shorthand_and_contradiction():
    sym = fm.FingerModel((5.2,), (1.0,), (1.5,), (6.0,), gamma=(1.0,))
    assert sym.gamma_pos == sym.gamma_neg == (1.0,)
    asym = fm.FingerModel((5.2,), (1.0,), (1.5,), (6.0,), gamma_pos=(1.0,), gamma_neg=(2.0,))
    from dataclasses import replace

    assert replace(asym, mu_t=0.1).gamma_neg == (2.0,)  # rebuilt from its own fields
    with pytest.raises(ParameterError, match="gamma"):
        fm.FingerModel((5.2,), (1.0,), (1.5,), (6.0,), gamma=(1.0,), gamma_neg=(2.0,))
    with pytest.raises(ParameterError, match="gamma_neg"):
        fm.FingerModel((5.2,), (1.0,), (1.5,), (6.0,), gamma_neg=(5.2,))


def test_larger_gamma_neg_opens_later_on_release():
    """Two joints: a larger γ⁻ narrows the opening band's lower edge, so joints stay closed longer on release."""
    base = dict(
        stiffness=(5.2, 7.8),
        preload=(90 * DEG,) * 2,
        rotation=(90 * DEG,) * 2,
        moment_arm=(6.0, 6.0),
        friction=(1.0, 1.0),
    )
    lo = fm.simulate_stroke(fm.FingerModel(**base, gamma_pos=(1.89,) * 2, gamma_neg=(1.89,) * 2), 12.0, 200)
    hi = fm.simulate_stroke(fm.FingerModel(**base, gamma_pos=(1.89,) * 2, gamma_neg=(3.15,) * 2), 12.0, 200)
    pull = np.array([p == "pull" for p in lo.phase])
    assert lo.theta[pull] == pytest.approx(hi.theta[pull])  # γ⁻ plays no part while pulling
    assert (hi.tension[~pull] <= lo.tension[~pull] + 1e-12).all()
    assert (hi.tension[~pull] < lo.tension[~pull] - 1e-3).any()


# --- rate and wind-up effects (issue #18: the joint catalogue's viscous, stiffening and relaxation per joint) ---


def _ramp(stroke, seconds, n=400, hold_s=0.0, hold_n=0):
    """A pull from 0 to ``stroke`` mm in ``seconds`` (uniform speed), then a hold: (t_s, tendon_mm)."""
    t = np.linspace(0.0, seconds, n)
    td = np.linspace(0.0, stroke, n)
    if hold_n:
        t = np.r_[t, seconds + np.linspace(0.0, hold_s, hold_n + 1)[1:]]
        td = np.r_[td, np.full(hold_n, stroke)]
    return t, td


@pytest.mark.parametrize("t_d", [8.0, 16.0, 24.0])
def test_stiffening_equals_the_energy_minimum(t_d):
    """Springs K·s + k3·s³ (s = θ + θ0): the quasi-static answer is the minimum of Σ(½K s² + ¼k3 s⁴) under the tendon
    constraint (SLSQP, which shares nothing with the solver's step linearisation)."""
    k3 = np.array([0.15, 0.2, 0.1])
    m = fm.FingerModel(
        (5.2, 7.8, 10.4),
        (90 * DEG, 60 * DEG, 40 * DEG),
        (90 * DEG, 80 * DEG, 100 * DEG),
        (6.0, 7.0, 8.0),
        cubic=tuple(k3),
    )
    c = fm.simulate_path(m, np.linspace(0, t_d, 400))
    K, th0, thmax, r = (np.array(v) for v in (m.stiffness, m.preload, m.rotation, m.moment_arm))
    res = minimize(
        lambda x: np.sum(0.5 * K * (x + th0) ** 2 + 0.25 * k3 * (x + th0) ** 4),
        np.full(3, 0.1),
        method="SLSQP",
        bounds=list(zip([0] * 3, thmax)),
        constraints=[{"type": "eq", "fun": lambda x: r @ x - t_d}],
        options={"ftol": 1e-14, "maxiter": 500},
    )
    assert res.success
    assert c.theta[-1] == pytest.approx(res.x, abs=2e-3)  # the step linearisation's error: O(k3·s·Δθ²) per step
    soft = fm.simulate_path(fm.FingerModel(m.stiffness, m.preload, m.rotation, m.moment_arm), np.linspace(0, t_d, 400))
    assert c.tension[-1] > soft.tension[-1]  # stiffer springs need more tension for the same stroke


def test_damping_vanishes_when_pulled_slowly_and_lags_when_fast():
    """Viscous damping: a pull 1000× slower than another gives the rate-free angles; a fast pull needs more tension
    (c·θ̇ adds to the springs) and the joint that moves most carries most of it."""
    m0 = fm.FingerModel((5.2, 7.8, 10.4), (90 * DEG, 60 * DEG, 40 * DEG), (90 * DEG,) * 3, (6.0, 7.0, 8.0))
    m = replace(m0, damping=(0.6, 0.4, 0.3))
    ref = fm.simulate_path(m0, _ramp(20.0, 1.0)[1])
    slow = fm.simulate_path(m, _ramp(20.0, 1000.0)[1], t_s=_ramp(20.0, 1000.0)[0])
    fast = fm.simulate_path(m, _ramp(20.0, 1.0)[1], t_s=_ramp(20.0, 1.0)[0])
    assert slow.theta == pytest.approx(ref.theta, abs=1e-3) and slow.tension == pytest.approx(
        ref.tension, rel=1e-3, abs=1e-3
    )
    assert fast.tension[200] > ref.tension[200] * 1.01
    # at constant tendon speed v the damping torques sum to c·θ̇ with r·θ̇ summing to v: check the balance directly
    k = 200
    dth = (fast.theta[k] - fast.theta[k - 1]) / (1.0 / 399)
    K, th0, r = (np.array(v) for v in (m.stiffness, m.preload, m.moment_arm))
    moving = dth > 1e-6
    torque = K * (fast.theta[k] + th0) + np.array(m.damping) * dth
    assert (r * fast.joint_tension[k])[moving] == pytest.approx(torque[moving], rel=1e-9)
    with pytest.raises(ParameterError, match="t_s"):
        fm.simulate_path(m, _ramp(20.0, 1.0)[1])


def test_relaxation_tension_decays_to_the_relaxed_value_during_a_hold():
    """A Maxwell arm (K_M, T_r) beside each spring: right after a fast pull the tension is higher than the rate-free
    model's; held for 10·T_r it decays to it, exponentially with T_r (the decay over one T_r is 1 − 1/e of it)."""
    m0 = fm.FingerModel((5.2, 7.8, 10.4), (90 * DEG, 60 * DEG, 40 * DEG), (90 * DEG,) * 3, (6.0, 7.0, 8.0))
    tr = 1.5
    m = replace(m0, relax_stiffness=(1.5, 2.3, 3.1), relax_time=tr)
    t, td = _ramp(20.0, 0.2, n=200, hold_s=10 * tr, hold_n=3000)
    c = fm.simulate_path(m, td, t_s=t)
    ref = fm.simulate_path(m0, td).tension[-1]
    start = c.tension[199]
    assert start > 1.05 * ref and c.tension[-1] == pytest.approx(ref, rel=1e-3)
    i = int(np.searchsorted(t, t[199] + tr))
    assert (c.tension[i] - ref) / (start - ref) == pytest.approx(math.exp(-1), abs=0.02)
    assert np.all(np.diff(c.tension[199:]) <= 1e-12)  # monotone decay: nothing moves while the tendon is held
