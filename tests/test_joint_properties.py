"""Every joint that validation accepts builds into valid, watertight bodies with their clearance, free over the
whole range of motion, and its wound springs (rod model) clear the other parts (issue #17, the valid side).

The random test builds RANDOM_JOINTS accepted designs per run, spread over every material, printer, layout and end,
and over stiffness, rotation, preload, clearance (within the printer's), link length, tendon, pin and safety factor;
designs that validation refuses are drawn again and do not count. Each build is checked here, independently of
``rjcad check`` (tests/body_checks.py). Hypothesis runs derandomized (the same designs every run) and does not
shrink: a failing build and check takes seconds, so the falsifying design is reported as drawn.
"""

import collections
import math
import time

import pytest
from body_checks import check_gaps, named_bodies, overlap_free_sweep, solid
from hypothesis import HealthCheck, Phase, example, given, reject, settings
from hypothesis import strategies as st
from wound_tools import wound_strip_clearance

from rjcad.cad import occ
from rjcad.cad.build import build
from rjcad.cad.mesh_export import stl_bytes
from rjcad.design.params import LAYOUTS, RANGES, JointParams
from rjcad.errors import ParameterError, RjcadError
from rjcad.materials import MATERIALS, PRINTERS

DEG = math.pi / 180
#: Accepted designs the random test builds per run (issue #17: at least 50).
RANDOM_JOINTS = 50


def _range(name, lo=None, hi=None):
    """Floats over RANGES[name] (angles in rad; a lower bound of None depends on the geometry), narrowed to
    [lo, hi] where given."""
    r_lo, r_hi, _ = RANGES[name]
    lo = r_lo if lo is None else lo if r_lo is None else max(lo, r_lo)
    return st.floats(lo, r_hi if hi is None else min(hi, r_hi))


@st.composite
def joint_designs(draw) -> dict:
    """JointParams keywords: every printer, layout, end (pinned: stacked only) and material; the clearance within
    the printer's (at least its XY gap) or the default; stiffness log-uniform over the whole range; links up to
    half the bed."""
    printer = draw(st.sampled_from(sorted(PRINTERS)))
    layout = draw(st.sampled_from(LAYOUTS))
    k_lo, k_hi, _ = RANGES["stiffness"]
    c_lo = max(RANGES["clearance"][0], PRINTERS[printer].min_gap_mm)
    return dict(
        printer=printer,
        layout=layout,
        material=draw(st.sampled_from(sorted(MATERIALS))),
        end="clamped" if layout == "desktop" else draw(st.sampled_from(["clamped", "pinned"])),
        stiffness=math.exp(draw(st.floats(math.log(k_lo), math.log(k_hi)))),
        rotation=draw(_range("rotation")),
        preload=draw(_range("preload")),
        clearance=draw(st.none() | st.floats(c_lo, RANGES["clearance"][1])),
        link_length=draw(st.floats(30.0, min(RANGES["link_length"][1], PRINTERS[printer].bed_length / 2))),
        tendon_diameter=draw(st.just(1.0) | _range("tendon_diameter", lo=0.7)),
        tendon_moment_arm=draw(st.none() | _range("tendon_moment_arm", lo=4.0)),
        pin_radius=draw(st.just(2.0) | _range("pin_radius")),
        safety_factor=draw(st.just(1.5) | _range("safety_factor", hi=3.0)),
    )


def check_joint(p: JointParams) -> dict:
    """Build ``p`` and check it (independent of rjcad.check); returns the exact gap and the poses swept."""
    b = build(p)
    for solid_ in (b.solids.ground, b.solids.moving):
        assert occ.is_valid(solid_) and len(occ.solids(solid_)) == 1
    m = b.manifest.to_json()
    bodies = named_bodies(
        stl_bytes(list(b.meshes.values())), b.meshes, {e["name"]: e["volume_mm3"] for e in m["bodies"]}
    )
    assert set(bodies) == {"ground", "moving"} and m["clearance_mm"] == p.clearance
    gaps = check_gaps(bodies, p.clearance, [("ground", "moving")])
    # the whole range of motion, free (every ≤ 1°, finer where the link's end moves by more than the clearance)
    step = max(min(1.0 * DEG, p.clearance / (p.link_length + p.link_width)), 0.25 * DEG)
    poses = overlap_free_sweep(
        solid(bodies["ground"]), solid(bodies["moving"]), m["axis_point_mm"], m["axis_dir"], p.rotation, step
    )
    assert wound_strip_clearance(p, b.meshes, step_deg=15.0) >= p.gap_internal - 0.05, p
    s = m["spring"]
    assert m["spring_strip_volume_mm3"] == pytest.approx(
        p.springs * s["width_mm"] * s["thickness_mm"] * s["length_mm"], rel=0.02
    )
    return {"gap": gaps[("ground", "moving")], "poses": poses}


#: Designs the random test found broken, fixed since, run first on every run (JointParams keywords).
PINNED = [
    # a desktop joint whose moment arm puts the band near the cup: its stop lugs had a negative length (the
    # builder raised Standard_DomainError) and the hub's flare reached into the cup's wall; the cup now grows
    dict(rotation=30.9 * DEG, tendon_moment_arm=11.29),
    # a stacked pinned joint turned 105.5°: the moving block's corner (x_m, W/2) passed the ground block's face
    # and went 0.1 mm³ into it at the end of the range; x_m now keeps the corner above the block
    # (rjcad.design.layout_desktop.clear_of_ground_block)
    dict(
        printer="dimension-elite",
        layout="stacked",
        material="pa12",
        end="pinned",
        stiffness=1.0,
        rotation=1.840747969664904,
        preload=1.3768136876480255,
        clearance=0.30499351255144863,
        link_length=85.53082133598582,
        tendon_diameter=1.3446053215111347,
        tendon_moment_arm=13.89814806111029,
        pin_radius=2.0,
        safety_factor=1.9,
    ),
]

#: The designs the random test built in this run (JointParams), in order, and their keywords.
BUILT: list = []
BUILT_KW: list = []


def _pinned(test):
    for kw in reversed(PINNED):
        test = example(kw)(test)
    return test


@_pinned
@settings(
    max_examples=RANDOM_JOINTS,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    derandomize=True,
    phases=[Phase.explicit, Phase.generate],
)  # no shrinking: a build and its checks per step
@given(joint_designs())
def random_joint(kw):
    try:
        p = JointParams(**kw)
    except RjcadError:  # refused by validation: not a design, drawn again
        reject()
    check_joint(p)
    BUILT.append(p)
    BUILT_KW.append(kw)


def cover_missing(what: str, values) -> list:
    """Build and check one design for each of ``values`` (a material or a printer) that the random draws missed:
    the first drawn design that validation still accepts with it changed. The draws are derandomized, but their
    order depends on hypothesis's version, so the spread over every value is made certain here. Returns the
    values so built."""
    built = []
    for value in sorted(set(values) - {getattr(p, what) for p in BUILT}):
        for kw in BUILT_KW:
            kw = dict(kw, **{what: value})
            if what == "printer" and kw["clearance"] is not None:
                kw["clearance"] = max(kw["clearance"], PRINTERS[value].min_gap_mm)
            try:
                p = JointParams(**kw)
            except RjcadError:
                continue
            check_joint(p)
            BUILT.append(p)
            built.append(value)
            break
    return built


@pytest.mark.slow
def test_random_accepted_joints_build_checked_meshes(summary_line):
    BUILT.clear()
    BUILT_KW.clear()
    t0 = time.perf_counter()
    random_joint()
    n = len(BUILT) - len(PINNED)
    assert n >= RANDOM_JOINTS
    extra = cover_missing("material", MATERIALS) + cover_missing("printer", PRINTERS)
    dt = time.perf_counter() - t0
    spread = {
        what: collections.Counter(getattr(p, what) for p in BUILT[len(PINNED) :])
        for what in ("material", "printer", "layout", "end")
    }
    assert set(spread["material"]) == set(MATERIALS) and set(spread["printer"]) == set(PRINTERS)
    assert set(spread["layout"]) == set(LAYOUTS) and set(spread["end"]) == {"clamped", "pinned"}
    line = (
        f"built {n} random accepted joints (and {len(PINNED)} pinned, {len(extra)} to cover {extra}) in {dt:.0f} s, each checked watertight, outward, 2 bodies, gap >= "
        f"clearance - 0.02 mm, free over its range: "
        + "; ".join(", ".join(f"{k} {v}" for k, v in sorted(c.items())) for c in spread.values())
    )
    print(line)
    summary_line(line)


@pytest.mark.parametrize(
    "rotation_deg, preload_deg, clearance, end",
    [(110, 30, 0.25, "clamped"), (15, 120, 0.6, "clamped"), (110, 120, 0.6, "clamped"), (110, 30, 0.25, "pinned")],
)
def test_range_corners_build(rotation_deg, preload_deg, clearance, end):
    layout = "stacked" if end == "pinned" else None  # the desktop layout holds a clamped end only
    check_joint(
        JointParams(rotation=rotation_deg * DEG, preload=preload_deg * DEG, clearance=clearance, end=end, layout=layout)
    )


@pytest.mark.parametrize(
    "kw, param",
    [
        (dict(rotation=120 * DEG), "rotation"),
        (dict(preload=20 * DEG), "preload"),
        (dict(clearance=0.1), "clearance"),
        (dict(link_length=200.0), "link_length"),
        (dict(link_length=110.5), "link_length"),  # a 221 mm joint on a 220 mm bed (rjcad check's bed failed)
        (dict(link_length=102.0, printer="dimension-elite"), "link_length"),
        (dict(tendon_diameter=3.0), "tendon_diameter"),
        (dict(tendon_moment_arm=2.0), "tendon_moment_arm"),
        (dict(stiffness=float("nan")), "stiffness"),
    ],
)
def test_out_of_range_is_rejected(kw, param):
    with pytest.raises(ParameterError) as e:
        JointParams(**kw)
    assert e.value.parameter == param


@pytest.mark.parametrize(
    "kw",
    PINNED
    + [
        dict(tendon_moment_arm=15.0),
        dict(tendon_moment_arm=15.0, printer="dimension-elite", layout="desktop"),
        dict(stiffness=1.8, pin_radius=1.45, printer="dimension-elite", layout="desktop"),
        dict(stiffness=0.2),
    ],
)
def test_the_desktop_cup_holds_its_stop_lugs_and_clears_the_flare(kw):
    """The cup grows to hold a moment arm's wide band: each stop lug at least LUG_WIDTH long (the first pinned design
    had a negative one) and the hub's flare clear of the cup's wall by the clearance (it reached into it)."""
    from rjcad.design.layout_desktop import FACET_MARGIN, LUG_WIDTH

    L = JointParams(**kw).desktop
    x0, x1, y0 = L.lug_span
    assert x1 - x0 >= LUG_WIDTH - 1e-9 and y0 == L.w_arm + L.c
    assert L.R_ci - L.R_flare >= L.c + FACET_MARGIN - 1e-9
