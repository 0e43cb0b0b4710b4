"""Finger design for target cylinders (issue #40, point 5): the wrap geometry against hand formulas, the middle
link's bound, the predicted quality, the binding target of an impossible set, the CLI's diameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rjcad import DEG
from rjcad.errors import InfeasibleDesign, ParameterError
from rjcad.physics import grasp_design as gd
from rjcad.physics.objects import Cylinder


def test_held_wrap_is_symmetric_as_the_tangent_lengths_say():
    L, D = (41.0, 46.0, 38.0), 25.0
    rho = D / 2 + gd.PAD_MM
    w = gd.wrap(L, (90 * DEG, 110 * DEG, 110 * DEG), (L[0] - L[1] / 2, rho), D / 2)
    assert w.reason is None
    half = 2 * math.atan(L[1] / 2 / rho)  # joint 2 and joint 3 each L2/2 from link 2's tangent point
    np.testing.assert_allclose(w.theta, [0.0, half, half], atol=1e-12)
    np.testing.assert_allclose(w.along, [L[0] - L[1] / 2, L[1] / 2, L[1] / 2], atol=1e-12)


def test_wrapped_links_are_tangent_at_the_reported_points():
    L, rot, centre, R = (50.0, 35.0, 40.0), (90 * DEG, 110 * DEG, 110 * DEG), (30.0, 35.0), 20.0
    w = gd.wrap(L, rot, centre, R)
    assert w.reason is None and w.theta[0] > 0
    axis, heading = np.zeros(2), 0.0
    for i in range(3):  # each axis line at distance R + pad from the centre, its foot at `along` on the link
        heading += w.theta[i]
        d = np.array([math.cos(heading), math.sin(heading)])
        rel = np.array(centre) - axis
        assert rel @ d == pytest.approx(w.along[i], abs=1e-9)
        assert d[0] * rel[1] - d[1] * rel[0] == pytest.approx(R + gd.PAD_MM, abs=1e-9)
        axis = axis + L[i] * d


@pytest.mark.parametrize("rot_deg", [90, 110])
def test_middle_link_bound_separates_wrap_from_stop(rot_deg):
    D, rot = 25.0, rot_deg * DEG
    top = gd.l2_bound(D, rot)
    assert top == pytest.approx(2 * 17.5 * math.tan(rot / 2 - 2 * DEG))
    for L2, ok in ((top - 0.2, True), (top + 0.2, False)):
        L = (L2 / 2 + 10, L2, 40.0)
        w = gd.wrap(L, (90 * DEG, rot, rot), (L[0] - L2 / 2, D / 2 + gd.PAD_MM), D / 2)
        assert (w.reason is None) is ok, w.reason
    assert "joint 2 must turn" in w.reason


def test_predicted_epsilon_is_the_largest_gap_between_normals():
    """Frictionless: the normals' hull is a polygon on the unit circle; ε = cos(largest gap / 2) (gap < 180°)."""
    L, D = (40.0, 46.0, 38.0), 25.0
    c = Cylinder(L[0] - L[1] / 2, D / 2 + gd.PAD_MM, diameter=D)
    w = gd.wrap(L, (90 * DEG, 110 * DEG, 110 * DEG), (c.x, c.y), c.radius)
    th = 2 * math.atan(L[1] / 2 / (D / 2 + gd.PAD_MM))
    assert gd.predicted_epsilon(L, w, c) == pytest.approx(math.cos(max(th, 2 * math.pi - 2 * th) / 2), abs=1e-9)
    big = Cylinder(c.x, 27.5 + gd.PAD_MM, diameter=55.0)  # links 2 and 3 turn < 90° each: no force closure
    assert gd.predicted_epsilon(L, gd.wrap(L, (90 * DEG, 110 * DEG, 110 * DEG), (big.x, big.y), 27.5), big) == 0


def test_an_impossible_set_names_the_small_cylinder_and_the_bound():
    def never(*a, **k):
        raise AssertionError("the geometry alone rules this set out")

    with pytest.raises(InfeasibleDesign) as e:
        gd.design_for_targets([gd.Held(120.0), gd.Held(5.0)], solve=never)
    msg = str(e.value)
    assert msg.startswith("5 mm: link 2 must be <= 19.9 mm") and "110°" in msg and "shortest middle link" in msg


def test_a_fixed_cylinder_in_the_open_finger_binds_with_its_reason():
    with pytest.raises(InfeasibleDesign, match=r"^20 mm at \(20, 10\): .*overlaps the open finger$"):
        gd.design_for_targets([gd.Held(25.0), Cylinder(20.0, 10.0, diameter=20.0)], solve=lambda *a, **k: None)


def test_cylinders_shorthand():
    assert gd.parse_diameters("25:55:10") == [25, 35, 45, 55]
    assert gd.parse_diameters("25:50:10") == [25, 35, 45]
    assert gd.parse_diameters("20, 40") == [20, 40]
    for bad in ("55:25:10", "25:55", "25:55:0", "a,b", "0", "1:1000:1"):
        with pytest.raises(ParameterError):
            gd.parse_diameters(bad)


@pytest.mark.slow
def test_targets_25_to_55_give_a_finger_that_builds_grasps_every_target_and_prints(tmp_path, cli):
    """Issue #40's acceptance: design for 25-55 mm, build the template, close the built finger (its manifest's
    model and the links' outlines measured on its solids) on each target, held where the docs hold it on that
    built finger: enveloping; `rjcad check` with the slicer passes."""
    import json
    import shutil

    from rjcad.physics.finger_sources import model_from_manifest, outlines_from_manifest
    from rjcad.physics.grasp import close_on, held_position

    design, built = tmp_path / "design", tmp_path / "built"
    r = cli("finger-design", "--cylinders", "25:55:10", "--out", design, "--json")
    assert r.code == 0, r.err
    rep = json.loads(r.out)
    assert [t["object"]["diameter_mm"] for t in rep["targets"]] == [25, 35, 45, 55]
    assert all(t["enveloping"] and not t["ejected"] for t in rep["targets"])
    assert cli("finger", design / "finger.toml", "--out", built).code == 0
    manifest = json.loads((built / "finger.json").read_text())
    model, outlines = model_from_manifest(manifest), outlines_from_manifest(manifest)
    assert model.link_length == tuple(rep["link_length_mm"]) and outlines is not None
    for t in rep["targets"]:
        D = t["object"]["diameter_mm"]
        g = close_on(model, [Cylinder(*held_position(model, D, outlines), D)], outlines=outlines, steps=20)
        assert g.verdict().enveloping, (D, g.verdict())
    if shutil.which("prusa-slicer") is not None:
        r = cli("check", built / "finger.3mf", "--manifest", built / "finger.json", "--slicer", "prusa")
        assert r.code == 0, r.out + r.err
