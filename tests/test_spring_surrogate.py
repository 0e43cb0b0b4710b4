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
    assert sg.stress_factor(RHO, SPRING["turns"], end=end) >= sg.stress_factor(RHO, SPRING["turns"], end=end,
                                                                                 margin=False)


def test_default_spring_unwound_clamped_keeps_its_gap():
    # spring-notes brief: clamped + unwind keeps 0.267 mm at 180° (rod model, none touching)
    gap = sg.coil_gap(math.pi, SPRING["r_in"], SPRING["pitch"], SPRING["turns"], SPRING["t"], sense="unwind",
                      margin=False)
    assert gap == pytest.approx(0.267, abs=0.01)


# --- random designs against fresh rod solves ------------------------------------------------------

def random_designs(n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        t = rng.uniform(0.4, 1.2)
        pitch = rng.uniform(t + 0.25, 2.5)
        r_in = rng.uniform(max(3.0, 3 * t), 8.0)
        yield dict(r_in=r_in, pitch=pitch, turns=rng.uniform(2.0, 7.0), b=2 * t, t=t, E=2200.0), rng.uniform(0.5, 3.0)


def test_printed_spiral_at_zero_windup():
    # undeformed: neighbouring coils one pitch apart (less the pitch angle), the pin side r_in + p_arm/4
    h1 = sg.gap_ratio_min(0.0, [1.0, 4.0, 12.0], 6.0, margin=False)
    assert h1 == pytest.approx([0.99, 0.999, 1.0], abs=0.01)
    assert sg.gap_ratio_min(0.0, 4.0, 3.0, arms=2, margin=False) == pytest.approx(1.0, abs=0.01)
    assert sg.hub_ratio_min(0.0, [1.0, 4.0], 6.0, margin=False) == pytest.approx(0.25, abs=1e-3)
    assert sg.hub_ratio_min(0.0, 4.0, 3.0, arms=2, margin=False) == pytest.approx(0.5, abs=1e-3)
    assert sg.torque_ratio(0.0, 4.0, 6.0) == pytest.approx(1.0, abs=1e-4)


def test_bad_arguments():
    with pytest.raises(ValueError):
        sg.gap_ratio_min(1.0, 4.0, 6.0, end="glued")
    with pytest.raises(ValueError):
        sg.stress_factor(4.0, 6.0, sense="clockwise")
    with pytest.raises(ValueError):
        sg.stiffness_ratio(4.0, 6.0, arms=3)
