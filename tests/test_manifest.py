"""rjcad.io.manifest: the one manifest type. Version-0 files (written by rjcad before it, kept in tests/data)
load; what the builders write round-trips; a bad manifest is one error line naming the key."""

import copy
import json
import math
from pathlib import Path

import pytest

from rjcad.errors import ParameterError
from rjcad.io.manifest import SCHEMA_VERSION, BodyEntry, JointEntry, Manifest, ManifestError

DATA = Path(__file__).parent / "data"


def v0(kind):
    """Text of the version-0 manifest that `rjcad joint` / `rjcad finger templates/finger.toml` wrote."""
    return (DATA / f"manifest_v0_{kind}.json").read_text()


def without_additions(d: dict) -> dict:
    """A version-1 manifest minus what version 1 added: schema_version, and a joint's `joints`."""
    d = dict(d)
    assert next(iter(d)) == "schema_version" and d.pop("schema_version") == SCHEMA_VERSION
    if "moving_body" in d:
        assert list(d)[-1] == "joints"
        d.pop("joints")
    return d


@pytest.mark.parametrize("kind", ["joint", "finger"])
def test_version_0_loads_and_writes_the_same_keys_values_and_order(kind):
    text = v0(kind)
    m = Manifest.from_json(json.loads(text))
    assert m.kind == kind and m.read_version == 0
    assert json.dumps(without_additions(m.to_json()), indent=2) + "\n" == text
    assert Manifest.from_json(m.to_json()) == m


def test_a_joint_is_a_finger_with_one_joint():
    flat = json.loads(v0("joint"))
    m = Manifest.from_json(flat)
    (j,) = m.joints
    assert (j.parent, j.child) == ("ground", "moving")
    assert j.axis_point_mm == flat["axis_point_mm"] and j.axis_dir == flat["axis_dir"]
    assert j.rotation_deg == flat["rotation_deg"] and j.preload_deg == flat["preload_deg"]
    assert j.joint_stiffness_nmm_per_rad == flat["joint_stiffness_nmm_per_rad"]
    assert j.requested_stiffness_nmm_per_rad == flat["stiffness_nmm_per_rad"]
    assert j.tendon_moment_arm_mm == flat["tendon_moment_arm_mm"] and j.spring == flat["spring"]
    assert [b.name for b in m.bodies] == ["ground", "moving"] and m.clearance_mm == flat["clearance_mm"]
    # version 1: the entry carries the finger entry's keys that a joint knows, after the flat keys
    out = m.to_json()
    assert list(out)[-1] == "joints" and out["joints"][0]["child"] == out["moving_body"] == "moving"
    finger_entry = json.loads(v0("finger"))["joints"][0]
    assert set(out["joints"][0]) <= set(finger_entry)
    # the extra keys round-trip untouched
    assert out["frame"] == flat["frame"] and out["print"] == flat["print"] and out["gaps_mm"] == flat["gaps_mm"]


def test_finger_entries_are_typed_and_the_json_view_reads_keys():
    m = Manifest.from_json(json.loads(v0("finger")))
    assert [(j.parent, j.child) for j in m.joints] == [("base", "link1"), ("link1", "link2"), ("link2", "distal")]
    assert all(isinstance(j, JointEntry) for j in m.joints) and all(isinstance(b, BodyEntry) for b in m.bodies)
    assert m["joints"][1]["tendon_moment_arm_mm"] == m.joints[1].tendon_moment_arm_mm
    assert "tendon_path_mm" in m and m.get("nope", 3) == 3


def test_readers_take_the_typed_object_or_its_json():
    from rjcad.check.motion import motion_joints
    from rjcad.physics.finger import model_from_manifest

    d = json.loads(v0("finger"))
    assert model_from_manifest(Manifest.from_json(d), mu_t=0.1) == model_from_manifest(d, mu_t=0.1)
    joint = model_from_manifest(json.loads(v0("joint")))
    assert joint.n == 1 and joint.rotation == pytest.approx((math.pi / 2,))
    assert [j.child for j in motion_joints(Manifest.from_json(d))] == ["link1", "link2", "distal"]


def bad(edit, base="finger"):
    d = json.loads(v0(base))
    edit(d)
    return d


@pytest.mark.parametrize(
    "data, key",
    [
        (bad(lambda d: d.update(schema_version=2)), "schema_version"),
        (bad(lambda d: d.update(schema_version="1")), "schema_version"),
        (bad(lambda d: (d.update(schema_version=1), d.pop("joints"))), "joints"),
        (bad(lambda d: d.update(joints={"a": 1})), "joints"),
        (bad(lambda d: d["joints"].__setitem__(1, "link")), "joints[2]"),
        (bad(lambda d: d["joints"][1].update(axis_dir="up")), "joints[2].axis_dir"),
        (bad(lambda d: d["joints"][2].update(axis_point_mm=[0, 0])), "joints[3].axis_point_mm"),
        (bad(lambda d: d["joints"][0].update(rotation_deg=True)), "joints[1].rotation_deg"),
        (bad(lambda d: d["joints"][0].update(parent=3)), "joints[1].parent"),
        (bad(lambda d: d["bodies"][1].pop("name")), "bodies[2].name"),
        (bad(lambda d: d.update(bodies="base")), "bodies"),
        (bad(lambda d: d.update(clearance_mm="0.25")), "clearance_mm"),
        (bad(lambda d: d.update(rotation_deg="90"), "joint"), "rotation_deg"),
        (bad(lambda d: d.update(schema_version=1, joints=[{}, {}]), "joint"), "joints"),
        (
            bad(
                lambda d: d.update(
                    Manifest.from_json(copy.deepcopy(d)).to_json(),
                    joints=[{**Manifest.from_json(copy.deepcopy(d)).to_json()["joints"][0], "rotation_deg": 80.0}],
                ),
                "joint",
            ),
            "rotation_deg",
        ),  # a version-1 joint's flat keys disagree with its entry
        ([1, 2], "manifest"),
    ],
)
def test_a_bad_manifest_is_one_line_naming_the_key(data, key):
    with pytest.raises(ParameterError) as e:
        Manifest.from_json(data)
    assert e.value.parameter == key
    msg = str(e.value)
    assert "\n" not in msg and key in msg
    if isinstance(e.value, ManifestError):
        assert msg.startswith(f"manifest: {key} ")


def test_missing_keys_are_named_by_the_reader_that_needs_them():
    from rjcad.check.motion import motion_joints
    from rjcad.physics.finger import model_from_manifest

    d = json.loads(v0("finger"))
    del d["joints"][1]["axis_dir"]
    with pytest.raises(ManifestError, match=r"^manifest: joints\[2\]\.axis_dir is required for the motion check$"):
        motion_joints(Manifest.from_json(d))
    flat = json.loads(v0("joint"))
    del flat["tendon_moment_arm_mm"]  # a version-0 joint: errors name the flat key, as before
    with pytest.raises(ParameterError) as e:
        model_from_manifest(flat)
    assert e.value.parameter == "tendon_moment_arm_mm"
    # a flat manifest without moving_body has no joint to sweep (as before the manifest type)
    assert motion_joints(Manifest.from_json({"bodies": [{"name": "a", "volume_mm3": 1.0}]})) == []


def test_keys_unknown_to_the_schema_round_trip():
    d = json.loads(v0("finger"))
    d["joints"][0]["note"] = "hand-made"
    d["bodies"][0]["colour"] = "red"
    d["operator"] = {"name": "A. Maker"}
    out = Manifest.from_json(copy.deepcopy(d)).to_json()
    assert out["joints"][0]["note"] == "hand-made" and out["bodies"][0]["colour"] == "red"
    assert list(out)[-1] == "operator" and without_additions(out) == d


@pytest.mark.slow
def test_the_builders_write_version_1_and_it_round_trips():
    from rjcad.cad.build import build, build_finger_model, render_files
    from rjcad.design.finger_params import FingerParams
    from rjcad.design.params import JointParams

    b = build(JointParams(end="pinned", layout="stacked"))  # the end version 0's default joint had
    text = render_files(b, png=False)["joint.json"]
    d = json.loads(text)
    assert Manifest.from_json(d) == b.manifest and json.dumps(b.manifest.to_json(), indent=2) + "\n" == text
    # what version 0 held: the same keys in the same order; the same values but for what the geometry of
    # the springs' ends (issue #14: clockwise spiral, key and socket) changed: bodies, the fork block's
    # place (wrap angle, frame), the mesh, the strip volume, the assembly text and the measured gap
    old = json.loads(v0("joint"))
    new = without_additions(d)
    assert list(new) == list(old)
    assert d["measured_min_gap_mm"] == pytest.approx(old["measured_min_gap_mm"], abs=1e-4)
    geometry = (
        "bodies",
        "tendon_wrap_angle_rad",
        "spring_strip_volume_mm3",
        "frame",
        "mesh",
        "print",
        "measured_min_gap_mm",
        "spring",
        "joint_stiffness_nmm_per_rad",
    )  # #14: the spring is designed on the rod model
    assert {k: v for k, v in new.items() if k not in geometry} == {k: v for k, v in old.items() if k not in geometry}
    fb = build_finger_model(FingerParams.from_dict({"joint": [{"stiffness_nmm_per_rad": 5.2}]}))
    assert Manifest.from_json(fb.manifest.to_json()) == fb.manifest and len(fb.manifest.joints) == 1
