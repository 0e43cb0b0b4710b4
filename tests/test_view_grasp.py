"""`rjcad view --object` (issue #40): the page's data carry rjcad's closure on the objects (one slider step per
reading, the objects' poses, an arrow per contact force at the stated scale), the page is written whole, bad
input is one error line. The page in Chromium, on the built default finger: test_finger.py."""

import importlib.resources
import json
import math
import re

import numpy as np
import pytest

from rjcad.physics.grasp_result import ARROW_FRACTION
from rjcad.physics.objects import Cylinder
from rjcad.view import THREE_FILE, close_grasp, page_data

THREE = (importlib.resources.files("rjcad") / "data" / "vendor" / THREE_FILE).is_file()
#: A cylinder where the docs hold it for the v0 manifest's finger (links 40 mm, the template's pads at 5 mm:
#: ``rjcad.physics.grasp.held_position`` gives (20, 25) mm): links 1 and 3 press it (about 1 s for 10 readings).
SPEC = "cylinder:diameter=40,x=20,y=25.01,mu=0.5"
HELD = Cylinder(20.0, 25.01, diameter=40.0, mu=0.5)


@pytest.fixture(scope="module")
def built(tmp_path_factory, root):
    """The v0 finger manifest (no outlines: the template's pads) with a small GLB of one box per body beside it."""
    import trimesh

    from rjcad.cad.mesh_export import glb_bytes

    folder = tmp_path_factory.mktemp("built")
    man = json.loads((root / "tests" / "data" / "manifest_v0_finger.json").read_text())
    (folder / "finger.json").write_text(json.dumps(man))
    boxes = {b["name"]: trimesh.creation.box((10, 10, 10)) for b in man["bodies"]}
    (folder / "finger.glb").write_bytes(glb_bytes(boxes))
    return folder, man


def page_json(html: str) -> dict:
    """The page's data (its JSON script element)."""
    m = re.search(r'<script id="rjcad-data" type="application/json">(.*?)</script>', html, re.S)
    assert m, "no data element"
    return json.loads(m.group(1).replace("<\\/", "</"))


def test_the_pages_data_carry_the_grasp_one_slider_step_per_reading(built):
    folder, man = built
    glb = (folder / "finger.glb").read_bytes()
    g = close_grasp(man, [HELD], 10.0, None, 10)
    data = page_data(man, glb, "t", 25.0, 500, grasp=g)
    c, d = data["closure"], data["grasp"]
    n = len(g.tendon_mm)
    assert n == 10 and c["steps"] == n - 1 and len(c["theta_deg"]) == len(c["tension_n"]) == n
    assert c["theta_deg"] == d["theta_deg"] and c["tension_n"] == d["tension_n"] and c["tendon_mm"] == d["tendon_mm"]
    assert c["tension_n"][0] == 0.0 and c["tension_n"][-1] == pytest.approx(10.0)
    assert d["object_specs"] == [HELD.to_dict()] and all(len(p) == 1 for p in d["objects"]) and len(d["objects"]) == n
    assert d["grasp"]["phalanges_in_contact"] == [1, 3] and d["grasp"]["quality"]["epsilon"] > 0, d["grasp"]
    # one arrow per contact, from its point along F_n n + F_t t (t: n turned +90°), mm_per_n long per N
    assert [len(a) for a in d["arrows_mm"]] == [len(cs) for cs in d["contacts"]]
    k = d["arrow_mm_per_n"]
    longest = 0.0
    for arrows, contacts in zip(d["arrows_mm"], d["contacts"]):
        for (x0, y0, x1, y1), ct in zip(arrows, contacts):
            n_, t_ = np.array(ct["normal"]), np.array([-ct["normal"][1], ct["normal"][0]])
            f = ct["normal_force_n"] * n_ + ct["tangential_force_n"] * t_
            assert [x0, y0] == ct["point_mm"]
            assert np.allclose([x1 - x0, y1 - y0], k * f, atol=1e-9)
            longest = max(longest, math.hypot(x1 - x0, y1 - y0))
    assert longest == pytest.approx(ARROW_FRACTION * 120.0)  # the largest force: a quarter of the 3 × 40 mm finger


def test_without_objects_the_pages_data_are_as_before(built):
    folder, man = built
    data = page_data(man, (folder / "finger.glb").read_bytes(), "t", 25.0, 50)
    assert "grasp" not in data and set(data["closure"]) == {"stroke_mm", "steps", "mu_t", "tendon_mm", "theta_deg",
                                                             "tension_n"}  # fmt: skip
    assert len(data["closure"]["theta_deg"]) == 51 and data["closure"]["tendon_mm"][-1] == 25.0


@pytest.mark.skipif(not THREE, reason="three.js not vendored (make vendor: npm pack three)")
def test_view_with_objects_writes_the_whole_page(cli, built, tmp_path):
    folder, _ = built
    more = ("--object", SPEC, "--max-tension", "5", "--steps", "10")
    r = cli("view", str(folder / "finger.json"), "--out", str(tmp_path), *more)
    assert r.code == 0, r.err
    html = (tmp_path / "finger.html").read_text()
    assert html.rstrip().endswith("</html>") and "@@" not in html and 'import * as THREE from "data:' in html
    d = page_json(html)
    assert len(d["closure"]["theta_deg"]) == 10  # the closure's readings, not the pull's steps + 1
    assert d["grasp"]["grasp"]["max_tension_n"] == pytest.approx(5.0)
    assert d["grasp"]["object_specs"] == [HELD.to_dict()]
    # the same closure as `rjcad simulate finger MANIFEST --object SPEC --max-tension 5 --steps 10 --json`
    r = cli("simulate", "finger", str(folder / "finger.json"), *more, "--json")
    assert r.code == 0, r.err
    sim = json.loads(r.out)
    assert d["closure"]["theta_deg"] == sim["theta_deg"] and d["grasp"]["contacts"] == sim["contacts"]


@pytest.mark.parametrize(
    "args, names",
    [
        (["--object", "cylinder:diameter=40,x=60"], "--object"),  # no y
        (["--object", "sphere:diameter=40,x=60,y=25"], "--object"),
        (["--object", "cylinder:diameter=nan,x=60,y=25"], "--object"),
        (["--max-tension", "3"], "--max-tension"),  # only with objects
        (["--object", SPEC, "--max-tension", "0"], "--max-tension"),
        (["--object", "cylinder:diameter=40,x=20,y=0"], "overlaps link 1"),  # inside the open finger
    ],
)
def test_view_refuses_a_bad_object_in_one_line(cli, built, tmp_path, args, names):
    folder, _ = built
    r = cli("view", str(folder / "finger.json"), "--out", str(tmp_path / "page"), *args)
    assert r.code == 2 and r.err.count("\n") == 1 and r.err.startswith("rjcad: error:"), r.err
    assert names in r.err, r.err
    assert not (tmp_path / "page" / "finger.html").exists()
