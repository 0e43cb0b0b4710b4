"""Joint hysteresis model (paper Eq. 3-7, rjcad's β convention): the paper's relations with F_n = 1.5 N,
direction held through holds, the parameter-vector interface, and the relaxation arm on uneven samples."""

import math

import numpy as np
import pytest

from rjcad.errors import ParameterError
from rjcad.physics.joint import (
    PAPER_JOINT,
    PARAM_NAMES,
    JointModel,
    Setup,
    cycle,
    motion_direction,
    relaxation_torque,
    simulate,
)

DEG = math.pi / 180
R = PAPER_JOINT.pulley_radius


def ramp_hold_return(rot=90 * DEG, n=300, hold=50):
    """0 → rot, a hold, rot → 0: the direction is left for the model to find (not given)."""
    up = np.linspace(0, rot, n)
    return np.concatenate([up, np.full(hold, rot), up[::-1]])


def branch_fit(th, y, mask):
    slope, icpt = np.polyfit(th[mask], y[mask], 1)
    return slope, icpt


def test_tendon_test_with_normal_load_slopes_and_offsets():
    """Experiment B (tendon, not routed): r·F_t = (K + γ⁺)·θ + μ_j·F_n pulling,
    (K − γ⁻)·θ − μ_j·F_n releasing."""
    th = ramp_hold_return()
    d = np.r_[0, np.diff(th)]
    x = th + PAPER_JOINT.preload  # spring deformation
    F = simulate(PAPER_JOINT, Setup("tendon", 1.5), th)
    k_up, c_up = branch_fit(x, R * F, d > 0)
    assert k_up == pytest.approx(5.19 + 1.89, rel=0.01)
    assert c_up == pytest.approx(+6.92 * 1.5, rel=0.01)
    # with the paper's own numbers and F_n = 1.5 N the release needs a negative force all the way:
    # (K − γ⁻)·θ < μ_j·F_n for θ ≤ 160°, so the tendon is slack (the paper-notes' critique, made visible)
    assert np.all(F[d < 0] == 0.0)
    # a lighter load (0.5 N) leaves a taut part of the release branch, with slope K − γ⁻ and offset −μ_j·F_n
    F = simulate(PAPER_JOINT, Setup("tendon", 0.5), th)
    taut = (d < 0) & (F > 1e-9)
    assert taut.sum() > 100
    k_dn, c_dn = branch_fit(x, R * F, taut)
    assert k_dn == pytest.approx(5.19 - 3.15, rel=0.01)
    assert c_dn == pytest.approx(-6.92 * 0.5, rel=0.01)


def test_routed_ratio_is_beta():
    """Experiment C against B (pulling, F_n = 1.5 N) and E against D (releasing, F_n = 0)."""
    th = ramp_hold_return()
    d = np.r_[0, np.diff(th)]
    for fn, sel, beta in ((1.5, d > 0, 1.24), (0.0, d < 0, 0.67)):
        free = simulate(PAPER_JOINT, Setup("tendon", fn), th)
        routed = simulate(PAPER_JOINT, Setup("tendon", fn, routed=True), th)
        ok = sel & (free > 1e-6)
        assert ok.sum() > 100
        assert np.median(routed[ok] / free[ok]) == pytest.approx(beta, rel=0.01)


def test_a_hold_keeps_the_friction_direction_of_the_last_motion():
    th = ramp_hold_return()
    tau = simulate(PAPER_JOINT, Setup("bar", 1.5), th)
    hold = slice(300, 350)
    # holding after flexing: on the flexing branch, K·θ + μ_j·F_n (not the mean, not the extending branch)
    expected = PAPER_JOINT.stiffness * (90 * DEG + PAPER_JOINT.preload) + 6.92 * 1.5
    assert tau[hold] == pytest.approx(np.full(50, expected))
    # and a hold after extending stays on the extending branch
    th2 = np.concatenate([np.linspace(0, 1, 50), np.linspace(1, 0.5, 50), np.full(20, 0.5)])
    tau2 = simulate(PAPER_JOINT, Setup("bar", 1.5), th2)
    assert tau2[-1] == pytest.approx(PAPER_JOINT.stiffness * (0.5 + PAPER_JOINT.preload) - 6.92 * 1.5)


def test_deadband_ignores_jitter_in_measured_angles():
    th = np.array([0.0, 0.1, 0.2, 0.2001, 0.1999, 0.2002, 0.1, 0.0])
    assert motion_direction(th, deadband=1e-3).tolist() == [1, 1, 1, 1, 1, 1, -1, -1]
    assert motion_direction(th).tolist()[4] == -1  # without a deadband the jitter flips it


def test_slack_tendon_force_is_never_negative():
    """Releasing under heavy pin friction: the required torque would be negative; the tendon goes slack."""
    m = PAPER_JOINT.with_(preload=0.0)
    th = ramp_hold_return(rot=30 * DEG)
    F = simulate(m, Setup("tendon", 1.5, routed=True), th)
    assert F.min() == 0.0 and np.all(F >= 0)


def test_parameter_vector_round_trip_and_errors():
    x = PAPER_JOINT.to_vector()
    assert len(x) == len(PARAM_NAMES) and JointModel.from_vector(x) == PAPER_JOINT
    sub = ("stiffness", "mu_j", "cubic")
    m = JointModel.from_vector([4.0, 5.0, 0.2], sub, base=PAPER_JOINT)
    assert (m.stiffness, m.mu_j, m.cubic, m.gamma_pos) == (4.0, 5.0, 0.2, PAPER_JOINT.gamma_pos)
    assert m.to_vector(sub) == pytest.approx([4.0, 5.0, 0.2])
    with pytest.raises(ParameterError, match="unknown parameter"):
        JointModel.from_vector([1.0], ("stifness",))
    with pytest.raises(ParameterError, match="needs 2 values"):
        JointModel.from_vector([1.0], ("stiffness", "mu_j"))


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"beta_pos": 0.9}, "beta_pos"),
        ({"beta_neg": 1.1}, "beta_neg"),
        ({"beta_neg": 0.0}, "beta_neg"),
        ({"viscous": -1.0}, "viscous"),
        ({"stiffness": math.nan}, "stiffness"),
    ],
)
def test_the_beta_convention_and_signs_are_enforced(kw, name):
    with pytest.raises(ParameterError) as e:
        JointModel(**kw)
    assert e.value.parameter == name


def step_by_step(th, t, k_m, t_r):
    """Exact Maxwell update for piecewise-linear θ, one step at a time (the reference)."""
    ref = np.zeros_like(th)
    for k in range(1, len(t)):
        dt = t[k] - t[k - 1]
        a = math.exp(-dt / t_r)
        ref[k] = a * ref[k - 1] + k_m * t_r * (1 - a) * (th[k] - th[k - 1]) / dt
    return ref


def test_relaxation_on_uneven_samples_matches_a_step_by_step_solution():
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.001, 0.05, 20000))  # ~500 s = ~1300 T_r: many blocks of the vectorised sum
    th = 0.5 * np.sin(0.7 * t) + 0.3 * np.sin(2.3 * t)
    assert relaxation_torque(th, t, 2.0, 0.4) == pytest.approx(step_by_step(th, t, 2.0, 0.4), abs=1e-9)
    tu = np.linspace(0, 5, 501)  # uniform steps take the linear-filter path
    assert relaxation_torque(np.sin(tu), tu, 2.0, 0.4) == pytest.approx(
        step_by_step(np.sin(tu), tu, 2.0, 0.4), abs=1e-12
    )


def test_optional_effects_all_act_in_the_tendon_drive():
    t = np.linspace(0, 2, 201)
    th = 0.6 * t
    base = PAPER_JOINT
    setup = Setup("tendon", 1.5, routed=True)
    f0 = simulate(base, setup, th, t)
    visc = simulate(base.with_(viscous=0.5), setup, th, t)
    # pulling: everything inside the β⁺ factor, over the pulley radius
    assert visc - f0 == pytest.approx(np.full_like(t, 1.24 * 0.5 * 0.6 / R), rel=1e-6)
    relax = simulate(base.with_(relaxation_stiffness=1.0, relaxation_time=0.5), setup, th, t)
    assert np.all(np.diff(relax - f0) >= -1e-12) and (relax - f0)[-1] > 0


# ---------------------------------------------------------------- one full cycle (from test_physics.py)


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
