"""The compiled finger path (rjcad.physics.finger_fast) gives what the reference solver gives, to 1e-9."""

import math

import numpy as np
import pytest

from rjcad.physics.finger import FingerModel, simulate_path
from rjcad.physics.finger_fast import simulate_angles

DEG = math.pi / 180


def _path(rng, n=600):
    """A tendon path with reversals, holds and slack phases (back to 0)."""
    knots = np.concatenate([[0.0], rng.uniform(0, 30, 6), [0.0]])
    td = np.concatenate([np.linspace(a, b, n // 8) for a, b in zip(knots[:-1], knots[1:])])
    return np.concatenate([td, np.full(20, td[-1])])


MODELS = {
    "frictionless": dict(),
    "friction": dict(friction=(2.0, 1.0, 0.5), gamma=(1.0, 0.5, 0.5)),
    "asymmetric": dict(friction=(1.0, 1.0, 1.0), gamma_pos=(1.89, 1.0, 0.5), gamma_neg=(3.15, 2.0, 1.5)),
    "capstan": dict(wrap=(0.45, 0.6, 0.6), mu_t=0.25, friction=(1.0,) * 3),
    "stretch": dict(tendon_stiffness=3.0, friction=(1.0,) * 3),
    "gravity": dict(link_mass=(17.6, 14.4, 9.8), gravity=(0.0, -1.0), friction=(0.5,) * 3),
    "everything": dict(wrap=(0.45, 0.6, 0.6), mu_t=0.2, friction=(2.0, 1.0, 0.5), gamma_pos=(1.0, 0.5, 0.5),
                       gamma_neg=(2.0, 1.5, 1.0), tendon_stiffness=4.0, link_mass=(17.6, 14.4, 9.8),
                       gravity=(0.6, -0.8)),
    "stiffening": dict(cubic=(0.15, 0.1, 0.2), friction=(1.0,) * 3),
    "damping": dict(damping=(0.6, 0.4, 0.3), friction=(1.0,) * 3),
    "relaxation": dict(relax_stiffness=(1.5, 2.0, 2.5), relax_time=1.5, friction=(0.5,) * 3),
    "rates and gravity": dict(damping=(0.6, 0.4, 0.3), cubic=(0.1,) * 3, relax_stiffness=(1.5, 2.0, 2.5),
                              relax_time=0.8, friction=(1.0,) * 3, gamma=(0.5,) * 3, tendon_stiffness=4.0,
                              link_mass=(17.6, 14.4, 9.8), gravity=(0.0, -1.0)),
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_same_as_reference(name):
    rng = np.random.default_rng(len(name))
    m = FingerModel((5.2, 7.8, 10.4), (90 * DEG, 60 * DEG, 45 * DEG), (90 * DEG,) * 3, (6.0, 7.0, 8.5),
                    **MODELS[name])
    td = _path(rng)
    t = np.cumsum(rng.uniform(0.005, 0.02, len(td)))  # uneven steps
    ref = simulate_path(m, td, t_s=t)
    th, T = simulate_angles(m, td, t)
    assert th == pytest.approx(ref.theta, abs=1e-9)
    assert T == pytest.approx(ref.tension, abs=1e-9)


def test_one_and_five_joints():
    for n in (1, 5):
        m = FingerModel((5.2,) * n, (80 * DEG,) * n, (90 * DEG,) * n, tuple(np.linspace(5, 9, n)),
                        friction=(1.0,) * n, gamma=(0.5,) * n)
        td = _path(np.random.default_rng(n), 400)
        ref = simulate_path(m, td)
        th, T = simulate_angles(m, td)
        assert th == pytest.approx(ref.theta, abs=1e-9) and T == pytest.approx(ref.tension, abs=1e-9)
