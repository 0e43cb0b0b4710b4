"""Physics: joint hysteresis (paper Eq. 3-7), finger statics with stick-slip, the paper's finger, inverse design."""

import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize

from rjcad.errors import InfeasibleDesign, ParameterError
from rjcad.physics import finger as fm
from rjcad.physics.joint import PAPER_JOINT, JointModel, Setup, cycle, motion_direction, relaxation_torque, simulate

DEG = math.pi / 180
ROOT = Path(__file__).resolve().parents[1]


# ---------------------------------------------------------------- joint model

def loop(setup, model=PAPER_JOINT, rot=90):
    th, d = cycle(rot * DEG)
    return th, d, simulate(model, setup, th, direction=d)


def test_bar_test_mean_friction_level_is_10_39():
    th, d, tau = loop(Setup("bar", 1.5))
    up, dn = d > 0, d < 0
    # half the gap between the flexing and extending branches at the same angle = μ_j·F_n = 6.92·1.5
    width = np.interp(th[up], th[dn][::-1], tau[dn][::-1])
    level = np.mean(tau[up] - width) / 2
    assert level == pytest.approx(10.39, rel=0.01)
    # the mid line passes through zero torque at zero spring deformation, slope K_s = 5.19
    mid = (tau[up] + width) / 2
    slope, icpt = np.polyfit(th[up] + PAPER_JOINT.preload, mid, 1)
    assert slope == pytest.approx(5.19, rel=0.01) and abs(icpt) < 0.01  # N·mm (interpolation error)


def test_tendon_test_slopes_are_K_plus_minus_gamma():
    th, d, F = loop(Setup("tendon", 0.0))
    up, dn = d > 0, d < 0
    assert np.polyfit(th[up], 6.0 * F[up], 1)[0] == pytest.approx(5.19 + 1.89, rel=0.01)
    assert np.polyfit(th[dn], 6.0 * F[dn], 1)[0] == pytest.approx(5.19 - 3.15, rel=0.01)


def test_routed_test_ratio_is_beta():
    th, d, free = loop(Setup("tendon", 0.0, routed=False))
    _, _, routed = loop(Setup("tendon", 0.0, routed=True))
    ok = free > 1e-9
    assert np.median((routed / free)[ok & (d > 0)]) == pytest.approx(1.24, rel=0.01)
    assert np.median((routed / free)[ok & (d < 0)]) == pytest.approx(0.67, rel=0.01)


def test_direction_holds_through_holds():
    assert motion_direction([0, 1, 2, 2, 2, 1, 1, 3]).tolist() == [1, 1, 1, 1, 1, -1, -1, 1]


def test_relaxation_decays_during_a_hold_and_matches_the_ode():
    t = np.linspace(0, 10, 2001)
    th = np.clip(t, 0, 1.0)  # ramp for 1 s, then hold
    tau = relaxation_torque(th, t, k_m=2.0, t_r=1.5)
    # during the ramp (θ̇ = 1): τ = K_M·T_r·(1 − e^{−t/T_r}); then decays as e^{−(t−1)/T_r}
    peak = 2.0 * 1.5 * (1 - math.exp(-1 / 1.5))
    assert tau[np.searchsorted(t, 1.0)] == pytest.approx(peak, rel=1e-3)
    assert tau[-1] == pytest.approx(peak * math.exp(-9 / 1.5), rel=1e-2)


def test_viscous_and_cubic_terms():
    t = np.linspace(0, 1, 101)
    th = 0.5 * t
    base = simulate(JointModel(), Setup("bar"), th, t)
    visc = simulate(JointModel(viscous=0.4), Setup("bar"), th, t)
    cub = simulate(JointModel(cubic=0.3), Setup("bar"), th, t)
    assert np.allclose(visc - base, 0.4 * 0.5)
    assert np.allclose(cub - base, 0.3 * (th + JointModel().preload) ** 3)


def test_bad_joint_parameters():
    with pytest.raises(ParameterError):
        JointModel(pulley_radius=0)
    with pytest.raises(ParameterError):
        Setup("rope")


# ---------------------------------------------------------------- finger statics

def paper_model(**kw):
    return fm.FingerModel((5.2, 7.8, 10.4), (90 * DEG,) * 3, (90 * DEG,) * 3, (6.0,) * 3, **kw)


@pytest.mark.parametrize("t_d", [1.0, 5.0, 12.0, 20.0, 25.0])
def test_frictionless_equals_the_energy_minimum(t_d):
    m = fm.FingerModel((5.2, 7.8, 10.4), (90 * DEG, 60 * DEG, 40 * DEG), (90 * DEG, 80 * DEG, 100 * DEG),
                       (6.0, 7.0, 8.0))
    c = fm.simulate_path(m, np.linspace(0, t_d, 60))
    K, th0, thmax, r = (np.array(v) for v in (m.stiffness, m.preload, m.rotation, m.moment_arm))
    res = minimize(lambda x: 0.5 * np.sum(K * (x + th0) ** 2), np.full(3, 0.1), method="SLSQP",
                   bounds=list(zip([0] * 3, thmax)), constraints=[{"type": "eq", "fun": lambda x: r @ x - t_d}],
                   options={"ftol": 1e-14, "maxiter": 500})
    assert res.success
    assert c.theta[-1] == pytest.approx(res.x, abs=1e-4)
    assert fm.frictionless_optimum(m, t_d) == pytest.approx(res.x, abs=1e-4)


def test_capstan_makes_the_proximal_joint_start_first():
    equal = fm.FingerModel((5.0,) * 3, (60 * DEG,) * 3, (90 * DEG,) * 3, (6.0,) * 3,
                           wrap=(0.3, 0.3, 0.3), mu_t=0.3)
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


def test_model_from_manifest_reads_the_builder_keys():
    man = {"joints": [{"parent": "base", "child": "distal", "joint_stiffness_nmm_per_rad": 5.2, "preload_deg": 90,
                       "rotation_deg": 90, "tendon_moment_arm_mm": 6.5, "tendon_wrap_angle_rad": 0.45}],
           "bodies": [{"name": "base", "mass_g": 10}, {"name": "distal", "mass_g": 8}]}
    m = fm.model_from_manifest(man, mu_t=0.2)
    assert m.moment_arm == (6.5,) and m.wrap == (0.45,) and m.link_mass == (8,)


# ---------------------------------------------------------------- the paper's finger

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


def test_paper_finger_doc_is_generated_and_current(tmp_path):
    doc = (ROOT / "docs" / "paper-finger.md").read_text()
    assert (ROOT / "docs" / "paper-finger.png").stat().st_size > 10_000
    assert "Generated by `rjcad paper-finger`" in doc


@pytest.mark.slow
def test_paper_finger_doc_regenerates_identically(tmp_path):
    from rjcad.physics.paper_finger import write_doc

    write_doc(tmp_path)
    assert (tmp_path / "paper-finger.md").read_text() == (ROOT / "docs" / "paper-finger.md").read_text()


# ---------------------------------------------------------------- inverse design

@pytest.mark.parametrize("sequence", ["simultaneous", "proximal-first"])
def test_inverse_design_reaches_the_target(sequence, tmp_path):
    from rjcad.cad.finger import FingerParams
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


def test_inverse_design_unreachable_targets_say_why():
    from rjcad.physics.inverse import design_finger

    with pytest.raises(InfeasibleDesign, match="moment arm"):
        design_finger([65, 50, 50], 80)
    with pytest.raises(InfeasibleDesign, match="no printable spring"):
        design_finger([65, 50, 50], 25, base_stiffness=40)
    with pytest.raises(ParameterError):
        design_finger([65, 150, 50], 25)


def run_cli(args):
    return subprocess.run([sys.executable, "-m", "rjcad", *args], capture_output=True, text=True, timeout=300)


def test_cli_simulate_joint_json(tmp_path):
    r = run_cli(["simulate", "joint", "--drive", "tendon", "--routed", "--rotation", "90", "--json",
                 "--plot", str(tmp_path / "loop.png")])
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert set(d) == {"theta_deg", "direction", "tendon_force_n"}
    assert len(d["theta_deg"]) == len(d["direction"]) == len(d["tendon_force_n"])
    assert (tmp_path / "loop.png").stat().st_size > 1000


def test_cli_simulate_finger_and_design(tmp_path):
    r = run_cli(["simulate", "finger", str(ROOT / "templates" / "finger.toml"), "--stroke", "25", "--json"])
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert set(d) >= {"tendon_mm", "phase", "theta_deg", "tension_n"} and len(d["theta_deg"]) == 3
    out = tmp_path / "my.toml"
    r = run_cli(["finger-design", "--target", "65,50,50", "--stroke", "25", "--sequence", "proximal-first",
                 "--out", str(out)])
    assert r.returncode == 0, r.stderr and out.exists()
    r = run_cli(["finger-design", "--target", "65,50,50", "--stroke", "90", "--out", str(tmp_path / "x.toml")])
    assert r.returncode == 2 and "moment arm" in r.stderr and r.stderr.count("\n") == 1
    assert not (tmp_path / "x.toml").exists()


def test_physics_benchmark_prints_its_json():
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "physics.py"), "--repeats", "1"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["finger_1000_step_stroke_s"] > 0 and d["joint_samples_per_s"] > 0
