"""rjcad.identify.diagnose on residuals made to measure: each feature reads back its known size, and each
points to the effect that makes it."""

import math

import numpy as np
import pytest
from test_identify_fit import campaign

from rjcad.identify.diagnose import angle_direction_fit, diagnose
from rjcad.identify.fit import prepare


@pytest.fixture(scope="module")
def bar():
    """Experiment A (bar drive, 1.5 N normal load), analysed."""
    return prepare(campaign())[0]


def test_angle_direction_fit_recovers_known_coefficients(bar):
    th, s = bar.motion.theta, bar.motion.direction
    r = 0.3 - 0.2 * th + 0.1 * th**2 + 0.5 * s + 0.05 * s * th
    coef, X = angle_direction_fit(bar, r)
    assert coef == pytest.approx([0.3, -0.2, 0.1, 0.5, 0.05], abs=1e-9)
    assert X.shape == (int(bar.valid.sum()), 5)


def test_a_constant_band_under_normal_load_points_to_coulomb_friction(bar):
    d = diagnose(bar, 0.5 * bar.motion.direction)
    assert d["band_halfwidth"] == pytest.approx([0.5, 0.5], abs=1e-9)
    assert d["centre_offset"] == pytest.approx(0.0, abs=1e-9) and d["rmse"] == pytest.approx(0.5)
    assert [h["effects"] for h in d["hints"]] == [["coulomb_pin"]]
    assert "about constant" in d["hints"][0]["evidence"]


def test_a_bent_centre_line_points_to_stiffening_and_an_offset_to_calibration(bar):
    th = bar.motion.theta
    lo, hi = th[bar.valid].min(), th[bar.valid].max()
    d = diagnose(bar, 2.0 * (th - lo) * (th - hi))  # a sag of (hi − lo)²/2 mid-range, zero at both ends
    assert d["centre_curvature"] == pytest.approx(2.0 * (hi - lo) ** 2 / 4, rel=1e-6)
    assert ["stiffening"] in [h["effects"] for h in d["hints"]]
    d = diagnose(bar, np.full(th.shape, 0.8))
    assert d["centre_offset"] == pytest.approx(0.8) and d["centre_change"] == pytest.approx(0.0, abs=1e-9)
    assert [h["effects"] for h in d["hints"]] == [["spring_calibration"]]


def test_a_residual_that_follows_the_velocity_points_to_damping(bar):
    """Only the part the band terms cannot take (the speeds differ between ramps) is read as damping."""
    v = bar.motion.velocity
    d = diagnose(bar, 4.0 * v)
    assert 1.0 < d["velocity_slope"] <= 4.0
    assert d["velocity_effect"] == pytest.approx(d["velocity_slope"] * np.percentile(np.abs(v[bar.valid]), 95))
    assert ["viscous"] in [h["effects"] for h in d["hints"]]


def test_noise_alone_points_nowhere(bar):
    rng = np.random.default_rng(6)
    d = diagnose(bar, rng.normal(0, bar.sigma, bar.exp.t.size))
    assert d["hints"] == [] and d["rmse"] == pytest.approx(bar.sigma, rel=0.1)
    assert d["angle_range_rad"][1] == pytest.approx(math.radians(90), abs=0.02)
