"""Issue #40, the first part: a finger closing on fixed cylinders with frictionless contacts
(rjcad/physics/grasp.py), checked against a case solved by hand with none of its code: a two-link finger whose
links both come to rest on a cylinder, where the angles follow from the two tangencies and the forces from the
joints' balance in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rjcad.physics.finger_model import FingerModel
from rjcad.physics.grasp import Cylinder, close_on

PAD = 5.0
K1, K2, PRELOAD, ARM, LINKS, KT = 2.0, 5.0, math.radians(90), 6.0, (40.0, 30.0), 2.0
K = K2
CENTRE, R = (25.0, 26.0), 16.0
STROKE = 8.0


def _by_hand(t_d: float):
    """Angles, tension and the two normal forces when both links rest on the cylinder (tangent pads)."""
    cx, cy = CENTRE
    # a pad line tangent to the circle: the centre lies R + PAD from the link's axis line, on the palm side
    th1 = math.atan2(cy, cx) - math.asin((R + PAD) / math.hypot(cx, cy))
    a1 = (LINKS[0] * math.cos(th1), LINKS[0] * math.sin(th1))
    ex, ey = cx - a1[0], cy - a1[1]
    th12 = math.atan2(ey, ex) - math.asin((R + PAD) / math.hypot(ex, ey))
    th2 = th12 - th1
    T = KT * (t_d - ARM * (th1 + th2))
    # contact points: the centre less R along each pad's palmar normal; the force pushes back along it
    n1, n2 = (-math.sin(th1), math.cos(th1)), (-math.sin(th12), math.cos(th12))
    p1, p2 = (cx - R * n1[0], cy - R * n1[1]), (cx - R * n2[0], cy - R * n2[1])
    cross = lambda a, f: a[0] * f[1] - a[1] * f[0]  # noqa: E731
    t12 = cross((p2[0], p2[1]), (-n2[0], -n2[1]))  # about joint 1, per newton of link 2's contact
    t22 = cross((p2[0] - a1[0], p2[1] - a1[1]), (-n2[0], -n2[1]))
    t11 = cross(p1, (-n1[0], -n1[1]))
    # joint 2: K(θ2 + θ0) = r T + t22 N2; joint 1: K(θ1 + θ0) = r T + t11 N1 + t12 N2
    N2 = (K2 * (th2 + PRELOAD) - ARM * T) / t22
    N1 = (K1 * (th1 + PRELOAD) - ARM * T - t12 * N2) / t11
    return (th1, th2), T, (N1, N2)


def test_two_links_resting_on_a_cylinder_match_the_hand_solution():
    m = FingerModel(
        (K1, K2), (PRELOAD, PRELOAD), (math.radians(120),) * 2, (ARM, ARM), link_length=LINKS, tendon_stiffness=KT
    )
    g = close_on(m, [Cylinder(*CENTRE, 2 * R)], STROKE, pad=PAD)
    (th1, th2), T, (N1, N2) = _by_hand(STROKE)
    assert g.touch_order == [1, 2]  # link 1 meets the cylinder first, then link 2 closes onto it
    assert g.theta[-1] == pytest.approx([th1, th2], abs=1e-6)
    assert g.tension_n[-1] == pytest.approx(T, rel=1e-6)
    forces = {c.link: c.normal_force_n for c in g.contacts[-1]}
    assert forces[1] == pytest.approx(N1, rel=1e-6) and forces[2] == pytest.approx(N2, rel=1e-6)
    assert N1 > 0 and N2 > 0


def test_without_an_object_the_closure_is_the_free_one():
    m = FingerModel((K, 2 * K), (PRELOAD, PRELOAD), (math.radians(90),) * 2, (ARM, ARM), link_length=LINKS)
    g = close_on(m, [], 6.0)
    # free: joint 1 turns with K(θ1 + θ0) = r T, r·θ1 = t_d less the stiff tendon's stretch T/k_t; joint 2 waits
    # at its stop until r T reaches its own preload's torque 2K·θ0
    th = np.asarray(g.theta[-1])
    T = g.tension_n[-1]
    assert K * (th[0] + PRELOAD) == pytest.approx(ARM * T, rel=1e-6)
    assert ARM * th[0] + T / 200.0 == pytest.approx(6.0, rel=1e-6)
    assert th[1] == 0.0 and ARM * T < 2 * K * PRELOAD
    assert g.contacts[-1] == []


def test_an_object_in_the_open_finger_is_refused():
    m = FingerModel((K, K), (PRELOAD, PRELOAD), (1.0, 1.0), (ARM, ARM), link_length=LINKS)
    with pytest.raises(Exception, match="overlaps the open finger"):
        close_on(m, [Cylinder(20.0, 2.0, 10.0)], 5.0)


def test_pulled_further_link_one_lifts_off_as_the_hand_solution_says():
    """At 10 mm the hand solution with both links down needs a pulling contact on link 1 (N1 < 0): the solver
    lifts link 1 off and keeps link 2 alone on the cylinder."""
    m = FingerModel(
        (K1, K2), (PRELOAD, PRELOAD), (math.radians(120),) * 2, (ARM, ARM), link_length=LINKS, tendon_stiffness=KT
    )
    assert _by_hand(10.0)[2][0] < 0
    g = close_on(m, [Cylinder(*CENTRE, 2 * R)], 10.0, pad=PAD)
    assert [c.link for c in g.contacts[-1]] == [2] and g.contacts[-1][0].normal_force_n > 0
