"""Palmar outlines (#40): measured on a body's mesh (rjcad.cad.outline), written to a finger's manifest, read by
rjcad.physics.finger_sources.outlines_from_manifest. Checked against trimesh's own sections (no shared code),
on extruded shapes whose envelope is known in closed form and on the default finger's built bodies."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import trimesh
from shared_builds import finger_build

from rjcad.cad.outline import outline_points, palmar_outline
from rjcad.io.manifest import Manifest, ManifestError
from rjcad.physics.finger_sources import base_outline_from_manifest, outlines_from_manifest

#: how far the solid may reach beyond its outline towards the palm, and an outline point lie off it [mm]
TOL = 0.05


def _section_top(mesh: trimesh.Trimesh, x: float) -> float:
    """trimesh's section of ``mesh`` by the plane x = const: its largest y (−inf where there is none) [mm]."""
    s = mesh.section(plane_origin=[x, 0.0, 0.0], plane_normal=[1.0, 0.0, 0.0])
    return -math.inf if s is None else float(s.vertices[:, 1].max())


def _joined(*meshes: trimesh.Trimesh) -> trimesh.Trimesh:
    """The meshes as one (overlapping, not fused) [mm]."""
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    faces = np.vstack([m.faces + k for m, k in zip(meshes, offsets, strict=True)])
    return trimesh.Trimesh(np.vstack([m.vertices for m in meshes]), faces, process=False)


def _stadium_link() -> trimesh.Trimesh:
    """A 40 x 10 mm bar (y in [−5, 5]) ending in a disc of radius 8 at x = 40, 12 mm high (two overlapping
    meshes: the envelope is their union's)."""
    bar = trimesh.creation.box(bounds=[[0.0, -5.0, 0.0], [40.0, 5.0, 12.0]])
    disc = trimesh.creation.cylinder(radius=8.0, height=12.0, sections=256)
    disc.apply_translation([40.0, 0.0, 6.0])
    return _joined(bar, disc)


def test_outline_of_an_extruded_shape_follows_its_closed_form_envelope():
    m = _stadium_link()
    o = palmar_outline(m.vertices, m.faces, origin_x=10.0)
    assert np.all(np.diff(o[:, 0]) > 0) and 3 <= len(o) <= 60
    assert o[0, 0] == pytest.approx(-10.0) and o[-1, 0] == pytest.approx(38.0, abs=1e-3)
    x = np.linspace(-10.0, 38.0, 2001)
    exact = np.maximum(np.where(x <= 30, 5.0, -np.inf), np.sqrt(np.clip(64 - (x - 30) ** 2, 0, None)))
    # the disc is a 256-gon: its flats lie up to 8 (1 − cos(π/512)) = 1.5e-4 mm inside the circle
    err = np.interp(x, o[:, 0], o[:, 1]) - exact
    assert err.min() > -TOL and err.max() < 0.1 + 1e-3


def test_the_slab_limits_the_heights_that_count():
    """A step whose upper half reaches further towards the palm: the lower slab sees only the lower block."""
    low = trimesh.creation.box(bounds=[[0, -5, 0], [30, 5, 10]])
    high = trimesh.creation.box(bounds=[[10, -5, 10], [20, 8, 20]])
    m = _joined(low, high)
    full = palmar_outline(m.vertices, m.faces)
    lower = palmar_outline(m.vertices, m.faces, slab=(0.0, 9.0))
    assert np.interp(15.0, full[:, 0], full[:, 1]) == pytest.approx(8.0)
    assert np.interp(15.0, lower[:, 0], lower[:, 1]) == pytest.approx(5.0)
    assert np.interp([5.0, 25.0], full[:, 0], full[:, 1]) == pytest.approx([5.0, 5.0])


@pytest.fixture(scope="module")
def default_finger():
    from rjcad.io.templates import DEFAULT_FINGER

    return finger_build(DEFAULT_FINGER)


def _bodies(b) -> list[tuple[str, float, np.ndarray, float]]:
    """(body, its frame's x in the finger, outline, link length; the base's: its length) of each body."""
    man = b.manifest
    out = [("base", 0.0, np.array(man.base_palmar_outline_mm), float(b.params.base_length))]
    for j in man.joints:
        out.append((j.child, j.axis_point_mm[0], np.array(j.palmar_outline_mm), j.link_length_mm))
    return out


def test_default_finger_outlines_lie_on_the_solids_and_bound_them(default_finger):
    rng = np.random.default_rng(40)
    for name, x0, o, _ in _bodies(default_finger):
        mesh = default_finger.meshes[name]
        assert o.shape[1] == 2 and 3 <= len(o) <= 100 and np.all(np.diff(o[:, 0]) > 0), name
        # every point on the palmar boundary: the top of a section just before or just after it
        for x, y in o:
            off = min(abs(_section_top(mesh, x0 + x + d) - y) for d in (-1e-4, 1e-4))
            assert off < TOL, (name, x, y, off)
        # nothing of the solid beyond the outline towards the palm: every vertex, and sections in between
        v = mesh.vertices
        assert np.max(v[:, 1] - np.interp(v[:, 0] - x0, o[:, 0], o[:, 1])) < TOL, name
        for x in rng.uniform(o[0, 0], o[-1, 0], 40):
            assert _section_top(mesh, x0 + x) - np.interp(x, o[:, 0], o[:, 1]) < TOL, (name, x)


def test_default_finger_outlines_span_their_links(default_finger):
    bodies = _bodies(default_finger)
    for name, _, o, length in bodies[1:]:
        assert o[0, 0] <= 0.0 and o[-1, 0] >= length - 0.01, name
    distal = bodies[-1][2]
    assert distal[-1, 0] == pytest.approx(bodies[-1][3], abs=0.01)  # the fingertip
    _, _, base, base_length = bodies[0]
    assert base[0, 0] == pytest.approx(-base_length, abs=0.01) and base[-1, 0] > 0.0


def test_outlines_round_trip_through_the_manifest_and_its_reader(default_finger):
    data = json.loads(json.dumps(default_finger.manifest.to_json()))
    assert "base_palmar_outline_mm" in data and all("palmar_outline_mm" in j for j in data["joints"])
    outlines = outlines_from_manifest(data)
    assert outlines is not None and len(outlines) == len(data["joints"])
    for o, j in zip(outlines, data["joints"], strict=True):
        assert o.shape == (len(j["palmar_outline_mm"]), 2) and np.array_equal(o, j["palmar_outline_mm"])
    base = base_outline_from_manifest(data)
    assert base is not None and np.array_equal(base, data["base_palmar_outline_mm"])
    assert Manifest.from_json(data).to_json() == data


def test_a_manifest_without_outlines_loads_with_none(root):
    old = json.loads((root / "tests/data/manifest_v0_finger.json").read_text())
    assert outlines_from_manifest(old) is None and base_outline_from_manifest(old) is None
    m = _stadium_link()
    one = {"schema_version": 1, "joints": [{"palmar_outline_mm": outline_points(m.vertices, m.faces)}, {}]}
    assert outlines_from_manifest(one) is None  # one joint without: no outlines


@pytest.mark.parametrize(
    "outline",
    [[[0, 5]], [[0, 5], [0, 6]], [[1, 5], [0, 6]], [[0, 5], [1, "6"]], [[0, 5, 1], [1, 6, 1]], [[0, 5], [1, math.nan]]],
)
def test_a_bad_outline_is_one_manifest_error(outline):
    with pytest.raises(ManifestError, match=r"joints\[1\]\.palmar_outline_mm"):
        Manifest.from_json({"schema_version": 1, "joints": [{"palmar_outline_mm": outline}]})
    with pytest.raises(ManifestError, match="base_palmar_outline_mm"):
        Manifest.from_json({"schema_version": 1, "joints": [{}], "base_palmar_outline_mm": outline})
