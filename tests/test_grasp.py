"""Issue #40: a finger closing on objects (rjcad/physics/grasp.py), checked against cases solved by hand with
none of its code: a two-link finger whose links both come to rest on a cylinder (the angles from the two tangencies,
the forces from the joints' balance in closed form), and one link meeting a cylinder with the bearing's friction,
the capstan and the weight each on (the tension at the touch, and the force after it, in closed form)."""

from __future__ import annotations

import math

import pytest

from rjcad.errors import ParameterError
from rjcad.physics.finger_model import FingerModel, G
from rjcad.physics.grasp import close_on, template_outlines
from rjcad.physics.objects import Box, Cylinder

PAD = 5.0
K1, K2, PRELOAD, ARM, LINKS = 2.0, 5.0, math.radians(90), 6.0, (40.0, 30.0)
CENTRE, R = (25.0, 26.0), 16.0


def _cross(a, f) -> float:
    return a[0] * f[1] - a[1] * f[0]


def _by_hand(T: float):
    """Angles and the two normal forces at tension T when both links rest on the cylinder (tangent pads)."""
    cx, cy = CENTRE
    # a pad line tangent to the circle: the centre lies R + PAD from the link's axis line, on the palm side
    th1 = math.atan2(cy, cx) - math.asin((R + PAD) / math.hypot(cx, cy))
    a1 = (LINKS[0] * math.cos(th1), LINKS[0] * math.sin(th1))
    ex, ey = cx - a1[0], cy - a1[1]
    th12 = math.atan2(ey, ex) - math.asin((R + PAD) / math.hypot(ex, ey))
    th2 = th12 - th1
    # contact points: the centre less R along each pad's palmar normal; the force pushes back along it
    n1, n2 = (-math.sin(th1), math.cos(th1)), (-math.sin(th12), math.cos(th12))
    p1, p2 = (cx - R * n1[0], cy - R * n1[1]), (cx - R * n2[0], cy - R * n2[1])
    t12 = _cross(p2, (-n2[0], -n2[1]))  # about joint 1, per newton of link 2's contact
    t22 = _cross((p2[0] - a1[0], p2[1] - a1[1]), (-n2[0], -n2[1]))
    t11 = _cross(p1, (-n1[0], -n1[1]))
    # joint 2: K(θ2 + θ0) = r T + t22 N2; joint 1: K(θ1 + θ0) = r T + t11 N1 + t12 N2
    N2 = (K2 * (th2 + PRELOAD) - ARM * T) / t22
    N1 = (K1 * (th1 + PRELOAD) - ARM * T - t12 * N2) / t11
    return (th1, th2), (N1, N2)


def _two_links(**kw) -> FingerModel:
    return FingerModel((K1, K2), (PRELOAD, PRELOAD), (math.radians(120),) * 2, (ARM, ARM), link_length=LINKS, **kw)


def test_two_links_resting_on_a_cylinder_match_the_hand_solution():
    m = _two_links()
    g = close_on(m, [Cylinder(*CENTRE, 2 * R)], max_tension_n=2.4, outlines=template_outlines(m, PAD), steps=25)
    (th1, th2), (N1, N2) = _by_hand(2.4)
    assert g.touch_order == [1, 2]  # link 1 meets the cylinder first, then link 2 closes onto it
    assert g.theta[-1] == pytest.approx([th1, th2], abs=1e-6)
    forces = {c.link: c.normal_force_n for c in g.contacts[-1]}
    assert forces[1] == pytest.approx(N1, rel=1e-6) and forces[2] == pytest.approx(N2, rel=1e-6)
    assert N1 > 0 and N2 > 0
    v = g.verdict()
    assert v.phalanges_in_contact == [1, 2] and v.enveloping and not v.ejected and v.max_tension_n == 2.4


def test_pulled_harder_link_one_lifts_off_as_the_hand_solution_says():
    """At 4 N the hand solution with both links down needs a pulling contact on link 1 (N1 < 0): the solver
    lifts link 1 off and keeps link 2 alone on the cylinder."""
    m = _two_links()
    assert _by_hand(4.0)[1][0] < 0
    g = close_on(m, [Cylinder(*CENTRE, 2 * R)], max_tension_n=4.0, outlines=template_outlines(m, PAD), steps=40)
    assert [c.link for c in g.contacts[-1]] == [2] and g.contacts[-1][0].normal_force_n > 0


def test_without_an_object_the_closure_is_the_free_one():
    m = FingerModel((K1, 2 * K1), (PRELOAD, PRELOAD), (math.radians(90),) * 2, (ARM, ARM), link_length=LINKS)
    g = close_on(m, [], max_tension_n=0.8, steps=5)
    # free: joint 1 turns with K(θ1 + θ0) = r T; joint 2 waits at its stop until r T reaches 2K·θ0
    th, T = g.theta[-1], g.tension_n[-1]
    assert K1 * (th[0] + PRELOAD) == pytest.approx(ARM * T, rel=1e-9)
    assert th[1] == 0.0 and ARM * T < 2 * K1 * PRELOAD and g.contacts[-1] == []


def test_an_object_in_the_open_finger_is_refused():
    m = _two_links()
    with pytest.raises(ParameterError, match="overlaps link 1 of the open finger"):
        close_on(m, [Cylinder(20.0, 2.0, 10.0)])


# One link meets a cylinder: it turns until its pad is tangent, θ* = atan2(cy, cx) − asin((R + pad)/|c|).
ONE_K, ONE_L, ONE_C, ONE_R = 3.0, 50.0, (30.0, 30.0), 8.0
THETA_STAR = math.atan2(ONE_C[1], ONE_C[0]) - math.asin((ONE_R + PAD) / math.hypot(*ONE_C))
#: the contact's lever about the axis: the distance along the pad from the axis to the tangent point
LEVER = math.sqrt(math.hypot(*ONE_C) ** 2 - (ONE_R + PAD) ** 2)


def _one_link(**kw) -> FingerModel:
    return FingerModel((ONE_K,), (PRELOAD,), (math.radians(120),), (ARM,), link_length=(ONE_L,), **kw)


def _touch_and_force(m: FingerModel, resist, share: float):
    """The closure on the cylinder at 8 N, 81 readings, against the hand's: free, the link turns where
    r·share·T = K(θ + θ0) + resist(θ) (solved by bisection), and touches at that law's tension for θ*; after it,
    the link stays at θ*."""
    from scipy.optimize import brentq

    g = close_on(m, [Cylinder(*ONE_C, 2 * ONE_R)], max_tension_n=8.0, outlines=template_outlines(m, PAD), steps=81)
    law = lambda th: ONE_K * (th + PRELOAD) + resist(th)  # noqa: E731
    T_touch = law(THETA_STAR) / (ARM * share)
    down = [k for k, cs in enumerate(g.contacts) if cs]
    assert g.theta[-1][0] == pytest.approx(THETA_STAR, abs=1e-6)
    for k, T in enumerate(g.tension_n):  # before the touch: the free law; after: held at θ*
        if T < T_touch - 1e-9:
            pull = ARM * share * T
            free = 0.0 if pull <= law(0.0) else brentq(lambda th, p=pull: law(th) - p, 0.0, THETA_STAR, xtol=1e-14)
            assert g.theta[k][0] == pytest.approx(free, abs=1e-6)
    assert g.tension_n[down[0]] >= T_touch - 1e-9 and g.tension_n[down[0] - 1] < T_touch + 1e-9
    return g


def test_bearing_friction_with_a_contact():
    """Closing, the bearing resists by its band f0 + γ⁺(θ + θ0): the link moves when r T exceeds K(θ + θ0) + band.
    On the cylinder the joint no longer moves: the contact then takes r T − K(θ* + θ0) less a friction torque
    anywhere within the band."""
    f0, gp = 0.4, 0.5
    m = _one_link(friction=(f0,), gamma_pos=(gp,), gamma_neg=(gp,))
    band = f0 + gp * (THETA_STAR + PRELOAD)
    g = _touch_and_force(m, lambda th: f0 + gp * (th + PRELOAD), 1.0)
    N = g.contacts[-1][0].normal_force_n
    spare = ARM * 8.0 - ONE_K * (THETA_STAR + PRELOAD)
    assert spare - band - 1e-6 <= N * LEVER <= spare + band + 1e-6


def test_capstan_with_a_contact():
    """The tension reaching the joint is T·exp(−μ_t α): the touch comes later by that factor, and the contact takes
    r T e^(−μα) − K(θ* + θ0)."""
    m = _one_link(wrap=(1.2,), mu_t=0.3)
    share = math.exp(-0.3 * 1.2)
    g = _touch_and_force(m, lambda th: 0.0, share)
    spare = ARM * 8.0 * share - ONE_K * (THETA_STAR + PRELOAD)
    assert g.contacts[-1][0].normal_force_n * LEVER == pytest.approx(spare, rel=1e-6)


def test_gravity_with_a_contact():
    """A 10 g link with its centre of mass 25 mm out, gravity along −y: the weight resists flexion by
    w·25·cos θ; the touch and the force follow with it."""
    mass, com = 10.0, 25.0
    m = _one_link(link_mass=(mass,), gravity=(0.0, -1.0), link_com=((com, 0.0),))
    w = mass * G
    g = _touch_and_force(m, lambda th: w * com * math.cos(th), 1.0)
    spare = ARM * 8.0 - ONE_K * (THETA_STAR + PRELOAD) - w * com * math.cos(THETA_STAR)
    assert g.contacts[-1][0].normal_force_n * LEVER == pytest.approx(spare, rel=1e-6)


def test_a_box_is_met_by_the_corner_its_pad_line_reaches_first():
    """One link closing on a box (x 30…40, y 20…40 mm): the pad line reaches a corner c at the turn
    θ_c = atan2(y_c, x_c) − asin(pad/|c|), first the corner (40, 20) (20.1°; (30, 20) only at 25.7°)."""
    m = _one_link()
    box = Box(35.0, 30.0, 10.0, 20.0)
    g = close_on(m, [box], max_tension_n=8.0, outlines=template_outlines(m, PAD), steps=41)
    cx, cy = 40.0, 20.0
    expect = math.atan2(cy, cx) - math.asin(PAD / math.hypot(cx, cy))
    assert g.theta[-1][0] == pytest.approx(expect, abs=1e-6)
    (c,) = g.contacts[-1]
    assert c.point_mm == pytest.approx((cx, cy), abs=1e-5) and c.normal_force_n > 0
