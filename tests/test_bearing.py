"""The bearing model (rjcad.physics.bearing, bearing_paper) against calculations that share no code with it.

* A shaft in a bore of two rims under a side load at a known height: the lever rule, written out here.
* Equilibrium of every solved state: ΣF = 0 and ΣM = 0 recomputed from the contacts' points and normals.
* Turning the whole problem about the axis changes nothing (the friction torque is a frame invariant).
* A cone under an axial load against a quadrature of a uniform pressure over the cone's surface, and the
  wedge factors of a force triangle.
* The spring's end force against the rod model's own ``hub_force`` (rjcad.spring.rod.spiral_windup).
* The calibration reproduces the paper's band; docs/bearing.md quotes the numbers the module computes.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest

from rjcad.design.layout_desktop import CONE_ANGLE
from rjcad.design.params import JointParams
from rjcad.errors import ParameterError
from rjcad.physics import bearing as B
from rjcad.physics import bearing_paper as BP
from rjcad.spring import rod

DOC = Path(__file__).resolve().parents[1] / "docs" / "bearing.md"


def _shaft(c=0.25, h=10.0):
    """A shaft in a bore: two rims at z = 0 and h (radius 2), and an axial stop at the axis (three points)."""
    return (
        B.ring("low", 2.0, 0.0, 1.0, 0.0, c)
        + B.ring("high", 2.0, h, 1.0, 0.0, c)
        + B.ring("stop", 0.0, 0.0, 0, 1, 0.2, 3)
    )


def _equilibrium(state):
    """ΣF and ΣM about a point off the origin, from the loads and the contact forces, written out here."""
    o = np.array([1.3, -0.7, 2.1])
    f, m = np.zeros(3), np.zeros(3)
    for ld in state.loads:
        f += ld.force
        m += np.cross(np.array(ld.point) - o, ld.force)
    for n_i, c in zip(state.forces, state.contacts):
        f += n_i * np.array(c.normal)
        m += np.cross(np.array(c.point) - o, n_i * np.array(c.normal))
    return f, m


@pytest.mark.parametrize("a", [3.0, 7.5, 14.0])
def test_lever_rule(a):
    """F at height a between rims 0 and h: R_high = F·a/h, R_low = F·(1 − a/h) (opposite sides when a > h)."""
    F, h, mu = 1.0, 10.0, 0.3
    s = B.solve(_shaft(h=h), [B.Load("F", (F, 0, 0), (0, 0, a)), B.Load("w", (0, 0, -0.5), (0, 0, 0))], mu)
    got = s.bearing
    assert got["high"] == pytest.approx(abs(F * a / h), abs=1e-9)
    assert got["low"] == pytest.approx(abs(F * (1 - a / h)), abs=1e-9)
    assert got["stop"] == pytest.approx(0.5, abs=1e-9)
    expected_torque = mu * 2.0 * (abs(F * a / h) + abs(F * (1 - a / h)))  # the stop's points are on the axis
    assert s.friction_torque == pytest.approx(expected_torque, abs=1e-9)
    # tilt: none while both rims bear on one side; 2c/h once they bear on opposite sides
    assert s.tilt == pytest.approx(0.0 if a <= h else 2 * 0.25 / h, abs=1e-9)


def test_equilibrium_of_the_layouts():
    p = BP.paper_joint()
    d = JointParams(layout="desktop")
    states = [
        B.driven(p, 0.4, 0.5, 1, "bar").state,
        B.driven(p, 0.4, 1.2, -1, "tendon").state,
        B.driven(d, 0.2, 0.3, 1, "tendon").state,
        B.driven(d, 0.2, d.rotation, -1, "tendon").state,
    ]
    for s in states:
        f, m = _equilibrium(s)
        assert np.abs(f).max() < 1e-9 and np.abs(m[:2]).max() < 1e-9
        assert s.forces.min() >= 0.0  # contacts only push
        closed = s.gaps < 1e-6
        assert np.all(s.forces[~closed] == 0.0)  # and only where they touch
        assert s.gaps.min() > -1e-9  # nothing passes through anything


def _turned(contacts, loads, a):
    c, s = math.cos(a), math.sin(a)

    def t(v):
        return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])

    return (
        [B.Contact(k.surface, t(k.point), t(k.normal), k.gap, k.designed) for k in contacts],
        [B.Load(ld.name, t(ld.force), t(ld.point)) for ld in loads],
    )


@pytest.mark.parametrize("layout", ["stacked", "desktop"])
def test_friction_torque_is_frame_invariant(layout):
    p = JointParams(layout=layout)
    contacts = B.contacts_of(p)
    loads = [B.tendon_load(p, 2.0, 0.7), *B.spring_forces(p).loads(0.7)]
    ref = B.solve(contacts, loads, 0.3)
    for a in (0.37, 2.0):
        s = B.solve(*_turned(contacts, loads, a), 0.3)
        assert s.friction_torque == pytest.approx(ref.friction_torque, rel=1e-7)
        assert s.tilt == pytest.approx(ref.tilt, abs=1e-7)
        assert s.bearing == pytest.approx(ref.bearing, rel=1e-7)


def test_cone_under_axial_load_against_pressure_quadrature():
    """A cone band (r 7.25..8.05, at the cone angle) pushed down by F: the model's contacts at the band's effective
    radius against a uniform pressure integrated over the cone's surface (ψ and slant length, midpoint rule)."""
    a, F, mu, r1, r2 = CONE_ANGLE, 1.7, 0.35, 7.25, 8.05
    # quadrature: dA = r dψ ds, ds = dr / cos a; pressure p along the normal (sin a ê_r + cos a ẑ)
    r = np.linspace(r1, r2, 401)
    rm, dr = 0.5 * (r[1:] + r[:-1]), np.diff(r)
    area_z = 2 * math.pi * np.sum(rm * dr / math.cos(a)) * math.cos(a)  # ∫ n_z dA per unit pressure
    p = F / area_z
    torque_q = mu * p * 2 * math.pi * np.sum(rm * rm * dr / math.cos(a))
    normal_q = p * 2 * math.pi * np.sum(rm * dr / math.cos(a))
    # the model: one ring at the band's friction radius, pushing up and out, and a radial stop at the axis
    r_eff = 2 / 3 * (r2**3 - r1**3) / (r2**2 - r1**2)
    cone = B.ring("cone", r_eff, 0.0, math.sin(a), math.cos(a), 0.1, 72)
    s = B.solve(cone, [B.Load("F", (0, 0, -F), (0, 0, 0))], mu)
    assert sum(s.forces) == pytest.approx(normal_q, rel=1e-6)
    assert sum(s.forces) == pytest.approx(F / math.cos(a), rel=1e-9)  # the axial wedge factor
    assert s.friction_torque == pytest.approx(torque_q, rel=1e-5)


def test_cone_wedge_factor_under_a_radial_load():
    """A radial load on one side of a cone (normal at the cone angle from the axis' plane), its axial part taken
    by a flat stop: the force triangle gives N = F/sin α on the cone and F·cot α on the stop."""
    a, F = CONE_ANGLE, 1.0
    cone = B.ring("cone", 8.0, 0.0, -math.sin(a), -math.cos(a), 0.1, 72)  # pushes in and down (the flare)
    stop = B.ring("stop", 8.0, 0.0, 0.0, 1.0, 0.1, 72)  # a flat ring under the cone's rim: pushes up
    s = B.solve(cone + stop, [B.Load("F", (F, 0, 0), (0, 0, 0))], 0.3)
    assert s.bearing["cone"] == pytest.approx(F / math.sin(a), rel=1e-9)
    assert s.bearing["stop"] == pytest.approx(F / math.tan(a), rel=1e-9)


def test_spring_end_force_matches_the_rod_models_hub_force():
    p = JointParams(layout="desktop")
    d = p.spring
    res = rod.spiral_windup(
        d.inner_radius, d.pitch, d.turns, d.width, d.thickness, d.youngs_modulus,
        sense="unwind", theta_max=p.preload + p.rotation, steps=18,
    )  # fmt: skip
    th = res.theta - p.preload
    sf = B.spring_forces(p)
    for k in (9, 13, 18):
        assert np.interp(th[k], sf.theta_j, sf.magnitude()) == pytest.approx(res.hub_force[k], rel=0.01)
    assert sf.magnitude().max() == pytest.approx(0.29, abs=0.01)  # the 0.29 N
    assert sf.heights == (d.width / 2,)


def test_tendon_resultant_is_the_tension_along_the_ground_channel():
    p = JointParams(layout="desktop")
    for th in (0.0, 0.9):
        ld = B.tendon_load(p, 2.0, th)
        m = np.cross(ld.point, ld.force)
        assert math.hypot(*ld.force[:2]) == pytest.approx(2.0)
        assert m[2] == pytest.approx(2.0 * p.moment_arm)  # r·T flexes the joint
        assert ld.point[2] == pytest.approx(p.z_mid)


def test_calibration_reproduces_the_papers_band():
    mu = BP.calibrate()
    assert BP.band(BP.paper_joint(), mu, "bar") == pytest.approx(BP.PAPER_BAND, rel=0.10)
    assert BP.PAPER_BAND == pytest.approx(10.38)
    # the finding docs/bearing.md states: the paper's load path needs a μ far above dry ABS on ABS
    assert mu > 2 * BP.PLAUSIBLE_MU[1]


def test_bad_inputs():
    p = JointParams(layout="desktop")
    with pytest.raises(ParameterError, match="mu"):
        B.solve(B.contacts_of(p), [B.tendon_load(p, 1.0, 0.0)], -0.1)
    with pytest.raises(ParameterError, match="layout"):
        B.stacked_contacts(p)
    with pytest.raises(ParameterError, match="tension"):
        B.tendon_load(p, -1.0, 0.0)
    with pytest.raises(ParameterError, match="contacts"):
        B.solve(B.ring("floor", 1.0, 0.0, 0, 1, 0.1), [B.Load("up", (0, 0, 1.0), (0, 0, 0))], 0.3)


def test_the_page_quotes_the_computed_numbers():
    text = re.sub(r"^```.*?^```", "", DOC.read_text(encoding="utf-8"), flags=re.S | re.M)  # the examples' blocks
    quoted = set(re.findall(r"`([^`]+)`", text))
    numbers = BP.doc_numbers()
    missing = {k: v for k, v in numbers.items() if f"{k}={v}" not in quoted}
    assert not missing, f"docs/bearing.md does not quote: {missing}"


@pytest.mark.parametrize("layout", ["desktop", "stacked"])
def test_the_manifest_block_is_the_bearing_at_the_largest_tension(layout):
    """bearing_block: the tendon balances the spring and the friction (r·T = τ_s + τ_f), the friction is μ·Σ N·ρ
    of the contacts it lists, and the tilt and gap are those of that state."""
    from rjcad.physics.bearing_block import MU_ASSUMED, bearing_block

    p = JointParams(layout=layout)
    b = bearing_block(p)
    assert b["mu"] == MU_ASSUMED and not b["locked"]
    tau_s = p.springs * p.spring.rod.torque_at(p.preload + p.rotation)
    assert b["tendon_tension_n"] * p.moment_arm == pytest.approx(tau_s + b["friction_torque_nmm"], rel=1e-4)
    state = B.driven(p, MU_ASSUMED, p.rotation, 1, "tendon").state
    by_hand = MU_ASSUMED * sum(f * math.hypot(*c.point[:2]) for f, c in zip(state.forces, state.contacts))
    assert b["friction_torque_nmm"] == pytest.approx(by_hand, rel=1e-4)
    assert set(b["contacts"]) == set(state.bearing) and b["binding"] == state.binding
    assert b["tilt_deg"] == pytest.approx(math.degrees(state.tilt), abs=1e-3)
    assert b["min_gap_under_load_mm"] == pytest.approx(state.min_gap, abs=1e-4)
    if layout == "stacked":  # the pin alone carries the tendon: no tilt, the clearance kept elsewhere
        assert set(b["contacts"]) == {"pin"} and b["tilt_deg"] == 0.0 and b["binding"] == []
    else:  # the finding docs/bearing.md states: the hub rocks until the spring meets the cup wall
        assert b["binding"] == ["spring on cup wall"] and b["tilt_deg"] > 5.0
    touch = B.first_touch(state)
    assert b["first_touch"] == {
        "tilt_deg": pytest.approx(math.degrees(touch.tilt), abs=1e-3),
        "surface": touch.contact.surface,
        "designed": True,  # a designed surface stops the body first: the collar (desktop) or the pin (stacked)
    }
    assert b["first_touch"]["surface"] == ("pin" if layout == "stacked" else "collar")


def test_the_fixed_point_is_the_plain_iterations():
    """driven() finds the friction by secant steps: the same fixed point as the plain iteration τ_f ← F(τ(τ_f))."""
    p = JointParams()
    springs = B.spring_forces(p)
    tau_s, tau_f = B.spring_torque(p, p.rotation), 0.0
    for _ in range(500):
        T = (tau_s + tau_f) / p.moment_arm
        s = B.solve(B.contacts_of(p), [B.tendon_load(p, T, p.rotation), *springs.loads(p.rotation)], 0.4)
        if abs(s.friction_torque - tau_f) < 1e-10:
            break
        tau_f = s.friction_torque
    assert B.driven(p, 0.4, p.rotation, 1, "tendon").drive == pytest.approx(T, rel=1e-8)
    with pytest.raises(B.BearingLocked):  # the calibrated μ locks the desktop joint (docs/bearing.md)
        B.driven(p, BP.calibrate(), p.rotation, 1, "tendon")


@pytest.mark.parametrize("phi, u", [(0.05, 0.0), (0.15, 0.0), (-0.12, 0.3), (0.2, -0.1)])
def test_exact_gaps_of_a_shaft_tilted_in_its_bore(phi, u):
    """A shaft (radius 6.8) tilted by φ about +Y through the origin, then shifted by u along X, in a bore's rim
    (radius 7.25 at height z): the rim's distance from the tilted axis, |q × a| with a = (sin φ, 0, cos φ), less the
    shaft's radius, written out here. The rim is a ground edge: the shaft's surface slides along it. In the plane
    of the tilt (azimuth 0, π) the surface slides along its straight generator and the tangent plane is exact;
    elsewhere it also slides round the shaft, which curves away from its tangent plane: the model's gap is then
    smaller than the true one (it closes early, never late)."""
    R_bore, r_s = 7.25, 6.8
    rims = [(a, z) for a in (0.0, math.pi / 2, math.pi, 4.0) for z in (2.0, 21.0)]
    contacts = [
        B.Contact(
            "rim",
            (R_bore * math.cos(a), R_bore * math.sin(a), z),
            (-math.cos(a), -math.sin(a), 0.0),
            R_bore - r_s,
            edge="ground",
        )
        for a, z in rims
    ]
    got = B.exact_gaps(contacts, (u, 0.0, 0.0, 0.0, phi))
    axis = np.array([math.sin(phi), 0.0, math.cos(phi)])
    for (a, z), g in zip(rims, got):
        q = np.array([R_bore * math.cos(a) - u, R_bore * math.sin(a), z])
        true = np.linalg.norm(np.cross(q, axis)) - r_s
        if abs(math.sin(a)) < 1e-12:
            assert g == pytest.approx(true, abs=1e-12)
        else:
            assert g <= true + 1e-12


def test_first_touch_of_a_shaft_tilting_in_its_bore():
    """A shaft (radius 6.8) tilting about +Y in a bore's rims (radius 7.25, at z = 2 and 21): the rim at azimuth 0,
    z = 21, closes first, where R·cos φ − z·sin φ = r_s, φ = acos(r_s/√(R² + z²)) − atan(z/R) (written out here)."""
    R_bore, r_s = 7.25, 6.8
    rims = [(a, z) for a in (0.0, math.pi / 2, math.pi) for z in (2.0, 21.0)]
    contacts = tuple(
        B.Contact(
            "rim" if (a, z) != (0.0, 21.0) else "top rim",
            (R_bore * math.cos(a), R_bore * math.sin(a), z),
            (-math.cos(a), -math.sin(a), 0.0),
            R_bore - r_s,
            edge="ground",
        )
        for a, z in rims
    )
    n = len(contacts)
    state = B.BearingState(contacts, np.zeros(n), np.array([0.0, 0.0, 0.0, 0.0, 0.2]), np.zeros(n), 0.4)
    touch = B.first_touch(state, closed=1e-9)
    assert touch is not None and touch.contact.surface == "top rim"
    want = math.acos(r_s / math.hypot(R_bore, 21.0)) - math.atan2(21.0, R_bore)
    assert touch.tilt == pytest.approx(want, abs=1e-6)
    assert touch.s == pytest.approx(want / 0.2, abs=1e-5)
    # a motion too small to close anything: no touch
    small = B.BearingState(contacts, np.zeros(n), np.array([0.0, 0.0, 0.0, 0.0, 0.5 * want]), np.zeros(n), 0.4)
    assert B.first_touch(small) is None


def test_exact_gaps_agree_with_the_linearised_ones_to_first_order():
    """On the default desktop joint's contacts: exact − linearised gaps shrink as |δ|² (halving δ quarters it)."""
    contacts = B.contacts_of(JointParams())
    A = B._matrix(contacts)
    g = np.array([c.gap for c in contacts])
    d = np.array([0.3, -0.2, 0.1, 0.04, -0.03])
    err = [np.abs(B.exact_gaps(contacts, s * d) - (g + A.T @ (s * d))).max() for s in (1.0, 0.5, 0.25)]
    assert err[0] > 1e-3  # the second order is not nothing at 3° ...
    assert err[1] / err[0] == pytest.approx(0.25, abs=0.03) and err[2] / err[1] == pytest.approx(0.25, abs=0.03)


def test_a_contact_names_whose_edge_it_is():
    with pytest.raises(ParameterError, match="edge"):
        B.Contact("rim", (1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), 0.1, edge="gorund")
