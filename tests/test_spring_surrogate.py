"""The table surrogate of the rod model (rjcad.spring.surrogate) against fresh rod solves.

* The claim the tables rest on: under a prescribed wind-up the centreline (so the
  coil distance / p), K/(E·b·t³/12L) and max|M|/T do not depend on t, b, E or the
  start angle (axial strain aside: below 1 µm here).
* A handful of seeded random designs against spiral_windup: the raw lookup within the
  stated margin of the rod model, the lookup with its margin below it.
* Monotone in θ, NaN outside the table, the default spring's known factors.
"""

import math

import numpy as np
import pytest

from rjcad.spring import rod
from rjcad.spring import surrogate as sg

DEG = math.pi / 180
# The default first-wave spring (spring-notes.md): b 7.6, t 0.8, r_in 3, pitch 1.1434, 5.62 turns.
SPRING = dict(r_in=3.0, pitch=1.1434137451636173, turns=5.620157989891363, b=7.6, t=0.8, E=2200.0)
RHO = SPRING["r_in"] / SPRING["pitch"]


def centreline_distance(res, t):
    """Smallest distance between coil centrelines at each wind-up [mm] (the rod's coil gap + t)."""
    return res.coil_gap + t


# --- the invariance the tables rest on ---------------------------------------------------------


def test_centreline_depends_on_the_geometry_only():
    base = rod.spiral_windup(**SPRING, end="clamped", sense="unwind", theta_max=90 * DEG, steps=6)
    ref = centreline_distance(base, SPRING["t"])
    variants = [dict(t=0.6), dict(t=1.0), dict(b=3.8), dict(E=1500.0), dict(phi0=0.3)]
    for change in variants:
        kw = {**SPRING, **change}
        phi0 = kw.pop("phi0", None)
        res = rod.spiral_windup(**kw, end="clamped", sense="unwind", theta_max=90 * DEG, steps=6, phi0=phi0)
        assert np.max(np.abs(centreline_distance(res, kw["t"]) - ref)) < 1e-3, change  # 1 µm
        assert res.stiffness_ratio[1] == pytest.approx(base.stiffness_ratio[1], rel=1e-4), change
        assert res.max_moment[1] / res.torque[1] == pytest.approx(base.max_moment[1] / base.torque[1], rel=1e-4)


# --- the default spring ---------------------------------------------------------------------------


@pytest.mark.parametrize("end, c, m", [("clamped", 1.0082, 1.154), ("pinned", 0.7857, 1.944)])
def test_default_spring_factors(end, c, m):
    # rod.stiffness_ratio / stress_factor of the default spring (test_spring_rod.py)
    assert sg.stiffness_ratio(RHO, SPRING["turns"], end=end) == pytest.approx(c, rel=0.003)
    assert sg.stress_factor(RHO, SPRING["turns"], end=end, margin=False) == pytest.approx(m, rel=0.005)
    assert sg.stress_factor(RHO, SPRING["turns"], end=end) >= sg.stress_factor(
        RHO, SPRING["turns"], end=end, margin=False
    )


@pytest.mark.parametrize(
    "end, sense, contact_deg", [("clamped", "tighten", 84.2), ("pinned", "tighten", 23.5), ("pinned", "unwind", 37.0)]
)
def test_default_spring_first_contact(end, sense, contact_deg):
    # centreline distance = t where the rod model's first contact is (test_spring_rod.py, spring-notes.md)
    theta = np.radians(np.arange(0.0, 120.0, 0.25))
    h = sg.gap_ratio_min(theta, RHO, SPRING["turns"], end=end, sense=sense, margin=False)
    touch = theta[np.argmax(h * SPRING["pitch"] < SPRING["t"])]
    assert math.degrees(touch) == pytest.approx(contact_deg, abs=1.5)
    h_safe = sg.gap_ratio_min(theta, RHO, SPRING["turns"], end=end, sense=sense)
    assert math.degrees(theta[np.argmax(h_safe * SPRING["pitch"] < SPRING["t"])]) <= math.degrees(touch)


def test_default_spring_unwound_clamped_keeps_its_gap():
    # spring-notes brief: clamped + unwind keeps 0.267 mm at 180° (rod model, none touching)
    gap = sg.coil_gap(
        math.pi, SPRING["r_in"], SPRING["pitch"], SPRING["turns"], SPRING["t"], sense="unwind", margin=False
    )
    assert gap == pytest.approx(0.267, abs=0.01)


# --- random designs against fresh rod solves ------------------------------------------------------


def random_designs(n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        t = rng.uniform(0.4, 1.2)
        pitch = rng.uniform(t + 0.25, 2.5)
        r_in = rng.uniform(max(3.0, 3 * t), 8.0)
        yield dict(r_in=r_in, pitch=pitch, turns=rng.uniform(2.0, 7.0), b=2 * t, t=t, E=2200.0), rng.uniform(0.5, 3.0)


@pytest.mark.parametrize("sense", ["unwind", "tighten"])
def test_random_designs_within_the_margin(sense):
    for design, theta_max in random_designs(3, seed=7 if sense == "unwind" else 8):
        steps = math.ceil(theta_max / (3.75 * DEG))
        res = rod.spiral_windup(**design, end="clamped", sense=sense, theta_max=theta_max, steps=steps, per_turn=160)
        p, t = design["pitch"], design["t"]
        rod_h = np.minimum.accumulate(centreline_distance(res, t)) / p
        args = (res.theta, design["r_in"] / p, design["turns"])
        raw, spread = sg.gap_lookup(*args, sense=sense)
        margin = sg.error_margin("h", res.theta, sense=sense, spread=spread)
        safe = sg.gap_ratio_min(*args, sense=sense)
        open_ = rod_h >= 0.1  # the table reports 0 once every printable design touches
        assert np.all((raw - rod_h)[open_] <= margin[open_]), design
        assert np.all(safe[open_] <= rod_h[open_] + 1e-9), design
        m_rod = np.maximum.accumulate(res.max_moment[1:] / res.torque[1:])
        m_safe = sg.stress_factor(design["r_in"] / p, design["turns"], res.theta[1:], sense=sense)
        assert np.all((m_safe >= m_rod - 1e-9)[open_[1:]]), design


# --- properties of the lookups --------------------------------------------------------------------


def monotone(a, sign):
    """Each row non-increasing (sign -1) or non-decreasing (+1) along θ wherever two neighbours are finite."""
    both = np.isfinite(a[:, :-1]) & np.isfinite(a[:, 1:])
    with np.errstate(invalid="ignore"):
        step = sign * np.diff(a, axis=1)
    return bool(np.all(~both | (step >= -1e-12)))


@pytest.mark.parametrize("end", ["clamped", "pinned"])
@pytest.mark.parametrize("sense", ["tighten", "unwind"])
@pytest.mark.parametrize("arms", [1, 2])
def test_gap_ratio_is_non_increasing_in_theta(end, sense, arms):
    rng = np.random.default_rng(1)
    rho = 2.0 ** rng.uniform(-0.5, 4.0, (500, 1))
    turns = rng.uniform(*((1, 20) if arms == 1 else (0.5, 10)), (500, 1))
    theta = np.linspace(0.0, 2 * math.pi, 181)
    for margin in (False, True):
        h = sg.gap_ratio_min(theta, rho, turns, end=end, sense=sense, arms=arms, margin=margin)
        assert h.shape == (500, 181)
        # a hole (NaN: the generator's solve stopped converging before the coils touched) runs to 2π: the
        # caller then has the rod model decide; the joint's own case (one clamped arm, unwinding) has none
        finite = np.isfinite(h)
        assert np.all(finite[:, :-1] >= finite[:, 1:])
        if (end, sense, arms) == ("clamped", "unwind", 1):
            assert finite.all()
        assert monotone(h, -1)
        assert monotone(sg.hub_ratio_min(theta, rho, turns, end=end, sense=sense, arms=arms, margin=margin), -1)
        assert monotone(sg.stress_factor(rho, turns, theta, end=end, sense=sense, arms=arms, margin=margin), 1)


def test_printed_spiral_at_zero_windup():
    # undeformed: neighbouring coils one pitch apart (less the pitch angle), the pin side r_in + p_arm/4
    h1 = sg.gap_ratio_min(0.0, [1.0, 4.0, 12.0], 6.0, margin=False)
    assert h1 == pytest.approx([0.99, 0.999, 1.0], abs=0.01)
    assert sg.gap_ratio_min(0.0, 4.0, 3.0, arms=2, margin=False) == pytest.approx(1.0, abs=0.01)
    assert sg.hub_ratio_min(0.0, [1.0, 4.0], 6.0, margin=False) == pytest.approx(0.25, abs=1e-3)
    assert sg.hub_ratio_min(0.0, 4.0, 3.0, arms=2, margin=False) == pytest.approx(0.5, abs=1e-3)
    assert sg.torque_ratio(0.0, 4.0, 6.0) == pytest.approx(1.0, abs=1e-4)


def test_nan_outside_the_table():
    inside = (1.0, 4.0, 6.0)
    assert np.isfinite(sg.gap_ratio_min(*inside))
    for theta, rho, turns in [
        (7.0, 4.0, 6.0),
        (-0.1, 4.0, 6.0),
        (1.0, 0.5, 6.0),
        (1.0, 17.0, 6.0),
        (1.0, 4.0, 0.9),
        (1.0, 4.0, 20.5),
        (np.nan, 4.0, 6.0),
    ]:
        assert np.isnan(sg.gap_ratio_min(theta, rho, turns)), (theta, rho, turns)
        assert np.isnan(sg.stress_factor(rho, turns, theta)), (theta, rho, turns)
    assert np.isnan(sg.gap_ratio_min(1.0, 4.0, 10.5, arms=2))
    assert np.isfinite(sg.gap_ratio_min(1.0, 4.0, 0.6, arms=2))
    assert np.isnan(sg.stiffness_ratio(4.0, 25.0))
    out = sg.gap_ratio_min(np.array([1.0, 7.0]), 4.0, 6.0)
    assert np.isfinite(out[0]) and np.isnan(out[1])


def test_bad_arguments():
    with pytest.raises(ValueError):
        sg.gap_ratio_min(1.0, 4.0, 6.0, end="glued")
    with pytest.raises(ValueError):
        sg.stress_factor(4.0, 6.0, sense="clockwise")
    with pytest.raises(ValueError):
        sg.stiffness_ratio(4.0, 6.0, arms=3)
