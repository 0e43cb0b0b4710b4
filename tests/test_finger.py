"""The default finger (the paper's): built once through the CLI, checked as a printer and a user need it."""

import importlib.resources
import io
import itertools
import json
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest
from gltf_tools import counts, glb_bodies, validate
from mesh_tools import load_bodies, manifold, posed, reimport_step, worst_overlap

from rjcad.cad.joint import LEAD_IN
from rjcad.cli import main
from rjcad.design.finger_lengths import shortest_lengths
from rjcad.design.finger_params import DEFAULT_FINGER, PAPER_FINGER, FingerParams
from rjcad.view import THREE_FILE

DEG = math.pi / 180
THREE = (importlib.resources.files("rjcad") / "data" / "vendor" / THREE_FILE).is_file()


@pytest.fixture(scope="module")
def default_finger(tmp_path_factory, root):
    out = tmp_path_factory.mktemp("finger")
    with pytest.raises(SystemExit) as e:  # with the viewer when three.js is vendored (make vendor)
        main(["finger", str(root / "templates" / "finger.toml"), "--out", str(out), *(["--html"] if THREE else [])])
    assert e.value.code == 0
    manifest = json.loads((out / "finger.json").read_text())
    bodies = load_bodies(out / "finger.stl")
    named = {}
    for entry in manifest["bodies"]:
        named[entry["name"]] = min(bodies, key=lambda b: abs(b.volume - entry["volume_mm3"]))
    order = [b["name"] for b in manifest["bodies"]]
    mans = [manifold(named[n]) for n in order]
    axes = [(j["axis_point_mm"], j["axis_dir"]) for j in manifest["joints"]]
    return out, manifest, bodies, order, mans, axes


def test_template_is_the_built_in_default_finger(root):
    assert tomllib.loads((root / "templates" / "finger.toml").read_text()) == DEFAULT_FINGER


def test_default_finger_links_are_the_shortest_whole_mm_and_the_paper_finger_keeps_40():
    fp = FingerParams.from_dict(DEFAULT_FINGER)
    assert {p.layout for p in fp.joints} == {"desktop"}
    base, links = shortest_lengths(fp.joints)
    assert (fp.base_length, [p.link_length for p in fp.joints]) == (base, links) == (29.0, [44.0, 48.0, 42.0])
    paper = FingerParams.from_dict(PAPER_FINGER)
    assert {p.layout for p in paper.joints} == {"stacked"} and paper.joints[0].clearance == 0.25
    assert [p.link_length for p in paper.joints] == [40.0] * 3 and paper.base_length == 25.0


def test_the_finger_rebuilt_from_its_manifest_is_the_one_built(default_finger, root, cli, tmp_path):
    """rjcad.design.rebuild: each joint rebuilt from the manifest has the manifest's spring and bearing block (the
    finger's shared eye plane and widths included); an edited spring is refused in one line; and simulate finger
    takes the same bearing bands from the manifest as from the template."""
    from rjcad.design.rebuild import finger_joints, joint_params
    from rjcad.errors import RjcadError
    from rjcad.io.manifest import Manifest
    from rjcad.physics.bearing_block import bearing_block

    out, manifest = default_finger[0], default_finger[1]
    man = Manifest.coerce(manifest)
    joints = finger_joints(man, "finger.json")
    assert [bearing_block(p) for p in joints] == [j["bearing"] for j in manifest["joints"]]
    edited = json.loads(json.dumps(manifest))
    edited["joints"][1]["spring"]["thickness_mm"] *= 1.1
    with pytest.raises(RjcadError, match=r"finger\.json: joint 2: the joint rebuilt from its manifest has a spring "):
        finger_joints(Manifest.coerce(edited), "finger.json")
    with pytest.raises(RjcadError, match="needs a joint's manifest"):
        joint_params(man, "finger.json")
    args = ("--friction", "bearing", "--mu", "0.3", "--json", "--steps", "50")
    from_manifest = cli("simulate", "finger", out / "finger.json", *args)
    from_template = cli("simulate", "finger", root / "templates" / "finger.toml", *args)
    assert from_manifest.code == from_template.code == 0, from_manifest.err
    bands = [json.loads(r.out)["bearing_friction"] for r in (from_manifest, from_template)]
    assert bands[0] == bands[1]
    # the viewer's closure with the same friction (rjcad view --friction bearing): the same angles
    from rjcad.view import page_data

    data = page_data(manifest, (out / "finger.glb").read_bytes(), "t", 25.0, 50, bearing_mu=0.3)["closure"]
    want = json.loads(from_manifest.out)
    assert data["bearing_mu"] == 0.3
    np.testing.assert_allclose(np.array(data["theta_deg"]), np.array(want["theta_deg"]).T[:51], atol=1e-9)
    if THREE:
        r = cli("view", out / "finger.json", "--out", tmp_path, "--friction", "bearing", "--mu", "0.5")
        assert r.code == 2 and "--mu = 0.5 is invalid: too high for this finger: joint 1" in r.err


def test_outputs(default_finger):
    out = default_finger[0]
    for ext in ("stl", "3mf", "step", "glb", "png", "json", *(["html"] if THREE else [])):
        assert (out / f"finger.{ext}").stat().st_size > 1000, ext


def test_glb_by_the_gltf_spec(default_finger):
    """The Khronos glTF validator finds nothing in finger.glb; metres and +Y up: 0.163 m along X (base end to
    fingertip), about 0.03 m tall, the bed at y = 0; one node per body named as the manifest's, in its preview
    colour, each mesh closed with the body's volume in m³ (positive: outward winding)."""
    out, manifest, *_ = default_finger
    report = validate(out / "finger.glb")["finger.glb"]
    assert counts(report) == {"errors": 0, "warnings": 0, "infos": 0, "hints": 0}, report["issues"]["messages"]
    doc, meshes = glb_bodies((out / "finger.glb").read_bytes())
    assert doc["asset"]["extras"]["units"] == "m" and doc["asset"]["extras"]["up"] == "+Y"
    names = [b["name"] for b in manifest["bodies"]]
    assert [n["name"] for n in doc["nodes"]] == names == ["base", "link1", "link2", "distal"]
    lo = np.min([m.bounds[0] for m in meshes.values()], axis=0)
    hi = np.max([m.bounds[1] for m in meshes.values()], axis=0)
    assert (lo[0], hi[0]) == pytest.approx((-0.029, 0.134), abs=1e-4)  # base 29 mm + links 44 + 48 + 42 mm
    assert lo[1] == 0.0 and 0.025 < hi[1] < 0.035  # up: +Y, from the bed
    assert hi[2] - lo[2] == pytest.approx(0.040, abs=0.002)  # across: rjcad's Y
    for i, b in enumerate(manifest["bodies"]):
        m = meshes[b["name"]]
        assert m.is_watertight and m.volume == pytest.approx(b["volume_mm3"] * 1e-9, rel=0.005), b["name"]
        factor = doc["materials"][doc["meshes"][i]["primitives"][0]["material"]]["pbrMetallicRoughness"]
        linear = np.array(factor["baseColorFactor"][:3])
        srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
        assert np.round(255 * srgb) == pytest.approx([int(BODY_COLOURS[i][k : k + 2], 16) for k in (1, 3, 5)])


def test_four_watertight_manifold_bodies(default_finger):
    _, m, bodies, order, mans, _ = default_finger
    assert len(bodies) == 4
    assert order == ["base", "link1", "link2", "distal"]
    for b, man in zip(bodies, mans):
        assert b.is_watertight and b.is_winding_consistent
        assert man.status().name == "NoError" and man.volume() > 0
    assert sorted(b.volume for b in bodies) == pytest.approx(sorted(e["volume_mm3"] for e in m["bodies"]), rel=0.005)


def test_neighbour_gaps_and_no_overlap(default_finger):
    _, m, _, order, mans, _ = default_finger
    c = m["clearance_mm"]
    for j in m["joints"]:
        a, b = mans[order.index(j["parent"])], mans[order.index(j["child"])]
        gap = a.min_gap(b, 1.0)
        assert c - 0.02 <= gap <= c + 0.05, (j["parent"], j["child"], gap)
    for a, b in itertools.combinations(range(len(mans)), 2):
        assert (mans[a] ^ mans[b]).volume() < 1e-9, (order[a], order[b])


def test_stiffnesses_and_manifest(default_finger):
    _, m, _, _, _, _ = default_finger
    ks = [j["joint_stiffness_nmm_per_rad"] for j in m["joints"]]
    assert ks == pytest.approx([5.2, 7.8, 10.4], rel=0.005)
    for j in m["joints"]:
        for key in (
            "parent",
            "child",
            "axis_point_mm",
            "axis_dir",
            "joint_stiffness_nmm_per_rad",
            "spring",
            "preload_deg",
            "rotation_deg",
            "tendon_moment_arm_mm",
            "tendon_wrap_angle_rad",
        ):
            assert key in j
        assert j["tendon_moment_arm_mm"] == pytest.approx(6.0, abs=1e-6)
        b = j["bearing"]  # issue #36: each joint's bearing at its largest tendon tension
        assert {"friction_torque_nmm", "tilt_deg", "min_gap_under_load_mm", "contacts"} <= set(b)
        spring = j["joint_stiffness_nmm_per_rad"] * math.radians(j["preload_deg"] + j["rotation_deg"])
        assert b["tendon_tension_n"] * 6.0 == pytest.approx(spring + b["friction_torque_nmm"], rel=0.02)
        assert j["preload_deg"] == 90 and j["rotation_deg"] == 90
    assert [j["axis_point_mm"][0] for j in m["joints"]] == [0.0, 44.0, 92.0]
    for key in ("material", "printer", "clearance_mm", "bodies", "tendon_length_mm"):
        assert key in m
    # base channel: square into the base end's centre (LEAD_IN), then climbs r = 6 mm to the fork face's square
    # run: two bends of atan(6/run) each
    path = m["tendon_path_mm"]
    assert path[1][0] - path[0][0] == pytest.approx(LEAD_IN) and path[1][1] == path[0][1] == 0.0
    run = path[2][0] - path[1][0]
    assert path[2][1] == pytest.approx(6.0)
    assert m["joints"][0]["tendon_wrap_angle_rad"] == pytest.approx(2 * math.atan2(6.0, run), rel=1e-6)
    # the links' channels are straight: all joints share one eye plane
    assert m["joints"][1]["tendon_wrap_angle_rad"] == pytest.approx(0.0, abs=1e-9)
    path = np.array(m["tendon_path_mm"])
    assert m["tendon_length_mm"] == pytest.approx(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
    # at rest the tendon runs from the base end to the distal anchor: at least that straight distance
    assert m["tendon_length_mm"] >= path[-1][0] - path[0][0]


def _sweep(mans, axes, start, stop, steps, pairs):
    worst = (0.0, None, None)
    for s in np.linspace(0.0, 1.0, steps + 1):
        th = np.asarray(start) + s * (np.asarray(stop) - np.asarray(start))
        v, pair = worst_overlap(posed(mans, axes, th), pairs)
        if v > worst[0]:
            worst = (v, pair, th / DEG)
    return worst


def test_each_joint_swept_with_the_others_at_zero_then_at_max(default_finger):
    _, m, _, _, mans, axes = default_finger
    n = len(axes)
    rot = [j["rotation_deg"] * DEG for j in m["joints"]]
    for i in range(n):
        # the child subtree of joint i is bodies i+1..n; it moves against bodies 0..i
        pairs = [(a, b) for a in range(i + 1) for b in range(i + 1, n + 1)]
        step = 0.5 * DEG
        for others in (np.zeros(n), np.array(rot)):
            start, stop = others.copy(), others.copy()
            start[i], stop[i] = 0.0, rot[i]
            worst = _sweep(mans, axes, start, stop, math.ceil(rot[i] / step), pairs)
            assert worst[0] < 1e-9, (i, worst)


def test_all_joints_closing_together(default_finger):
    _, m, _, _, mans, axes = default_finger
    rot = [j["rotation_deg"] * DEG for j in m["joints"]]
    pairs = list(itertools.combinations(range(len(mans)), 2))
    worst = _sweep(mans, axes, np.zeros(len(rot)), np.array(rot), 180, pairs)
    assert worst[0] < 1e-9, worst


def test_step_reimports_as_named_valid_solids(default_finger):
    out, m, _bodies, order, _, _ = default_finger
    res = reimport_step(out / "finger.step", order)
    assert sorted(res) == sorted(order)
    for name, entry in zip(order, m["bodies"]):
        n_solids, valid, vol = res[name]
        assert n_solids == 1 and valid and vol == pytest.approx(entry["volume_mm3"], rel=0.01)


BAD = [
    ("stiffness_nmm_per_rad = 5.2\n", None, "stiffness_nmm_per_rad", "unknown key"),
    ("[[joint]]\nstiffness_nmm_per_rad = 5.2\nlink_length_mm = -40\n", None, "joint[1].link_length_mm", ""),
    ("material = 'pla'\n", None, "joint", "1 to 6"),
    ("[[joint]]\nstiffness_nmm_per_rad = 5000\n", None, "joint[1].stiffness_nmm_per_rad", ""),
    (
        "[[joint]]\nstiffness_nmm_per_rad = 55\nrotation_deg = 110\npreload_deg = 120\n",
        None,
        "joint[1].stiffness_nmm_per_rad",
        "spring",
    ),
    ("[defaults]\nrotation_deg = 300\n[[joint]]\nstiffness_nmm_per_rad = 5\n", None, "rotation_deg", "[15, 110]"),
    ("[[joint]]\nstiffness_nmm_per_rad = 5.2\nstifness = 3\n", None, "joint[1].stifness", "known keys"),
    ("bogus = 1\n[[joint]]\nstiffness_nmm_per_rad = 5.2\n", None, "bogus", "known keys"),
    ("[[joint]]\nstiffness_nmm_per_rad = 5.2\nlink_length_mm = 30\n", None, "joint[1].link_length_mm", ">="),
]


@pytest.mark.parametrize("text, _, key, words", BAD)
def test_bad_templates(text, _, key, words, tmp_path, capsys):
    tpl = tmp_path / "bad.toml"
    tpl.write_text(text)
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as e:
        main(["finger", str(tpl), "--out", str(out)])
    err = capsys.readouterr().err
    assert e.value.code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert key in err and words in err and "Traceback" not in err
    assert not out.exists()


def test_seven_joints_rejected(tmp_path, capsys):
    tpl = tmp_path / "seven.toml"
    tpl.write_text("[[joint]]\nstiffness_nmm_per_rad = 5.2\n" * 7)
    with pytest.raises(SystemExit) as e:
        main(["finger", str(tpl), "--out", str(tmp_path / "o")])
    assert e.value.code == 2 and "1 to 6" in capsys.readouterr().err


def test_per_joint_overrides_and_one_joint_finger(tmp_path):
    from rjcad.cad.build import build_finger_model
    from rjcad.design.finger_params import FingerParams

    fp = FingerParams.from_dict(
        {
            "clearance_mm": 0.3,
            "material": "petg",
            "joint": [
                {
                    "stiffness_nmm_per_rad": 4.0,
                    "rotation_deg": 70,
                    "preload_deg": 60,
                    "link_length_mm": 45,
                    "tendon_moment_arm_mm": 7.0,
                }
            ],
        }
    )
    b = build_finger_model(fp)
    m = b.manifest
    assert [x["name"] for x in m["bodies"]] == ["base", "distal"]
    j = m["joints"][0]
    assert j["rotation_deg"] == pytest.approx(70) and j["preload_deg"] == pytest.approx(60)
    assert j["tendon_moment_arm_mm"] == pytest.approx(7.0, abs=1e-6)
    assert j["joint_stiffness_nmm_per_rad"] == pytest.approx(4.0, rel=0.005)
    assert m["clearance_mm"] == 0.3 and m["material"] == "petg"
    for mesh in b.meshes.values():
        assert mesh.is_watertight
    g, d = manifold(b.meshes["base"]), manifold(b.meshes["distal"])
    assert 0.28 <= g.min_gap(d, 1.0) <= 0.35


def test_default_finger_passes_every_check_with_supports_off(default_finger):
    """Issue #15's acceptance: the default (desktop) finger passes overhang and the supports-off slice
    (PrusaSlicer, where installed, as in CI) and every other check."""
    from rjcad.check import run_checks

    out = default_finger[0]
    slicer = "prusa" if shutil.which("prusa-slicer") else None
    rep = run_checks(out / "finger.stl", manifest=out / "finger.json", slicer=slicer)
    failed = {c.name: c.detail for c in rep.checks if c.passed is False}
    assert not failed, failed
    assert {c.name for c in rep.checks if c.passed is True} >= {
        "watertight",
        "manifold",
        "bodies",
        "clearance",
        "motion",
        "min_feature",
        "bed",
        "overhang",
    } | ({"slicer"} if slicer else set())


def test_the_physics_runs_on_the_desktop_finger_manifest(default_finger, capsys):
    """The finger model reads the desktop manifest as built: one spring's (whole) stiffness, preload, the measured
    moment arm and wrap; `rjcad simulate finger` runs on it unchanged."""
    import json as _json

    from rjcad.physics.finger import load_finger_model

    out, m = default_finger[0], default_finger[1]
    model = load_finger_model(str(out / "finger.json"))
    js = m["joints"]
    assert all(j["spring"]["springs"] == 1 for j in js)
    assert model.stiffness == pytest.approx([j["joint_stiffness_nmm_per_rad"] for j in js])
    assert model.stiffness == pytest.approx([5.2, 7.8, 10.4], rel=0.005)
    assert model.moment_arm == pytest.approx([j["tendon_moment_arm_mm"] for j in js])
    assert model.wrap == pytest.approx([j["tendon_wrap_angle_rad"] for j in js])
    assert model.preload == pytest.approx([j["preload_deg"] * DEG for j in js])
    assert model.link_length == pytest.approx([44.0, 48.0, 42.0])
    with pytest.raises(SystemExit) as e:
        main(["simulate", "finger", str(out / "finger.json"), "--stroke", "25", "--steps", "100", "--json"])
    assert e.value.code == 0
    d = _json.loads(capsys.readouterr().out)
    theta = np.array(d["theta_deg"])
    assert theta.shape[0] == 3 and theta.max() > 10.0 and theta.min() >= -1e-6


# ---------------------------------------------------------------- the viewer, in a real browser

ARTEFACTS = Path(__file__).resolve().parents[1] / "out" / "test-artifacts"
BODY_COLOURS = ("#9aa5b1", "#3b82c4", "#e0a33a", "#6aa84f")  # base, link1, link2, distal (the GLB's palette)


def chromium_page(pw):
    """Debian's Chromium (never Playwright's own download), software WebGL, no network: every request that
    is not the file itself or a data: URL is aborted and recorded."""
    browser = pw.chromium.launch(
        executable_path=shutil.which("chromium"), args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
    )
    context = browser.new_context(offline=True, viewport={"width": 960, "height": 720})
    blocked: list[str] = []

    def route(r):
        if r.request.url.startswith(("file:", "data:")):
            r.continue_()
        else:
            blocked.append(r.request.url)
            r.abort()

    context.route("**/*", route)
    return browser, context.new_page(), blocked


def canvas_rgb(page) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(page.locator("canvas").screenshot())).convert("RGB")).astype(int)


def colour_mask(img: np.ndarray, colour: str, tol: float = 0.05) -> np.ndarray:
    """Pixels whose chromaticity (r, g, b)/(r+g+b) is ``colour``'s (shading keeps it), not grey background."""
    c = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
    s = img.sum(axis=-1, keepdims=True)
    return (np.abs(img / np.maximum(s, 1) - c / c.sum()).max(axis=-1) < tol) & (img.std(axis=-1) > 6) & (s[..., 0] > 60)


@pytest.mark.skipif(not THREE, reason="three.js not vendored (make vendor: npm pack three)")
@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium not installed (apt-get install chromium)")
def test_viewer_in_chromium_offline(default_finger, tmp_path, capsys):
    """`rjcad view` writes the same page as `rjcad finger --html`; opened from disk in Chromium with the network
    off, the model loads, the canvas shows every body, the slider at full stroke moves the distal link and the
    page's angles are the physics' (`rjcad simulate finger MANIFEST --json`) within 0.1°."""
    sync_playwright = pytest.importorskip("playwright.sync_api").sync_playwright
    out, manifest, *_ = default_finger
    page_file = tmp_path / "view.html"
    with pytest.raises(SystemExit) as e:
        main(["view", str(out / "finger.json"), "--out", str(page_file)])
    assert e.value.code == 0
    assert page_file.read_bytes() == (out / "finger.html").read_bytes()
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["simulate", "finger", str(out / "finger.json"), "--json"])
    physics = json.loads(capsys.readouterr().out)
    steps = 500  # rjcad simulate finger's default, and the viewer's
    end = [physics["theta_deg"][i][steps] for i in range(len(manifest["joints"]))]
    assert physics["tendon_mm"][steps] == 25.0
    with sync_playwright() as pw:
        browser, page, blocked = chromium_page(pw)
        errors: list[str] = []
        page.on("pageerror", lambda err: errors.append(str(err)))
        page.goto(page_file.as_uri())
        page.wait_for_function("window.rjcad && window.rjcad.ready === true", timeout=60_000)
        assert page.evaluate("window.rjcad.bodies") == [b["name"] for b in manifest["bodies"]]
        rest = canvas_rgb(page)
        slider = page.locator("#stroke")
        slider.fill(slider.get_attribute("max"))
        closed = canvas_rgb(page)
        angles = page.evaluate("window.rjcad.angles_deg")
        shown = page.locator("#readout").inner_text()
        ARTEFACTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(ARTEFACTS / "viewer_full_stroke.png"))
        browser.close()
    assert not errors and not blocked, (errors, blocked)
    assert rest.std() > 10 and closed.std() > 10  # not blank
    for colour in BODY_COLOURS:
        assert colour_mask(rest, colour).mean() > 0.002, colour
    distal = [np.argwhere(colour_mask(img, BODY_COLOURS[3])).mean(axis=0) for img in (rest, closed)]
    assert np.linalg.norm(distal[1] - distal[0]) > 40  # the distal link's centroid moved by > 40 px
    assert np.abs(np.array(angles) - np.array(end)).max() < 0.1, (angles, end)
    assert "tension" in shown and f"{end[-1]:.2f}" in shown


def purple_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of a fixed object (#9467bd, see-through over the background): red and blue both above green; no body
    (grey, blue, orange, green), the tendon (red) or the arrows (black) is."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return (r > g + 10) & (b > g + 20)


@pytest.mark.skipif(not THREE, reason="three.js not vendored (make vendor: npm pack three)")
@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium not installed (apt-get install chromium)")
def test_viewer_with_an_object_in_chromium(default_finger, tmp_path):
    """`rjcad view --object` (issue #40) on the built finger, in Chromium offline: no JS error; the slider runs
    over the closure's readings; the object is drawn; at the last reading an arrow per contact that pushes, the
    readout names the contacts and the verdict; each contact point lies on its link's posed mesh (the page's
    ``contactGapsMm``: 2 mm from inside the object back along −n to the mesh), so the objects and the bodies share
    one frame."""
    sync_playwright = pytest.importorskip("playwright.sync_api").sync_playwright
    from rjcad.physics.finger_sources import outlines_from_manifest

    out, manifest, *_ = default_finger
    # a 40 mm cylinder over the middle of link 1 (x = 20 mm), 1 mm clear of its measured outline
    line = outlines_from_manifest(manifest)[0]
    dx = line[:, 0] - 20.0
    under = np.abs(dx) < 20.0
    y = float((line[under, 1] + np.sqrt(20.0**2 - dx[under] ** 2)).max()) + 1.0
    page_file = tmp_path / "grasp.html"
    spec = f"cylinder:diameter=40,x=20,y={y:.3f},mu=0.5"
    with pytest.raises(SystemExit) as e:
        main(["view", str(out / "finger.json"), "--out", str(page_file), "--object", spec, "--steps", "20"])
    assert e.value.code == 0
    with sync_playwright() as pw:
        browser, page, blocked = chromium_page(pw)
        errors: list[str] = []
        page.on("pageerror", lambda err: errors.append(str(err)))
        page.goto(page_file.as_uri())
        page.wait_for_function("window.rjcad && window.rjcad.ready === true", timeout=60_000)
        slider = page.locator("#stroke")
        assert slider.get_attribute("max") == "19"  # 20 readings
        slider.fill("19")
        img = canvas_rgb(page)
        arrows, contacts = page.evaluate("window.rjcad.arrows"), page.evaluate("window.rjcad.contacts")
        gaps = page.evaluate("window.rjcad.contactGapsMm()")
        panel = page.locator("#panel").inner_text()
        ARTEFACTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(ARTEFACTS / "viewer_grasp.png"))
        browser.close()
    assert not errors and not blocked, (errors, blocked)
    assert purple_mask(img).mean() > 0.01  # the object, on at least 1 % of the canvas
    pushing = [c for c in contacts if math.hypot(c["normal_force_n"], c["tangential_force_n"]) > 0]
    assert len(pushing) >= 2 and len(arrows) == len(pushing), (arrows, contacts)
    assert len(gaps) == len(contacts) and all(abs(g - 2.0) < 0.2 for g in gaps), gaps
    assert "tension 10.00 N" in panel and f"{contacts[0]['body']} on object 1" in panel
    assert "enveloping" in panel and "ε =" in panel and "1 N = " in panel
