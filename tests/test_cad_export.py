"""rjcad.cad.export on small solids: tessellation within its chord tolerance, measurements along rays and
channels, STL/3MF/STEP bytes that read back, and atomic writes. No joint build."""

import io
import math

import numpy as np
import pytest
import trimesh

from rjcad.cad import export as ex
from rjcad.cad import mesh_export as mx
from rjcad.cad import occ


def cylinder(r=2.0, h=10.0):
    return occ.cylinder(r, h)


def test_triangulate_winds_every_face_outwards_and_follows_a_location():
    """A cut block (its bore's faces reversed: their triangles are flipped) meshes into a closed mesh wound
    outwards, of the block's volume; the same block placed by a location (shared geometry) gives the same
    triangles, its nodes moved by the location."""
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    block = occ.cut(occ.box(10, 8, 6), occ.translated(cylinder(2.0, 6.0), (5, 4, 0)))
    assert any(face.Orientation().name == "TopAbs_REVERSED" for face in occ.faces(block))
    v, f = ex.triangulate(block)
    mesh = mx.mesh_of(v, f)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume == pytest.approx(occ.volume(block), rel=1e-3)  # positive: wound outwards
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(30))
    t.SetTranslationPart(gp_Vec(1, 2, 3))
    v2, f2 = ex.triangulate(block.Moved(TopLoc_Location(t)))
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    moved = v @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]]) + (1, 2, 3)
    assert np.array_equal(f2, f) and np.allclose(v2, moved, atol=1e-12)


def test_to_mesh_is_watertight_and_within_the_chord_tolerance():
    r = 2.0
    mesh = ex.to_mesh(cylinder(r))
    assert mesh.is_watertight and mesh.is_winding_consistent
    rho = np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 1])
    side = (mesh.vertices[:, 2] > 1e-6) & (mesh.vertices[:, 2] < 10 - 1e-6)
    assert np.allclose(rho[side], r, atol=1e-9)  # vertices on the surface
    # chords sag inwards by at most the tolerances: r·(1 − cos(δ/2)) with δ the angular step
    sag = min(mx.MESH_TOLERANCE, r * (1 - math.cos(mx.MESH_ANGULAR_TOLERANCE / 2)))
    faces_mid = mesh.triangles_center
    mid_rho = np.hypot(faces_mid[:, 0], faces_mid[:, 1])
    on_side = (faces_mid[:, 2] > 1e-6) & (faces_mid[:, 2] < 10 - 1e-6)
    assert np.all(mid_rho[on_side] >= r - sag - 1e-9)
    assert mesh.volume == pytest.approx(math.pi * r**2 * 10, rel=2 * sag / r)
    coarse = ex.to_mesh(cylinder(r), tolerance=0.1, angular_tolerance=0.5)
    assert len(coarse.faces) < len(mesh.faces)


def test_segment_inside_and_moment_arm_along_a_ray():
    ring = occ.cut(cylinder(5.0, 4.0), cylinder(3.0, 4.0))  # an eye: material from r = 3 to 5
    spans = ex.segment_inside(ring, (0, 0, 2), (20, 0, 2))
    assert spans == [pytest.approx((3.0, 5.0))]
    # the arm: where the ray from the axis first leaves the material, plus half the line
    assert ex.measure_moment_arm(ring, 2.0, 0.6, direction=(1.0, 0.0, 0.0)) == pytest.approx(5.3)
    with pytest.raises(RuntimeError, match="does not cross"):
        ex.measure_moment_arm(ring, 10.0, 0.6)


def test_wrap_angle_sums_the_turns_of_a_channel():
    """A bent channel of radius 1: a run along x, then one climbing at 30°."""
    run1 = occ.cylinder(1.0, 10.0, (0, 0, 0), (1, 0, 0))
    d = (math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0)
    run2 = occ.cylinder(1.0, 10.0, (10, 0, 0), d)
    channel = occ.fuse(run1, run2)
    assert len(ex.channel_axes(channel, 1.0)) == 2
    assert ex.measure_wrap_angle(channel, 1.0) == pytest.approx(math.radians(30), abs=1e-6)
    with pytest.raises(RuntimeError, match="no channel"):
        ex.measure_wrap_angle(channel, 2.0)


def test_stl_and_3mf_read_back_with_their_bodies(tmp_path):
    from rjcad.check.load import load_bodies

    a = trimesh.creation.box(extents=(1, 2, 3))
    b = trimesh.creation.box(extents=(1, 1, 1))
    b.apply_translation((5, 0, 0))
    stl = trimesh.load(io.BytesIO(mx.stl_bytes([a, b])), file_type="stl")
    assert len(stl.split(only_watertight=False)) == 2 and stl.volume == pytest.approx(6 + 1)
    # the 3MF is one object whose named parts are the bodies (see tests/test_check_print.py)
    path = tmp_path / "pair.3mf"
    path.write_bytes(mx.threemf_bytes({"ground": a, "moving": b}))
    bodies, names = load_bodies(path)
    assert names == ["ground", "moving"]
    assert bodies[0].volume == pytest.approx(6) and bodies[1].volume == pytest.approx(1)


def test_step_names_its_solids(tmp_path):
    from mesh_tools import read_step

    data = ex.step_bytes({"pin": cylinder(1.0, 5.0), "cube": occ.box(2, 2, 2)}, "pair")
    assert data.startswith(b"ISO-10303-21")
    (tmp_path / "pair.step").write_bytes(data)
    named = read_step(tmp_path / "pair.step")
    assert list(named) == ["pin", "cube"]
    assert [len(occ.solids(s)) for s in named.values()] == [1, 1]
    assert occ.volume(named["pin"]) == pytest.approx(math.pi * 5, rel=1e-6)
    assert occ.volume(named["cube"]) == pytest.approx(8, rel=1e-6)


def test_write_outputs_writes_every_file_and_no_temporaries(tmp_path):
    paths = mx.write_outputs(tmp_path / "out", {"a.json": "{}\n", "b.stl": b"\0" * 84})
    assert [p.name for p in paths] == ["a.json", "b.stl"]
    assert (tmp_path / "out" / "a.json").read_text() == "{}\n"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.json", "b.stl"]
