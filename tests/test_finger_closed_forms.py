"""The finger's solver (rjcad.physics.finger) against independent solutions: closed forms of one joint (spring and
preload, stiffening, capstan, friction band, hysteresis, weight, a stretchy tendon) and small cases solved here by
scipy's root finders from the torque balance written out (two joints, with and without the links' weight)."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq, root

from rjcad.physics import finger as fm

DEG = math.pi / 180
K, TH0, R = 5.2, 70 * DEG, 6.0  # the paper's joint: N·mm/rad, rad, mm
W_PER_G = 9.81e-3  # N per g


def one_joint(**kw):
    return fm.FingerModel((K,), (TH0,), (90 * DEG,), (R,), **kw)


def pull_release(m, stroke, steps=200):
    """The closure of a pull to ``stroke`` mm and back, and the tendon path's pull and release halves' indices
    (the same t_d at pull[i] and release[i])."""
    c = fm.simulate_stroke(m, stroke, steps)
    pull = np.arange(1, steps)
    return c, pull, 2 * steps - pull


def test_one_joint_frictionless_tension_is_spring_over_arm():
    """Inextensible tendon, no friction, no weight: θ = t_d/r and r·T = K·(θ + θ0) (spring plus preload)."""
    c = fm.simulate_path(one_joint(), np.linspace(0.0, 9.0, 50))
    th = c.tendon_mm / R
    assert c.theta[:, 0] == pytest.approx(th, abs=1e-12)
    assert c.tension[1:] == pytest.approx(K * (th[1:] + TH0) / R, rel=1e-12)
    assert c.tension[0] == 0.0 and c.slack[0]  # at t_d = 0 nothing pulls: the spring rests on its stop


def test_one_joint_with_stiffening_and_a_stretchy_tendon():
    """r·T = K·s + k3·s³ (s = θ + θ0) and t_d = r·θ + T/k_t: θ from brentq on the tendon's length."""
    k3, kt = 0.3, 2.5
    m = one_joint(cubic=(k3,), tendon_stiffness=kt)
    td = np.linspace(0.5, 10.0, 40)
    c = fm.simulate_path(m, td)

    def tension(th):
        s = th + TH0
        return (K * s + k3 * s**3) / R

    for k, t_d in enumerate(td):
        th = brentq(lambda x, t_d=t_d: R * x + tension(x) / kt - t_d, 0.0, 90 * DEG)
        # the step linearises the cubic about the previous angle: exact to the square of the step's move
        assert c.theta[k, 0] == pytest.approx(th, abs=2e-4)
        assert c.tension[k] == pytest.approx(kt * (t_d - R * c.theta[k, 0]), rel=1e-9)


def test_capstan_ratio_is_exp_mu_wrap():
    """The tension reaching the joint is T·e^{−μα} while pulling and T·e^{+μα} while releasing; for a frictionless
    joint at the same angle the actuator's tensions pulling and releasing differ by e^{2μα}."""
    mu, wrap = 0.25, 0.8
    c, pull, rel = pull_release(one_joint(wrap=(wrap,), mu_t=mu), 8.0)
    assert c.joint_tension[pull, 0] == pytest.approx(c.tension[pull] * math.exp(-mu * wrap), rel=1e-12)
    assert c.joint_tension[rel, 0] == pytest.approx(c.tension[rel] * math.exp(mu * wrap), rel=1e-12)
    assert c.tension[pull] / c.tension[rel] == pytest.approx(np.full(len(pull), math.exp(2 * mu * wrap)), rel=1e-12)


def test_hysteresis_width_is_the_friction_band():
    """One joint with pin friction f0 + γ±·s and a capstan: the actuator pulls with
    (K·s + f0 + γ⁺·s)/(r·e^{−μα}) and lets go with (K·s − f0 − γ⁻·s)/(r·e^{μα}) at the same angle θ = t_d/r."""
    f0, gp, gn, mu, wrap = 2.0, 1.89, 3.15, 0.2, 0.45
    c, pull, rel = pull_release(one_joint(friction=(f0,), gamma_pos=(gp,), gamma_neg=(gn,), wrap=(wrap,), mu_t=mu), 8.0)
    s = c.tendon_mm[pull] / R + TH0
    assert c.theta[pull, 0] == pytest.approx(c.theta[rel, 0], abs=1e-12)
    assert c.tension[pull] == pytest.approx((K * s + f0 + gp * s) / (R * math.exp(-mu * wrap)), rel=1e-12)
    assert c.tension[rel] == pytest.approx((K * s - f0 - gn * s) / (R * math.exp(mu * wrap)), rel=1e-12)


def test_sticking_band_of_a_joint_on_a_stretchy_tendon():
    """After the reversal the joint sticks while the tendon's stretch takes the motion up: θ stays, T = k_t·(t_d −
    r·θ), until T reaches the band's lower edge (K·s − f0 − γ⁻·s)/r; the band is (2f0 + (γ⁺ + γ⁻)·s)/(r·k_t) mm of
    tendon wide."""
    f0, g, kt = 3.0, 1.0, 2.0
    m = one_joint(friction=(f0,), gamma=(g,), tendon_stiffness=kt)
    c = fm.simulate_stroke(m, 10.0, 400)
    top = 400
    th_top = c.theta[top, 0]
    s = th_top + TH0
    band_mm = (2 * f0 + 2 * g * s) / (R * kt)
    assert c.tension[top] == pytest.approx((K * s + f0 + g * s) / R, rel=1e-9)  # sliding closed at the top
    rel = np.arange(top + 1, 2 * top + 1)
    inside = c.tendon_mm[rel] > c.tendon_mm[top] - band_mm + 1e-6
    stuck = rel[inside]
    assert len(stuck) == int(band_mm / (10.0 / 400))  # the band in tendon steps
    assert np.all(c.theta[stuck, 0] == th_top) and np.all(c.state[stuck, 0] == 0)
    assert c.tension[stuck] == pytest.approx(kt * (c.tendon_mm[stuck] - R * th_top), rel=1e-9)
    after = rel[~inside][0]  # the first reading beyond the band slides open on the lower edge
    s1 = c.theta[after, 0] + TH0
    assert c.theta[after, 0] < th_top and c.tension[after] == pytest.approx((K * s1 - f0 - g * s1) / R, rel=1e-9)


def test_two_joints_frictionless_by_a_root_finder():
    """r_i·c_i·T = K_i·(θ_i + θ0_i) with θ_i clipped to its range and Σ r_i·θ_i = t_d: brentq on T. The joint with
    the lower preload torque per arm starts first (here joint 2 only after t_d ≈ 1.6 mm)."""
    Ks, th0, arms, wraps, mu = np.array([5.2, 7.8]), np.array([60, 80]) * DEG, np.array([6.0, 7.5]), (0.3, 0.4), 0.2
    m = fm.FingerModel(tuple(Ks), tuple(th0), (90 * DEG,) * 2, tuple(arms), wrap=wraps, mu_t=mu)
    c_pull = np.exp(-mu * np.cumsum(wraps))
    td = np.linspace(0.0, 15.0, 61)
    c = fm.simulate_path(m, td)

    def angles(T):
        return np.clip(arms * c_pull * T / Ks - th0, 0.0, 90 * DEG)

    for k in range(1, len(td)):
        T = brentq(lambda x, k=k: arms @ angles(x) - td[k], 0.0, 100.0, xtol=1e-14)
        assert c.tension[k] == pytest.approx(T, rel=1e-10)
        assert c.theta[k] == pytest.approx(angles(T), abs=1e-10)
    assert 0 < fm.onset_tendon(c, 1e-9)[0] < fm.onset_tendon(c, 1e-9)[1]


def test_a_single_link_under_its_weight():
    """One link of mass M, its centre at L/2, palm down (g = −y): r·T = K·(θ + θ0) + M·g·(L/2)·cos θ at θ = t_d/r.
    Palm up and heavy, the slack finger sags to K·(θ + θ0) = M·g·(L/2)·cos θ (brentq)."""
    M, L = 30.0, 40.0
    down = one_joint(link_mass=(M,), link_length=(L,), gravity=(0.0, -1.0))
    td = np.linspace(0.5, 9.0, 30)
    c = fm.simulate_path(down, td)
    th = td / R
    assert c.theta[:, 0] == pytest.approx(th, abs=1e-12)
    assert c.tension == pytest.approx((K * (th + TH0) + M * W_PER_G * L / 2 * np.cos(th)) / R, rel=1e-9)
    heavy = fm.FingerModel((K,), (20 * DEG,), (90 * DEG,), (R,), link_mass=(M,), link_length=(L,), gravity=(0.0, 1.0))
    sag = brentq(lambda x: K * (x + 20 * DEG) - M * W_PER_G * L / 2 * math.cos(x), 0.0, 90 * DEG, xtol=1e-14)
    c = fm.simulate_path(heavy, [0.0])
    assert c.slack[0] and c.tension[0] == 0.0 and c.theta[0, 0] == pytest.approx(sag, abs=1e-7)


def test_two_links_under_their_weight_by_scipy_root():
    """Two joints, links of 20 g and 12 g, palm down: the weight's torque written out here,
    τ_1 = w1·(L1/2)·cos θ1 + w2·(L1·cos θ1 + (L2/2)·cos(θ1 + θ2)), τ_2 = w2·(L2/2)·cos(θ1 + θ2),
    and r_i·T = K_i·(θ_i + θ0_i) + τ_i, r·θ = t_d solved by scipy.optimize.root."""
    Ks, th0, arms, L, w = (
        np.array([5.2, 7.8]),
        np.array([70, 80]) * DEG,
        np.array([6.0, 6.0]),
        np.array([40.0, 35.0]),
        np.array([20.0, 12.0]) * W_PER_G,
    )
    m = fm.FingerModel(
        tuple(Ks),
        tuple(th0),
        (90 * DEG,) * 2,
        tuple(arms),
        link_mass=(20.0, 12.0),
        link_length=tuple(L),
        gravity=(0.0, -1.0),
    )
    td = np.linspace(0.0, 14.0, 57)
    c = fm.simulate_path(m, td)

    def weight(th):
        c1, c12 = math.cos(th[0]), math.cos(th[0] + th[1])
        return np.array([w[0] * L[0] / 2 * c1 + w[1] * (L[0] * c1 + L[1] / 2 * c12), w[1] * L[1] / 2 * c12])

    def residual(x, t_d):
        th, T = x[:2], x[2]
        return np.r_[arms * T - Ks * (th + th0) - weight(th), arms @ th - t_d]

    checked = 0
    for k, t_d in enumerate(td):
        th = c.theta[k]
        if np.any(th < 1e-6) or np.any(th > 90 * DEG - 1e-6):
            continue  # a joint on a stop: not this system
        sol = root(residual, np.r_[th + 0.05, c.tension[k] * 1.1], args=(t_d,), tol=1e-13)
        assert sol.success
        assert th == pytest.approx(sol.x[:2], abs=1e-7) and c.tension[k] == pytest.approx(sol.x[2], rel=1e-7)
        checked += 1
    assert checked > 20
