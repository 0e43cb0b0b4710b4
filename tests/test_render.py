"""The preview renderer (rjcad/cad/render.py) off-screen, with no display: not blank, every body in its colour,
depth-correct (the nearer body hides the farther whatever the drawing order), the tendon drawn; and the GLB
export (named bodies, their colours, the same triangles in glTF's frame: metres, +Y up; the Khronos validator's
verdict)."""

import io

import numpy as np
import pytest
import trimesh
from gltf_tools import counts, glb_bodies, validate
from PIL import Image

from rjcad.cad import mesh_export as mx
from rjcad.cad.render import PANEL, TENDON, TITLE_PX, preview_png, rgb

COLOURS = {"near": "#3b82c4", "far": "#e0a33a"}


def scene():
    """Two boxes on the isometric view's line of sight: 'near' in front of 'far' (the camera is at azimuth
    -60°, elevation 28°), and a tendon polyline through both."""
    az, el = np.radians(-60.0), np.radians(28.0)
    towards_camera = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    near = trimesh.creation.box((10, 10, 10))
    near.apply_translation(towards_camera * 30)
    far = trimesh.creation.box((20, 20, 20))
    tendon = np.array([[-30.0, 0, 0], [0, 0, 0], [30.0, 0, 0]])
    return near, far, tendon


def render(order):
    """The preview of the bodies named in ``order``, drawn in that order, as an RGB array."""
    near, far, tendon = scene()
    meshes = {name: {"near": near, "far": far}[name] for name in order}
    png = preview_png(
        meshes, "test", lines=[tendon], colours=COLOURS, sections=[("z = 9.5", (0, 0, 9.5), (0, 0, 1))]
    )  # cuts both boxes
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def iso(img):
    """The isometric panel (top left, below the title)."""
    return img[TITLE_PX : TITLE_PX + PANEL[1], : PANEL[0]]


def hue_share(img, colour, tol=0.06):
    """Share of pixels whose chromaticity (r, g, b)/(r+g+b) is within ``tol`` of ``colour``'s (shading keeps it)."""
    c = np.array(rgb(colour))
    c = c / c.sum()
    s = img.sum(axis=-1, keepdims=True)
    chrom = img / np.maximum(s, 1)
    close = np.abs(chrom - c).max(axis=-1) < tol
    return float((close & (s[..., 0] > 60) & (img.std(axis=-1) > 8)).mean())


@pytest.fixture(scope="module")
def images():
    return render(["near", "far"]), render(["far", "near"])


def test_renders_without_a_display(images):
    img = images[0]
    assert img.shape == (PANEL[1] * 1 + TITLE_PX, PANEL[0] * 2, 3)  # the view and one section, side by side
    assert img.std() > 10  # not blank
    panel = iso(img)
    assert (panel.std(axis=-1) > 8).mean() > 0.02  # coloured, shaded pixels in the view


def test_each_body_in_its_colour_and_the_tendon_drawn(images):
    panel = iso(images[0])
    for name, colour in COLOURS.items():
        assert hue_share(panel, colour) > 0.002, name
    section = images[0][TITLE_PX:, PANEL[0] :]
    exact = {tuple(round(255 * v) for v in rgb(c)) for c in (*COLOURS.values(), TENDON)}
    present = {tuple(p) for p in section.reshape(-1, 3)}
    assert exact <= present  # the section's outlines are drawn unlit, in the bodies' exact colours


def test_depth_correct_whatever_the_drawing_order(images):
    a, b = (iso(im)[120:] for im in images)  # below the legend (which lists the bodies in the order given)
    assert np.abs(a - b).max() <= 2  # painter's order would swap the overlap between the two renders
    alone = iso(render(["near"]))[120:]  # framed a little closer: the camera fits the bodies shown
    seen, whole = hue_share(a, COLOURS["near"]), hue_share(alone, COLOURS["near"])
    assert whole > 0.01 and seen > 0.6 * whole  # the far box, drawn after it in `a`, does not cover the near one


def test_glb_holds_the_named_bodies_in_their_colours():
    """One node per body, named by it, with its own mesh and material: the body's triangles in glTF's frame
    (metres, +Y up), its preview colour as a linear factor."""
    near, far, _ = scene()
    glb = mx.glb_bytes({"near": near, "far": far}, COLOURS)
    doc, back = glb_bodies(glb)
    assert [n["name"] for n in doc["nodes"]] == ["near", "far"] == [m["name"] for m in doc["meshes"]]
    assert doc["scenes"][doc["scene"]]["nodes"] == [0, 1]
    for i, (name, m) in enumerate((("near", near), ("far", far))):
        g = back[name]
        in_gltf = m.triangles.reshape(-1, 3) @ mx.GLTF_FROM_RJCAD.T  # mm, +Z up → m, +Y up
        assert np.allclose(
            np.sort(g.triangles.reshape(-1, 9), axis=0), np.sort(in_gltf.reshape(-1, 9), axis=0), atol=1e-8
        )
        assert g.volume == pytest.approx(m.volume * 1e-9, rel=1e-5)  # positive: the winding stays outward
        material = doc["materials"][doc["meshes"][i]["primitives"][0]["material"]]
        linear = np.array(material["pbrMetallicRoughness"]["baseColorFactor"])
        srgb = np.where(linear[:3] <= 0.0031308, 12.92 * linear[:3], 1.055 * linear[:3] ** (1 / 2.4) - 0.055)
        assert np.allclose(srgb, rgb(COLOURS[name]), atol=1e-9) and linear[3] == 1.0, name  # glTF's factors: linear
    assert mx.glb_bytes({"near": near, "far": far}, COLOURS) == glb  # reruns give the same bytes


def test_glb_is_in_metres_with_y_up_and_says_so():
    """rjcad's +Z (up, the bed at z = 0) is glTF's +Y, +X stays +X, by a rotation (not a mirror) and 0.001 m/mm;
    the asset states it; each accessor's min/max are its stored values' bounds, in metres."""
    r = mx.GLTF_FROM_RJCAD / 0.001
    assert np.allclose(r @ r.T, np.eye(3)) and np.linalg.det(r) == pytest.approx(1.0)
    assert np.allclose(r @ [0, 0, 1], [0, 1, 0]) and np.allclose(r @ [1, 0, 0], [1, 0, 0])
    bed = trimesh.creation.box((163, 20, 32))
    bed.apply_translation((81.5 - 29, 0, 16))  # 163 mm along X from x = -29, 32 mm tall on the bed
    doc, back = glb_bodies(mx.glb_bytes({"base": bed}))
    assert doc["asset"]["version"] == "2.0" and doc["asset"]["extras"] == mx.GLTF_FRAME
    assert doc["asset"]["extras"]["units"] == "m" and doc["asset"]["extras"]["up"] == "+Y"
    frame = np.array(doc["asset"]["extras"]["source_to_gltf_matrix"]).reshape(4, 4).T  # column-major
    assert np.allclose(frame[:3, :3], mx.GLTF_FROM_RJCAD) and np.allclose(frame[3], [0, 0, 0, 1])
    assert np.allclose(back["base"].bounds, [[-0.029, 0.0, -0.010], [0.134, 0.032, 0.010]], atol=1e-9)
    assert back["base"].bounds[0][1] == 0.0  # the bed, exactly
    position = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    stored = np.asarray(back["base"].vertices, dtype=np.float32)
    assert position["min"] == stored.min(axis=0).tolist() and position["max"] == stored.max(axis=0).tolist()


def test_glb_passes_the_khronos_validator(tmp_path):
    """0 errors, warnings, infos and hints (the joint's and the finger's: tests/test_joint.py, test_finger.py)."""
    near, far, _ = scene()
    (tmp_path / "boxes.glb").write_bytes(mx.glb_bytes({"near": near, "far": far}, COLOURS))
    report = validate(tmp_path / "boxes.glb")["boxes.glb"]
    assert counts(report) == {"errors": 0, "warnings": 0, "infos": 0, "hints": 0}, report["issues"]["messages"]
    assert report["info"]["drawCallCount"] == 2 and report["info"]["totalTriangleCount"] == 24
