"""rjcad.cad.export on small solids: tessellation within its chord tolerance, measurements along rays and
channels, STL/3MF/STEP bytes that read back, and atomic writes. No joint build."""

import io
import math

import cadquery as cq
import numpy as np
import pytest
import trimesh

from rjcad.cad import export as ex
from rjcad.cad import mesh_export as mx


def cylinder(r=2.0, h=10.0):
    return cq.Solid.makeCylinder(r, h, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))


def test_triangulate_gives_cadquerys_tessellation_exactly():
    """The direct read of the triangulation equals CadQuery's Shape.tessellate: same nodes, order and winding
    (a cut solid has reversed faces, whose triangles are flipped), on a solid moved by a location."""
    block = cq.Solid.makeBox(10, 8, 6).cut(cylinder(2.0, 6.0).translate(cq.Vector(5, 4, 0)))
    block = block.moved(cq.Location(cq.Vector(1, 2, 3), cq.Vector(0, 0, 1), 30))
    v, f = ex.triangulate(block)
    verts, tris = block.tessellate(mx.MESH_TOLERANCE, mx.MESH_ANGULAR_TOLERANCE)
    assert np.array_equal(v, np.array([p.toTuple() for p in verts], dtype=float))
    assert np.array_equal(f, np.asarray(tris, dtype=np.int64))
    assert any(face.wrapped.Orientation().name == "TopAbs_REVERSED" for face in block.Faces())


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
    ring = cylinder(5.0, 4.0).cut(cylinder(3.0, 4.0))  # an eye: material from r = 3 to 5
    spans = ex.segment_inside(ring, (0, 0, 2), (20, 0, 2))
    assert spans == [pytest.approx((3.0, 5.0))]
    # the arm: where the ray from the axis first leaves the material, plus half the line
    assert ex.measure_moment_arm(ring, 2.0, 0.6, direction=(1.0, 0.0, 0.0)) == pytest.approx(5.3)
    with pytest.raises(RuntimeError, match="does not cross"):
        ex.measure_moment_arm(ring, 10.0, 0.6)


def test_wrap_angle_sums_the_turns_of_a_channel():
    """A bent channel of radius 1: a run along x, then one climbing at 30°."""
    run1 = cq.Solid.makeCylinder(1.0, 10.0, cq.Vector(0, 0, 0), cq.Vector(1, 0, 0))
    d = (math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0)
    run2 = cq.Solid.makeCylinder(1.0, 10.0, cq.Vector(10, 0, 0), cq.Vector(*d))
    channel = run1.fuse(run2)
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
    data = ex.step_bytes({"pin": cylinder(1.0, 5.0), "cube": cq.Solid.makeBox(2, 2, 2)}, "pair")
    assert data.startswith(b"ISO-10303-21")
    assert b"pin" in data and b"cube" in data
    (tmp_path / "pair.step").write_bytes(data)
    shape = cq.importers.importStep(str(tmp_path / "pair.step")).val()
    assert len(shape.Solids()) == 2
    assert shape.Volume() == pytest.approx(math.pi * 5 + 8, rel=1e-6)


def test_write_outputs_writes_every_file_and_no_temporaries(tmp_path):
    paths = mx.write_outputs(tmp_path / "out", {"a.json": "{}\n", "b.stl": b"\0" * 84})
    assert [p.name for p in paths] == ["a.json", "b.stl"]
    assert (tmp_path / "out" / "a.json").read_text() == "{}\n"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.json", "b.stl"]
