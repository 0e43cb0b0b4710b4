"""rjcad.identify.signal on signals whose answer is known: noise level, runs, spikes, smoothing, velocity,
direction through holds and reversals, cycles."""

import math

import numpy as np
import pytest

from rjcad.identify.signal import analyse_motion, noise_sigma, runs, spikes

DEG = math.pi / 180


def test_noise_sigma_of_gaussian_noise_on_a_smooth_signal():
    rng = np.random.default_rng(0)
    t = np.linspace(0, 10, 20_000)
    for sigma in (0.01, 0.3):
        y = np.sin(t) + 0.2 * t + rng.normal(0, sigma, t.size)
        assert noise_sigma(y) == pytest.approx(sigma, rel=0.05)


def test_noise_sigma_ignores_steps_and_is_zero_without_noise():
    rng = np.random.default_rng(1)
    y = np.where(np.arange(5000) < 2500, 0.0, 10.0) + rng.normal(0, 0.05, 5000)  # one big friction jump
    assert noise_sigma(y) == pytest.approx(0.05, rel=0.08)
    assert noise_sigma(np.linspace(0, 1, 100)) == pytest.approx(0.0, abs=1e-12)  # a ramp has Δ²y = 0
    assert noise_sigma([1.0, 2.0, 3.0]) == 0.0  # too short to say


def test_runs_of_a_known_mask():
    assert runs([0, 1, 1, 0, 0, 1, 0, 1, 1, 1]) == [(1, 3), (5, 6), (7, 10)]
    assert runs([1, 1, 0]) == [(0, 2)]
    assert runs([0, 0]) == [] and runs([]) == []
    assert runs(np.ones(4, dtype=bool)) == [(0, 4)]


def test_spikes_finds_isolated_outliers_but_not_a_step():
    rng = np.random.default_rng(2)
    x = rng.normal(0, 0.01, 1000)
    x[500:] += 1.0  # a step: kept
    x[[100, 700]] += 0.5  # two camera glitches
    assert np.flatnonzero(spikes(x, 0.01)).tolist() == [100, 700]
    assert not spikes(x[:4], 0.01).any() and not spikes(x, 0.0).any()


def test_smoothed_angle_and_velocity_of_a_known_ramp():
    """θ = 0.5 rad/s·t up for 4 s, then down: the smoothed angle is the ramp, θ̇ = ±0.5 away from the turn."""
    rng = np.random.default_rng(3)
    t = np.linspace(0, 8, 4001)
    true = np.where(t < 4, 0.5 * t, 4 - 0.5 * t)
    m = analyse_motion(t, true + rng.normal(0, 0.001, t.size))
    away = np.abs(t - 4) > 0.3
    away &= (t > 0.3) & (t < 7.7)
    assert m.sigma_theta == pytest.approx(0.001, rel=0.1)
    assert np.max(np.abs(m.theta - true)[away]) < 0.002
    assert m.velocity[away & (t < 4)] == pytest.approx(0.5, abs=0.01)
    assert m.velocity[away & (t > 4)] == pytest.approx(-0.5, abs=0.01)
    # one reversal near 4 s: forward before, backward after, ambiguous samples only around it
    assert len(m.reversals) == 1 and abs(t[m.reversals[0]] - 4) < 0.1
    assert set(m.direction[t < 3.8]) == {1.0} and set(m.direction[t > 4.2]) == {-1.0}
    assert not m.valid[np.argmin(np.abs(t - 4))] and m.valid[away].all()
    assert m.window % 2 == 1 and m.n_cycles == 1


def test_a_hold_keeps_the_direction_and_is_found():
    """Up, hold 2 s, up again (camera noise 0.05°): no reversal, direction +1 throughout, the hold is marked."""
    rng = np.random.default_rng(4)
    t = np.linspace(0, 6, 3001)
    theta = (np.clip(t, 0, 2) + np.clip(t - 4, 0, 2)) * 10 * DEG + rng.normal(0, 0.05 * DEG, t.size)
    m = analyse_motion(t, theta)
    assert len(m.reversals) == 0 and set(m.direction) == {1.0}
    inside = (t > 2.3) & (t < 3.7)
    assert m.hold[inside].all() and not m.hold[(t > 0.5) & (t < 1.5)].any()


def test_cycles_start_at_each_minimum():
    t = np.linspace(0, 6, 3001)
    theta = 0.5 * (1 - np.cos(2 * math.pi * t / 2))  # three up-down cycles from rest
    m = analyse_motion(t, theta)
    assert len(m.reversals) == 5  # 3 maxima, 2 minima in between
    assert m.n_cycles == 3
    assert m.cycle[0] == 0 and m.cycle[-1] == 2
    assert np.all(np.diff(m.cycle) >= 0)
