"""Two interleaved spring arms (issue 36, part 2): the rod model's net hub force checked by an independent elastica,
and the optimiser's two-arm design verified by the rod model."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import root

from rjcad import DEG
from rjcad.errors import ParameterError
from rjcad.spring import rod
from rjcad.spring.design import MAX_HUB_FORCE_RATIO, SpringRequirement
from rjcad.spring.optimise import design_spring

#: A two-arm spring the optimiser designs for the default desktop joint when its envelope is allowed to grow.
ROOMY = dict(inner_radius_max=30.0, outer_radius_max=150.0)


def _requirement(**kw) -> SpringRequirement:
    base = dict(joint_stiffness=5.2, rotation=90 * DEG, preload=90 * DEG, springs=1, min_gap=0.4, arms=2)
    return SpringRequirement(**{**base, **kw})


def elastica_hub_force(r_in, pitch_arm, turns, phi0, EI, windup) -> np.ndarray:
    """Force (2,) the hub applies to one inextensible clamped arm whose outer end is carried round the axis by
    ``windup`` [rad] (negative: clockwise, unwinding a counter-clockwise spiral), by shooting.

    The arm is r = r_in + k·a at φ = φ0 + a (k = pitch/2π), a ∈ [0, 2πn]; unknowns: the hub's force H and moment
    M_H on the inner end. The moment the outer part applies across a section at x(s) is M = −M_H + (x − x0) × H,
    and ψ' = ψ0' + M/EI; the outer end must reach its carried position and angle ψ0(L) + windup.
    """
    k = pitch_arm / (2 * math.pi)
    a_end = 2 * math.pi * turns

    def point(a):
        r = r_in + k * a
        return np.array([r * math.cos(phi0 + a), r * math.sin(phi0 + a)])

    def psi0(a):
        return phi0 + a + math.atan2(r_in + k * a, k)

    x0, x1 = point(0.0), point(a_end)

    def shoot(u, theta):
        Hx, Hy, MH = u

        def rhs(a, z):
            x, y, psi = z
            r = r_in + k * a
            ds = math.hypot(r, k)
            M = -MH + ((x - x0[0]) * Hy - (y - x0[1]) * Hx)
            return [ds * math.cos(psi), ds * math.sin(psi), 1 + k * k / (r * r + k * k) + ds * M / EI]

        sol = solve_ivp(rhs, (0.0, a_end), [x0[0], x0[1], psi0(0.0)], method="DOP853", rtol=1e-11, atol=1e-11)
        x, y, psi = sol.y[:, -1]
        c, s = math.cos(theta), math.sin(theta)
        target = (c * x1[0] - s * x1[1], s * x1[0] + c * x1[1])
        return [x - target[0], y - target[1], 10.0 * (psi - psi0(a_end) - theta)]

    u = np.zeros(3)
    for theta in np.linspace(0.0, windup, 13)[1:]:  # continuation in the wind-up
        out = root(shoot, u, args=(theta,), method="hybr", options={"xtol": 1e-12})
        assert out.success, out.message
        u = out.x
    return u[:2]


@pytest.fixture(scope="module")
def pair():
    return design_spring(_requirement(**ROOMY))


def test_two_arm_design_is_verified_by_the_rod_model(pair):
    req = pair.requirement
    report = pair.constraint_report()
    assert all(met for _, _, met in report.values()), report
    assert pair.arms == 2 and pair.joint_stiffness == pytest.approx(5.2, rel=0.005)
    assert pair.max_stress <= req.allowed_stress
    assert pair.min_coil_gap >= 0.4 and pair.min_key_gap >= 0.4
    assert pair.centreline_outer_radius == pytest.approx(pair.inner_radius + 2 * pair.pitch * pair.turns)
    d = pair.to_dict()
    assert d["arms"] == 2 and d["hub_force_ratio"] <= MAX_HUB_FORCE_RATIO and d["arm_force_n"] > 0


def test_net_hub_force_by_an_independent_elastica(pair):
    """Each arm solved on its own by shooting (not the rod model): their hub forces cancel to ≤ 5 % of one arm's,
    and one arm's matches the rod model's reaction."""
    E = pair.youngs_modulus
    EI = E * pair.width * pair.thickness**3 / 12.0
    windup = -pair.requirement.max_windup  # unwinding turns the counter-clockwise spiral's end clockwise
    phi0 = -math.pi / 2 - 2 * math.pi * pair.turns
    forces = [
        elastica_hub_force(pair.inner_radius, pair.arm_pitch, pair.turns, phi0 + turn, EI, windup)
        for turn in (0.0, math.pi)
    ]
    one = float(np.hypot(*forces[0]))
    net = float(np.hypot(*(forces[0] + forces[1])))
    assert one > 0.01
    assert net <= MAX_HUB_FORCE_RATIO * one
    res = rod.spiral_windup(
        pair.inner_radius,
        pair.pitch,
        pair.turns,
        pair.width,
        pair.thickness,
        E,
        arms=2,
        sense="unwind",
        theta_max=pair.requirement.max_windup,
        steps=12,
    )
    assert res.arm_force is not None
    assert res.arm_force[-1] == pytest.approx(one, rel=0.02)
    assert res.hub_force[-1] <= MAX_HUB_FORCE_RATIO * res.arm_force[-1]


def test_key_gap_sees_the_other_arm():
    """A key reaching over the other arm's outer coil closes the key gap; a short one keeps it."""
    kw = dict(r_in=4.0, pitch=2.0, turns=1.5, b=3.0, t=0.8, E=2200.0, arms=2, sense="unwind", theta_max=30 * DEG)
    short = rod.spiral_windup(**kw, steps=2, key=(-0.2, 0.5, 1.6))
    long = rod.spiral_windup(**kw, steps=2, key=(-4.0, 0.5, 1.6))  # reaches inwards across the other arm
    assert short.key_gap is not None and long.key_gap is not None
    assert short.key_gap[0] > 0.3
    assert long.key_gap[0] < 0


def test_box_gap_signs():
    box = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    X = np.array([[3.0, 0.5], [3.0, 0.6]])
    tang = np.array([math.pi / 2, math.pi / 2])
    assert rod.box_gap(X, tang, box, 0.2) == pytest.approx(1.9)
    inside = np.array([[0.5, 0.4], [0.5, 0.6]])
    assert rod.box_gap(inside, tang, box, 0.2) < -0.4


def test_default_envelope_refuses_two_arms_naming_the_coil_gap():
    from rjcad.errors import InfeasibleDesign

    with pytest.raises(InfeasibleDesign, match="coil") as e:
        design_spring(_requirement())
    assert "two arms" in str(e.value)


def test_one_arm_designs_do_not_change():
    one = design_spring(_requirement(arms=1))
    assert "arms" not in one.to_dict() and one.arms == 1 and one.min_key_gap is None


@pytest.mark.parametrize("bad", [0, 3, True, 1.5])
def test_arms_validated(bad):
    with pytest.raises(ParameterError, match="arms"):
        dataclasses.replace(_requirement(), arms=bad)


def test_cli_spring_arms_2(cli):
    r = cli("spring", "--stiffness", "5.2", "--springs", "1", "--arms", "2", "--rotation", "45", "--preload", "35")
    assert r.code == 0, r.err
    assert "hub force, net" in r.out and "key gap" in r.out
    r = cli(
        "spring", "--stiffness", "5.2", "--springs", "1", "--arms", "2", "--rotation", "45", "--preload", "35", "--json"
    )
    d = json.loads(r.out)
    assert d["arms"] == 2 and d["hub_force_ratio"] <= MAX_HUB_FORCE_RATIO and d["min_key_gap_mm"] >= d["min_gap_mm"]
