"""Printing without support: the overhang and slicer checks on purpose-made parts and on the stacked joint,
and the 3MF as one object with named parts (read back by PrusaSlicer and by the check)."""

import dataclasses
import io
import math
import re
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
import trimesh
from mesh_tools import box, difference, union

from rjcad.cad import mesh_export as mx
from rjcad.check import run_checks
from rjcad.check.load import PARTS_CONFIG, load_bodies
from rjcad.check.overhang import MAX_BRIDGE_MM, check_overhang
from rjcad.materials import get_printer

PRUSA = shutil.which("prusa-slicer")
PRINTER = get_printer("generic-0.4")


def flare(x0, y0, side, z0, z1, grow):
    """A square frustum: ``side`` wide at z0, ``side + 2·grow`` at z1 (45° when grow = z1 − z0)."""
    lo = [(x0 + dx * side, y0 + dy * side, z0) for dx in (0, 1) for dy in (0, 1)]
    hi = [
        (x0 - grow + dx * (side + 2 * grow), y0 - grow + dy * (side + 2 * grow), z1) for dx in (0, 1) for dy in (0, 1)
    ]
    return trimesh.convex.convex_hull(np.array(lo + hi))


def bridge_part(x0=0.0, span=8.0, width=3.0, height=6.0, pillar=3.0):
    """Two pillars ``span`` apart under a roof of the same body: a bridge anchored at both ends."""
    return union(
        box((x0, 0, 0), (x0 + pillar, width, height)),
        box((x0 + pillar + span, 0, 0), (x0 + 2 * pillar + span, width, height)),
        box((x0, 0, height), (x0 + 2 * pillar + span, width, height + 2)),
    )


def printable_pair():
    """Two bodies that print without support: a block flaring out at exactly 45°, and a bridge of 8 mm."""
    block = union(flare(0, 10, 10, 0, 3, 3), box((-3, 7, 3), (13, 23, 6)))
    return {"block": block, "bridge": bridge_part(x0=0.0)}


def over_other_pair(gap=0.4):
    """A 9 mm bridge of body ``cover`` over the top of body ``low``, ``gap`` mm above it."""
    low = box((0, 0, 0), (8, 6, 4))
    cover = union(
        box((-2.5, 0, 0), (-0.5, 6, 4 + gap + 2)),
        box((8.5, 0, 0), (10.5, 6, 4 + gap + 2)),
        box((-2.5, 0, 4 + gap), (10.5, 6, 4 + gap + 2)),
    )
    return {"low": low, "cover": cover}


def stacked_joint():
    """Today's layout (spring | cheek | eye | cheek | spring) on generic-0.4, and its top spring's z band."""
    from rjcad.cad.build import build
    from rjcad.design.params import JointParams

    names = {f.name for f in dataclasses.fields(JointParams)}
    p = JointParams(printer="generic-0.4", **({"layout": "stacked"} if "layout" in names else {}))
    return build(p).meshes, p.z_spring2


# ---------------------------------------------------------------- overhang


def test_printable_pair_passes_overhang_with_its_bridge_counted():
    parts = printable_pair()
    c = check_overhang(list(parts.values()), list(parts), PRINTER)
    assert c.passed is True, c.detail
    areas = dict(re.findall(r"(\w+): bed ([\d.]+)", c.detail))
    assert float(areas["block"]) == pytest.approx(100, rel=0.02)  # the 10 × 10 foot; the 45° flare is not downward
    bridge = re.search(r"bridge: bed [\d.]+, anchored ([\d.]+)", c.detail)
    assert float(bridge.group(1)) == pytest.approx(8 * 3, rel=0.1)  # the roof between the pillars


def test_surface_over_another_body_fails_overhang_there():
    parts = over_other_pair()
    c = check_overhang(list(parts.values()), list(parts), PRINTER)
    assert c.passed is False
    assert 0 <= c.where[0] <= 8 and 0 <= c.where[1] <= 6 and c.where[2] == pytest.approx(4.4, abs=0.01)
    assert "cover, other body" in c.detail and "under it: low 0.40 mm below" in c.detail
    assert re.search(r"cover: bed [\d.]+, anchored [\d.]+, other body (\d+)", c.detail).group(1) == "48"  # 8 × 6


def test_the_same_bridge_far_above_the_other_body_passes():
    parts = over_other_pair(gap=2.5)
    assert check_overhang(list(parts.values()), list(parts), PRINTER).passed is True


@pytest.mark.parametrize("span, ok", [(MAX_BRIDGE_MM - 1.0, True), (MAX_BRIDGE_MM + 2.0, False)])
def test_bridge_longer_than_the_limit_fails(span, ok):
    c = check_overhang([bridge_part(span=span)], ["b"], PRINTER)
    assert c.passed is ok, c.detail
    if not ok:
        assert "b, air" in c.detail and 3 <= c.where[0] <= 3 + span and c.where[2] == pytest.approx(6)


def test_cantilever_fails_at_its_free_end():
    arm = union(box((0, 0, 0), (3, 3, 6)), box((0, 0, 6), (12, 3, 8)))  # 9 mm out from one pillar
    c = check_overhang([arm], ["arm"], PRINTER)
    assert c.passed is False
    assert c.where[0] > 11 and c.where[2] == pytest.approx(6)
    reach = float(re.search(r"air, ([\d.]+) mm from", c.detail).group(1))
    assert reach == pytest.approx(9, abs=0.3)


def test_body_floating_above_the_bed_starts_in_mid_air():
    c = check_overhang([box((0, 0, 0), (5, 5, 5)), box((10, 0, 1), (15, 5, 5))], ["a", "b"], PRINTER)
    assert c.passed is False and "b, air" in c.detail and c.where[2] == pytest.approx(1)


def test_downward_tip_in_mid_air_fails():
    cone = trimesh.creation.cone(radius=2, height=6, sections=64)  # apex up; flip it: apex down at z = 2
    cone.apply_transform(trimesh.transformations.rotation_matrix(np.pi, [1, 0, 0]))
    cone.apply_translation((20, 0, 8))
    c = check_overhang([box((0, 0, 0), (5, 5, 5)), cone], ["a", "tip"], PRINTER)
    assert c.passed is False
    assert c.where == pytest.approx([20, 0, 2], abs=1e-6) and "lowest point" in c.detail


def test_overhang_is_skipped_for_a_printer_with_soluble_support():
    parts = over_other_pair()
    c = check_overhang(list(parts.values()), list(parts), get_printer("dimension-elite"))
    assert c.passed is None and c.detail.startswith("skipped") and "other body" in c.detail


# ---------------------------------------------------------------- slicer (PrusaSlicer, supports off)


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_printable_pair_passes_the_slicer_check():
    parts = printable_pair()
    rep = run_checks(parts, slicer="prusa", printer="generic-0.4")
    s = rep.get("slicer")
    assert s.passed is True, s.detail
    assert re.search(r"(\d+) bridges excused \(longest ([\d.]+) mm\)", s.detail)
    longest = float(re.search(r"longest ([\d.]+) mm", s.detail).group(1))
    assert 8.0 <= longest <= MAX_BRIDGE_MM  # the roof's first layer spans the 8 mm between the pillars
    assert rep.get("overhang").passed is True


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_bridge_over_another_body_fails_the_slicer_check_there():
    parts = over_other_pair()
    s = run_checks(parts, slicer="prusa", printer="generic-0.4").get("slicer")
    assert s.passed is False
    assert "cover" in s.detail and "low 0.40 mm below" in s.detail
    x, y, z = s.where
    assert -0.5 <= x <= 8.5 and 0 <= y <= 6 and 4.4 <= z <= 4.6


def holed_block(section: list[tuple[float, float]]) -> trimesh.Trimesh:
    """A 16 × 12 × 10 mm block with a horizontal hole along Y of (x, z) ``section`` through it."""
    # both sections are convex: the hole is the hull of the section at y = −1 and at y = 13
    hole = trimesh.convex.convex_hull(np.array([(x, y, z) for x, z in section for y in (-1.0, 13.0)]))
    return difference(box((-8, 0, 0), (8, 12, 10)), hole)


def round_section(r=1.7, z=5.0, n=48):
    return [(r * np.cos(a), z + r * np.sin(a)) for a in np.linspace(0, 2 * np.pi, n, endpoint=False)]


ROOF_50 = math.radians(50)


def teardrop_section(r=1.7, z=5.0, roof=ROOF_50, n=48):
    """The lower part of a circle, then two flanks at ``roof`` from horizontal meeting in a point."""
    a0 = np.pi / 2 - roof  # where the flanks leave the circle, tangent to it
    arc = [(r * np.cos(a), z + r * np.sin(a)) for a in np.linspace(np.pi - a0, 2 * np.pi + a0, n)]
    return arc + [(0.0, z + r / np.cos(roof))]


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_a_teardrop_hole_prints_and_a_round_one_fails_at_its_crown():
    """Roads along a horizontal hole: over a round hole's crown they lie on nothing for the hole's whole length
    (the base's M3 holes did this); a teardrop's tip is a slot narrower than a road, which the road straddles."""
    s = run_checks({"t": holed_block(teardrop_section())}, slicer="prusa", printer="generic-0.4").get("slicer")
    assert s.passed is True, s.detail
    s = run_checks({"r": holed_block(round_section())}, slicer="prusa", printer="generic-0.4").get("slicer")
    assert s.passed is False, s.detail
    x, _y, z = s.where
    assert abs(x) <= 1.7 and 5.0 <= z <= 6.9, s.where  # at the crown (top 6.7), along the hole
    length = float(re.search(r"worst \(where\): r in layer \d+, ([\d.]+) mm", s.detail).group(1))
    assert length > MAX_BRIDGE_MM  # the hole is 12 mm long: no bridge across it excuses that


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_roads_on_nothing_do_not_fail_on_a_printer_with_soluble_support():
    parts = over_other_pair()
    s = run_checks(parts, slicer="prusa", printer="dimension-elite").get("slicer")
    assert s.passed is True and s.value >= 1 and "not failing: dimension-elite prints soluble support" in s.detail


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_bodies_too_close_in_the_toolpaths_fail_the_slicer_check():
    parts = {"a": box((0, 0, 0), (10, 10, 3)), "b": box((10.15, 0, 0), (20, 10, 3))}
    s = run_checks(parts, slicer="prusa", printer="generic-0.4").get("slicer")
    assert s.passed is False and s.value == 0  # no road on nothing: the gap fails it
    gap = float(re.search(r"closest bodies a–b: ([\d.]+) mm", s.detail).group(1))
    assert gap < PRINTER.min_gap_mm - 0.02 and 9.5 <= s.where[0] <= 10.6


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_slicer_fails_a_body_above_the_bed_before_slicing():
    s = run_checks({"a": box((0, 0, 0), (5, 5, 5)), "b": box((10, 0, 1), (15, 5, 5))}, slicer="prusa").get("slicer")
    assert s.passed is False and "mid-air" in s.detail and s.where[2] == pytest.approx(1)


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_stacked_joint_fails_overhang_and_slicer_at_the_top_spring():
    meshes, (z0, z1) = stacked_joint()
    rep = run_checks(meshes, slicer="prusa", printer="generic-0.4")
    for name in ("overhang", "slicer"):
        assert rep.get(name).passed is False, (name, rep.get(name).detail)
    c = rep.get("overhang")
    assert z0 - 1e-6 <= c.where[2] <= z1, (c.where, c.detail)
    # the slicer's worst stretch is a whole first layer over one of the stack's flat 0.4 mm gaps, held at one end:
    # the top spring's, or (since #14's narrower clamped springs) a cheek's or the eye's, whose loops are as long
    # (which of these near-equal loops PrusaSlicer's paths make the longest varies from run to run)
    from rjcad.design.params import JointParams

    p = JointParams(printer="generic-0.4", layout="stacked")
    z = rep.get("slicer").where[2]
    first_layers = (p.spring.width + p.gap_z, p.z_eye[0], p.z_eye[1] + p.gap_z, z0)
    assert min(abs(z - f) for f in first_layers) <= 0.3, (z, first_layers, rep.get("slicer").detail)
    worst = float(
        re.search(r"worst \(where\): (?:ground|moving) in layer \d+, ([\d.]+) mm", rep.get("slicer").detail).group(1)
    )
    # a whole first layer's loop, held at one end (issue #15 measured 452 mm for the top spring's, MK3S profile)
    assert 150 < worst < 600
    assert re.search(r"first failing layer \d+ \(z = [\d.]+\)", rep.get("slicer").detail)
    # printed over the other body across the 0.4 mm gaps: the top cheek over the eye, the eye over the bottom
    # cheek (issue #15, by rays cast down from the mesh's facets: 173 and 171 mm²)
    other = dict(
        re.findall(r"(ground|moving): bed [\d.]+, anchored [\d.]+, other body ([\d.]+)", rep.get("overhang").detail)
    )
    # (172/173 mm² on the first-wave geometry, as the issue measured; the #14 sockets and narrower springs move
    # them: each body still prints well over 150 mm² onto the other across the 0.4 mm gaps)
    assert float(other["ground"]) > 150 and float(other["moving"]) > 150, other


# ---------------------------------------------------------------- the 3MF: one object, named parts


def test_3mf_is_one_object_with_named_parts_and_reads_back(tmp_path):
    parts = printable_pair()
    data = mx.threemf_bytes(parts, name="pair")
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        model = z.read("3D/3dmodel.model").decode()
        config = z.read(PARTS_CONFIG).decode()
    assert model.count("<object ") == 1 and 'name="pair"' in model
    assert re.findall(r'key="name" value="(\w+)"', config) == ["pair", "block", "bridge"]
    path = tmp_path / "pair.3mf"
    path.write_bytes(data)
    scene = trimesh.load(str(path))  # any 3MF reader: one mesh holding both shells
    assert len(scene.geometry) == 1
    bodies, names = load_bodies(path)
    assert names == ["block", "bridge"]
    for b, n in zip(bodies, names):
        assert b.volume == pytest.approx(parts[n].volume, rel=1e-6)
        assert b.bounds == pytest.approx(parts[n].bounds, abs=1e-5)
    assert run_checks(path).body_names == ["block", "bridge"]


def test_3mf_from_objects_still_reads_with_their_names_and_placements(tmp_path):
    parts = printable_pair()
    scene = trimesh.Scene()
    for n, m in parts.items():
        local = m.copy()
        local.apply_translation((-5, 0, 0))
        scene.add_geometry(
            local, node_name=n, geom_name=n, transform=trimesh.transformations.translation_matrix((5, 0, 0))
        )
    path = tmp_path / "objects.3mf"
    path.write_bytes(scene.export(file_type="3mf"))
    bodies, names = load_bodies(path)
    assert sorted(names) == ["block", "bridge"]
    for b, n in zip(bodies, names):
        assert b.bounds == pytest.approx(parts[n].bounds, abs=1e-5)


def _prusa_info(path) -> str:
    r = subprocess.run([PRUSA, "--info", str(path)], capture_output=True, text=True, timeout=120)
    return r.stdout


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_prusaslicer_loads_the_3mf_as_one_object_with_its_parts_in_place(tmp_path):
    parts = printable_pair()
    path = tmp_path / "pair.3mf"
    path.write_bytes(mx.threemf_bytes(parts, name="pair"))
    info = _prusa_info(path)
    assert info.count("[pair.3mf]") == 1 and "number_of_parts =  2" in info
    lo = np.min([m.bounds[0] for m in parts.values()], axis=0)
    hi = np.max([m.bounds[1] for m in parts.values()], axis=0)
    got = {k: float(v) for k, v in re.findall(r"(min_[xyz]|max_[xyz]) = ([-\d.]+)", info)}
    assert [got["min_x"], got["min_y"], got["min_z"]] == pytest.approx(lo, abs=1e-3)
    assert [got["max_x"], got["max_y"], got["max_z"]] == pytest.approx(hi, abs=1e-3)
    # PrusaSlicer's own 3MF of it keeps the part names
    out = tmp_path / "resaved.3mf"
    subprocess.run(
        [PRUSA, "--export-3mf", "--output", str(out), str(path)], capture_output=True, timeout=120, check=True
    )
    with zipfile.ZipFile(out) as z:
        config = z.read(PARTS_CONFIG).decode()
    assert re.findall(r'type="volume" key="name" value="(\w+)"', config) == ["block", "bridge"]


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_prusaslicer_slices_the_default_joint_3mf_as_one_object_at_its_modelled_place(tmp_path):
    from rjcad.cad.build import build, render_files
    from rjcad.design.params import JointParams

    b = build(JointParams())
    path = tmp_path / "joint.3mf"
    path.write_bytes(render_files(b, png=False)["joint.3mf"])
    info = _prusa_info(path)
    assert info.count("[joint.3mf]") == 1 and "number_of_parts =  2" in info
    gcode = tmp_path / "joint.gcode"
    ini = tmp_path / "p.ini"
    ini.write_text(
        "gcode_label_objects = 1\nskirts = 0\nseam_position = rear\nresolution = 0.01\nbed_shape = -100x-100,100x-100,"
        "100x100,-100x100\n"
    )
    subprocess.run(
        [PRUSA, "--export-gcode", "--dont-arrange", "--load", str(ini), "--output", str(gcode), str(path)],
        capture_output=True,
        timeout=300,
        check=True,
    )
    text = gcode.read_text()
    assert len(set(re.findall(r"; printing object (.*?) id:\d+ copy \d+", text))) == 1  # one object
    from gcode_reference import assert_same
    from gcode_reference import parse_gcode as reference

    from rjcad.check.gcode import parse_gcode

    assert_same(parse_gcode(text), reference(text))  # the numpy reader reads it as the line-by-line one did
    xy = np.array([(float(x), float(y)) for x, y in re.findall(r"G1 X([-\d.]+) Y([-\d.]+) E", text)])
    lo = np.min([m.bounds[0] for m in b.meshes.values()], axis=0)
    hi = np.max([m.bounds[1] for m in b.meshes.values()], axis=0)
    assert xy.min(axis=0) == pytest.approx(lo[:2], abs=0.6)  # roads lie half a road inside the outline
    assert xy.max(axis=0) == pytest.approx(hi[:2], abs=0.6)


def test_a_body_the_slicer_moved_or_dropped_is_caught():
    from rjcad.check.gcode import Toolpaths
    from rjcad.check.slicer import POSITION_TOL_MM, _moved

    body = box((0, 0, 0), (10, 10, 3))
    offset = np.array([100.0, 100.0, 0.0])

    def roads(shift):  # one square loop, half a road inside the outline, moved by ``shift`` in x
        x = np.array([0.2, 9.8, 9.8, 0.2]) + offset[0] + shift
        y = np.array([0.2, 0.2, 9.8, 9.8]) + offset[1]
        n = len(x)
        return Toolpaths(
            x,
            y,
            np.roll(x, -1),
            np.roll(y, -1),
            np.full(n, 0.2),
            np.full(n, 0.4),
            np.full(n, 0.2),
            np.zeros(n, int),
            np.zeros(n, int),
            np.ones(n, int),
            ["body0.stl"],
            ["External perimeter"],
        )

    assert _moved(roads(0.0), [body], ["block"], offset) is None
    assert "moved block" in _moved(roads(POSITION_TOL_MM + 1.0), [body], ["block"], offset)
    empty = roads(0.0)
    empty.objects = ["body7.stl"]
    assert _moved(empty, [body], ["block"], offset) == "PrusaSlicer printed nothing of block"


@pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")
def test_the_same_bodies_are_sliced_once_per_process():
    """GCODE_CACHE: slicing the same bodies with the same settings again reads the G-code of the first run."""
    from rjcad.check import GCODE_CACHE

    first = run_checks(printable_pair(), slicer="prusa", printer="generic-0.4").get("slicer")
    n = len(GCODE_CACHE)
    again = run_checks(printable_pair(), slicer="prusa", printer="generic-0.4").get("slicer")
    assert len(GCODE_CACHE) == n >= 1 and "from this run’s cache" in again.detail
    assert (again.passed, again.value, again.where) == (first.passed, first.value, first.where)
    assert again.detail.split("; sliced in")[0] == first.detail.split("; sliced in")[0]
