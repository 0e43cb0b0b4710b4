"""Every joint that validation accepts builds into two valid, watertight bodies with their clearance,
free over the whole range of motion, and its wound springs (rod model) clear the other parts."""

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mesh_tools import manifold, sweep_collisions
from wound_tools import wound_strip_clearance

from rjcad.cad.build import build
from rjcad.params import JointParams
from rjcad.errors import InfeasibleDesign, ParameterError

DEG = math.pi / 180

designs = st.builds(
    JointParams,
    stiffness=st.floats(1.0, 14.0),
    rotation=st.floats(20.0, 110.0).map(lambda d: d * DEG),
    preload=st.floats(30.0, 120.0).map(lambda d: d * DEG),
    clearance=st.floats(0.25, 0.6),  # the printers' XY minimum gap (0.25 mm) to the range's top
    link_length=st.floats(32.0, 70.0),
    printer=st.sampled_from(["generic-0.4", "dimension-elite"]),
    material=st.sampled_from(["absplus-p430", "petg", "pla"]),
    end=st.sampled_from(["clamped", "pinned"]),
)


def check_joint(p: JointParams):
    b = build(p)
    g_mesh, m_mesh = b.meshes["ground"], b.meshes["moving"]
    for mesh, solid in ((g_mesh, b.solids.ground), (m_mesh, b.solids.moving)):
        assert solid.isValid() and len(solid.Solids()) == 1
        assert mesh.is_watertight and mesh.is_winding_consistent
        assert len(mesh.split(only_watertight=False)) == 1
        assert abs(mesh.volume / solid.Volume() - 1) < 0.005
    g, m = manifold(g_mesh), manifold(m_mesh)
    assert g.status().name == "NoError" and m.status().name == "NoError"
    gap = g.min_gap(m, 2.0)
    assert p.clearance - 0.02 <= gap <= p.clearance + 0.05, (gap, p)
    step = min(1.0 * DEG, p.clearance / (p.link_length + p.link_width))
    poses = sweep_collisions(g, m, (0, 0, 0), (0, 0, 1), 0.0, p.rotation, step=max(step, 0.25 * DEG))
    assert all(vol < 1e-9 for _, vol, _ in poses), [a / DEG for a, vol, _ in poses if vol > 0][:5]
    assert wound_strip_clearance(p, b.meshes, step_deg=15.0) >= p.gap_internal - 0.05, p
    s = b.manifest["spring"]
    assert b.manifest["spring_strip_volume_mm3"] == pytest.approx(p.springs * s["width_mm"] * s["thickness_mm"] * s["length_mm"], rel=0.02)


def _build_or_skip(data):
    try:
        p = data.draw(designs)
    except (InfeasibleDesign, ParameterError):
        from hypothesis import assume
        assume(False)
    return p


@settings(max_examples=3, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(st.data())
def test_accepted_designs_build_valid_joints_fast(data):
    check_joint(_build_or_skip(data))


@pytest.mark.slow
@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.data())
def test_accepted_designs_build_valid_joints(data):
    check_joint(_build_or_skip(data))


@pytest.mark.parametrize("rotation_deg, preload_deg, clearance, end", [
    (110, 30, 0.25, "clamped"), (15, 120, 0.6, "clamped"), (110, 120, 0.6, "clamped"), (110, 30, 0.25, "pinned")])
def test_range_corners_build(rotation_deg, preload_deg, clearance, end):
    layout = "stacked" if end == "pinned" else None  # the desktop layout holds a clamped end only
    check_joint(JointParams(rotation=rotation_deg * DEG, preload=preload_deg * DEG, clearance=clearance, end=end,
                            layout=layout))


@pytest.mark.parametrize(
    "kw, param",
    [
        (dict(rotation=120 * DEG), "rotation"),
        (dict(preload=20 * DEG), "preload"),
        (dict(clearance=0.1), "clearance"),
        (dict(link_length=200.0), "link_length"),
        (dict(tendon_diameter=3.0), "tendon_diameter"),
        (dict(tendon_moment_arm=2.0), "tendon_moment_arm"),
        (dict(stiffness=float("nan")), "stiffness"),
    ],
)
def test_out_of_range_is_rejected(kw, param):
    with pytest.raises(ParameterError) as e:
        JointParams(**kw)
    assert e.value.parameter == param
