"""rjcad urdf: the URDF of a finger or a joint, loaded by MuJoCo and by yourdfpy, against the manifest and the MJCF.

A synthetic finger of boxes (one axis tilted, analytic masses and inertias) runs in the fast lane; the default
finger and the default joint, built once per test process (tests/shared_builds.py), in the slow one.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import trimesh

mujoco = pytest.importorskip("mujoco")
yourdfpy = pytest.importorskip("yourdfpy")

from shared_builds import finger_build, joint_build  # noqa: E402

from rjcad.cli import main  # noqa: E402
from rjcad.io.manifest import BodyEntry, JointEntry, Manifest  # noqa: E402

#: The synthetic finger: body → box corners [mm]; joints (axis point [mm], direction); density [g/mm³]
BOXES = {
    "base": ((-30.0, -5.0, 0.0), (-2.0, 5.0, 10.0)),
    "link1": ((2.0, -5.0, 0.0), (40.0, 5.0, 12.0)),
    "link2": ((44.0, -4.0, 1.0), (80.0, 6.0, 10.0)),
    "distal": ((84.0, -5.0, 0.0), (110.0, 5.0, 8.0)),
}
AXES = [((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), ((42.0, 0.0, 0.0), (0.1, 0.2, 1.0)), ((82.0, 1.0, 2.0), (0.0, 0.0, 1.0))]
DENSITY = 1.04e-3
HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)


def run(*args) -> None:
    """``rjcad ARGS`` in this process; it must succeed."""
    with pytest.raises(SystemExit) as e:
        main([str(a) for a in args])
    assert e.value.code == 0


def boxes_manifest() -> Manifest:
    names = list(BOXES)
    bodies = []
    for name, (lo, hi) in BOXES.items():
        vol = float(np.prod(np.subtract(hi, lo)))
        bodies.append(BodyEntry(name, vol, vol * DENSITY, list(np.add(lo, hi) / 2)))
    joints = [
        JointEntry(
            parent=names[k],
            child=names[k + 1],
            axis_point_mm=list(p),
            axis_dir=list(d),
            joint_stiffness_nmm_per_rad=5.2 * (k + 1),
            preload_deg=90.0 - 10 * k,
            rotation_deg=80.0 + 5 * k,
            tendon_moment_arm_mm=6.0,
        )
        for k, (p, d) in enumerate(AXES)
    ]
    path = [[x, 6.0, 5.0] for x in (-30.0, -10.0, -1.0, 10.0, 30.0, 41.0, 50.0, 70.0, 81.0, 95.0, 108.0)]
    extra = {"tendon_path_mm": path, "frame": "synthetic: boxes along +X"}
    return Manifest("finger", joints, bodies, material="absplus-p430", extra=extra)


def write_inputs(d: Path, stem: str, man: Manifest, meshes: dict[str, trimesh.Trimesh]) -> Path:
    """``<stem>.json`` and ``<stem>_<body>.stl`` (mm) in ``d``, as `rjcad finger --mjcf` leaves them."""
    d.mkdir(parents=True, exist_ok=True)
    for name, mesh in meshes.items():
        mesh.export(d / f"{stem}_{name}.stl")
    (d / f"{stem}.json").write_text(json.dumps(man.to_json(), indent=2))
    return d / f"{stem}.json"


def exported(d: Path, stem: str, man: Manifest, meshes: dict[str, trimesh.Trimesh], mjcf: bool) -> dict:
    """The manifest, its MJCF (``mjcf``) and its URDF written by the CLI: paths and the manifest read back."""
    path = write_inputs(d, stem, man, meshes)
    if mjcf:
        run("mjcf", path, "--out", d / f"{stem}.xml", "--gravity", "off")
    run("urdf", path, "--out", d / "urdf")
    return {"man": Manifest.read(path), "urdf": d / "urdf" / f"{stem}.urdf", "xml": d / f"{stem}.xml" if mjcf else None}


@pytest.fixture(scope="module")
def boxes(tmp_path_factory) -> dict:
    meshes = {n: trimesh.creation.box(bounds=np.array(b)) for n, b in BOXES.items()}
    return exported(tmp_path_factory.mktemp("boxes"), "finger", boxes_manifest(), meshes, mjcf=True)


@pytest.fixture(scope="module")
def default_finger(tmp_path_factory) -> dict:
    from rjcad.io.templates import DEFAULT_FINGER

    b = finger_build(DEFAULT_FINGER)
    return exported(tmp_path_factory.mktemp("finger"), "finger", b.manifest, b.meshes, mjcf=True)


@pytest.fixture(scope="module")
def default_joint(tmp_path_factory) -> dict:
    from rjcad.design.params import JointParams

    b = joint_build(JointParams())
    return exported(tmp_path_factory.mktemp("joint"), "joint", b.manifest, b.meshes, mjcf=False)


def _mj(path: Path):
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return m, d


def _angle_deg(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    c = np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b))
    return math.degrees(math.acos(min(1.0, max(-1.0, c))))


def _unit(v) -> np.ndarray:
    return np.asarray(v, float) / np.linalg.norm(v)


def check_mujoco(e: dict) -> dict:
    """The URDF in MuJoCo against the manifest (and the MJCF when there is one); the errors measured."""
    man, (m, d) = e["man"], _mj(e["urdf"])
    n = len(man.joints)
    assert m.njnt == n and set(m.jnt_type.tolist()) == {HINGE}
    mass = {m.body(i).name: float(m.body_mass[i]) for i in range(m.nbody)}
    mass_err = max(abs(mass[b.name] / (b.mass_g * 1e-3) - 1) for b in man.bodies)
    axis_err = max(_angle_deg(d.xaxis[k], j.axis_dir) for k, j in enumerate(man.joints))
    assert mass_err < 0.01 and axis_err < 0.1
    np.testing.assert_allclose(d.xanchor, [np.multiply(j.axis_point_mm, 1e-3) for j in man.joints], atol=1e-9)
    np.testing.assert_allclose(m.jnt_range, [(0.0, math.radians(j.rotation_deg)) for j in man.joints], atol=1e-8)
    out = {"mass_err": mass_err, "axis_err_deg": axis_err}
    if e["xml"] is not None:
        mx, dx = _mj(e["xml"])
        assert mx.njnt == n and set(mx.jnt_type.tolist()) == {HINGE}
        # the MJCF mounts its base above a floor, turned by gravity: compare in the base's frame (the URDF's world)
        ib = mujoco.mj_name2id(mx, mujoco.mjtObj.mjOBJ_BODY, man.joints[0].parent)
        rot, at = dx.xmat[ib].reshape(3, 3), dx.xpos[ib]
        axes, anchors, coms = dx.xaxis @ rot, (dx.xanchor - at) @ rot, (dx.xipos - at) @ rot
        out["axis_vs_mjcf_deg"] = max(_angle_deg(a, b) for a, b in zip(d.xaxis, axes))
        assert out["axis_vs_mjcf_deg"] < 0.1
        np.testing.assert_array_equal(m.jnt_range, mx.jnt_range)
        np.testing.assert_allclose(d.xanchor, anchors, atol=1e-9)
        for i in range(1, mx.nbody):
            name = mx.body(i).name
            if name not in mass:  # a body of the MJCF's own (its mount)
                continue
            k = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
            assert mass[name] == pytest.approx(float(mx.body_mass[i]), rel=1e-6)
            np.testing.assert_allclose(d.xipos[k], coms[i], atol=1e-8)  # the centres of mass, at rest
            np.testing.assert_allclose(sorted(m.body_inertia[k]), sorted(mx.body_inertia[i]), rtol=1e-5)
    return out


def check_yourdfpy(e: dict) -> dict:
    """The URDF in yourdfpy against the manifest: joints, axes, limits, masses, and the frames at zero angles."""
    man = e["man"]
    u = yourdfpy.URDF.load(str(e["urdf"]))
    assert u.validate()
    joints = {j.name: j for j in u.robot.joints}
    links = {link.name: link for link in u.robot.links}
    base = u.base_link
    assert base == man.joints[0].parent and len(joints) == len(man.joints) and len(links) == len(man.bodies)
    axis_err = 0.0
    for k, mj in enumerate(man.joints):
        j = joints[f"joint{k + 1}"]
        assert (j.type, j.parent, j.child) == ("revolute", mj.parent, mj.child)
        world = u.get_transform(mj.child, base)  # at zero angles: the child's frame is the joint's
        np.testing.assert_allclose(world[:3, 3], np.multiply(mj.axis_point_mm, 1e-3), atol=1e-12)
        axis_err = max(axis_err, _angle_deg(world[:3, :3] @ j.axis, mj.axis_dir))
        assert (j.limit.lower, j.limit.upper) == (0.0, pytest.approx(math.radians(mj.rotation_deg), abs=1e-8))
        assert j.limit.effort > 0 and j.limit.velocity > 0
    mass_err = max(abs(links[b.name].inertial.mass / (b.mass_g * 1e-3) - 1) for b in man.bodies)
    assert axis_err < 0.1 and mass_err < 0.01
    return {"axis_err_deg": axis_err, "mass_err": mass_err}


def inertials(path: Path) -> dict[str, tuple[float, np.ndarray, np.ndarray]]:
    """Each link's (mass [kg], centre [m], inertia tensor [kg·m²]) as the URDF writes them (link frame)."""
    out = {}
    for link in ET.parse(path).getroot().iter("link"):
        i = link.find("inertial")
        assert i is not None
        t = {k: float(v) for k, v in i.find("inertia").attrib.items()}
        tensor = np.array(
            [[t["ixx"], t["ixy"], t["ixz"]], [t["ixy"], t["iyy"], t["iyz"]], [t["ixz"], t["iyz"], t["izz"]]]
        )
        com = np.array(i.find("origin").attrib["xyz"].split(), float)
        out[link.attrib["name"]] = (float(i.find("mass").attrib["value"]), com, tensor)
    return out


def check_inertia(e: dict) -> None:
    """Symmetric positive definite, the triangle inequality; the same as trimesh's of the written metre mesh."""
    man = e["man"]
    origins = {man.joints[0].parent: np.zeros(3)}
    origins.update({j.child: np.multiply(j.axis_point_mm, 1e-3) for j in man.joints})
    for name, (mass, com, tensor) in inertials(e["urdf"]).items():
        np.testing.assert_array_equal(tensor, tensor.T)
        p = np.linalg.eigvalsh(tensor)
        assert p.min() > 0 and p[0] + p[1] >= p[2] * (1 - 1e-9)
        mesh = trimesh.load(e["urdf"].parent / "meshes" / f"{name}.stl", force="mesh")
        mesh.density = mass / mesh.volume  # the mesh in metres, in the link frame, holding the link's mass
        np.testing.assert_allclose(com, mesh.center_mass, atol=1e-9)
        np.testing.assert_allclose(tensor, mesh.moment_inertia, atol=1e-6 * p.max())
        body = next(b for b in man.bodies if b.name == name)
        assert abs(mesh.volume * 1e9 / body.volume_mm3 - 1) < 0.01  # metres: the solid's volume at 1e-9
        np.testing.assert_allclose(com + origins[name], np.multiply(body.com_mm, 1e-3), atol=2e-5)


def test_boxes_load_in_mujoco_as_in_the_mjcf(boxes):
    err = check_mujoco(boxes)
    assert err["axis_err_deg"] < 1e-6 and err["mass_err"] < 1e-8


def test_boxes_load_in_yourdfpy(boxes):
    err = check_yourdfpy(boxes)
    assert err["axis_err_deg"] < 1e-6 and err["mass_err"] < 1e-8


def test_boxes_inertia_is_the_analytic_one(boxes):
    """m·(b² + c²)/12 about the box's centre, no products: independent of trimesh and of the export."""
    check_inertia(boxes)
    origins = {"base": np.zeros(3), **{n: np.multiply(p, 1e-3) for n, (p, _) in zip(list(BOXES)[1:], AXES)}}
    for name, (mass, com, tensor) in inertials(boxes["urdf"]).items():
        lo, hi = (np.multiply(c, 1e-3) for c in BOXES[name])
        a, b, c = hi - lo
        np.testing.assert_allclose(mass, float(np.prod(hi - lo)) * 1e9 * DENSITY * 1e-3, rtol=1e-9)
        np.testing.assert_allclose(com, (lo + hi) / 2 - origins[name], atol=1e-12)
        expected = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * mass / 12
        np.testing.assert_allclose(tensor, expected, rtol=1e-6, atol=1e-15)


def test_springs_and_tendon_are_written_as_comments(boxes):
    text = boxes["urdf"].read_text()
    assert "<!-- rjcad: the URDF of a finger of 3 joints" in text and "What URDF cannot hold" in text
    for k, j in enumerate(boxes["man"].joints):
        note = text.split(f"<!-- joint{k + 1}: ")[1].split("-->")[0]
        assert f"K = {j.joint_stiffness_nmm_per_rad:.4g} N·mm/rad" in note
        assert f"θ0 = {j.preload_deg:.4g}°" in note and "moment arm r = 6 mm" in note
    root = ET.fromstring(text)
    assert [c.tag for c in root.find("mujoco")] == ["compiler"]  # the one MuJoCo element
    limits = [j.find("limit").attrib for j in root.iter("joint")]
    for lim, j in zip(limits, boxes["man"].joints):  # effort: the spring's torque at full flexion
        full = math.radians(j.preload_deg + j.rotation_deg)
        assert float(lim["effort"]) == pytest.approx(j.joint_stiffness_nmm_per_rad * 1e-3 * full, rel=1e-8)


def test_a_rerun_replaces_the_meshes_whole_and_bad_names_are_refused(boxes, tmp_path, cli):
    man = boxes["man"].to_json()
    man["bodies"][3]["name"] = man["joints"][2]["child"] = "tip"
    src = boxes["urdf"].parent.parent
    meshes = {b["name"]: trimesh.load(src / f"finger_{b['name'].replace('tip', 'distal')}.stl") for b in man["bodies"]}
    write_inputs(tmp_path, "finger", Manifest.from_json(man), meshes)
    out = tmp_path / "urdf"
    (out / "meshes").mkdir(parents=True)
    (out / "meshes" / "distal.stl").write_bytes(b"an earlier run's")
    r = cli("urdf", tmp_path / "finger.json", "--out", out)
    assert r.code == 0 and "URDF written to" in r.out
    assert sorted(p.name for p in (out / "meshes").iterdir()) == ["base.stl", "link1.stl", "link2.stl", "tip.stl"]
    man["bodies"][3]["name"] = man["joints"][2]["child"] = "../tip"
    (tmp_path / "bad.json").write_text(json.dumps(man))
    before = sorted(p.name for p in tmp_path.rglob("*"))
    r = cli("urdf", tmp_path / "bad.json", "--out", out)
    assert r.code == 2 and r.err.count("\n") == 1
    assert r.err.startswith("rjcad: error: bad.json: bodies[4].name") and "Traceback" not in r.err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


@pytest.mark.parametrize(
    "damage,key",
    [
        (lambda d: d["joints"][1].pop("axis_dir"), "joints[2].axis_dir"),
        (lambda d: d["joints"][0].__setitem__("rotation_deg", "90"), "joints[1].rotation_deg"),
        (lambda d: d["joints"][2].__setitem__("child", "nobody"), "joints[3].child"),
        (lambda d: d.pop("bodies"), "bodies"),
    ],
)
def test_a_bad_manifest_is_one_line_naming_the_file_and_key(boxes, tmp_path, cli, damage, key):
    data = boxes["man"].to_json()
    damage(data)
    (tmp_path / "m.json").write_text(json.dumps(data))
    r = cli("urdf", tmp_path / "m.json", "--out", tmp_path / "o")
    assert r.code == 2 and r.err.count("\n") == 1 and f"m.json: {key}" in r.err
    assert not (tmp_path / "o").exists()


def test_missing_meshes_are_named(boxes, tmp_path, cli):
    (tmp_path / "m.json").write_text(json.dumps(boxes["man"].to_json()))
    r = cli("urdf", tmp_path / "m.json", "--out", tmp_path / "o")
    assert r.code == 2 and "m_base.stl: mesh file not found" in r.err and not (tmp_path / "o").exists()


def test_the_default_finger_loads_in_mujoco_and_yourdfpy_as_its_mjcf(default_finger):
    mj, yp = check_mujoco(default_finger), check_yourdfpy(default_finger)
    check_inertia(default_finger)
    print(f"\ndefault finger: MuJoCo {mj}; yourdfpy {yp}")


def test_the_default_joint_loads_in_mujoco_and_yourdfpy(default_joint):
    mj, yp = check_mujoco(default_joint), check_yourdfpy(default_joint)
    check_inertia(default_joint)
    assert "<!-- rjcad: the URDF of a joint" in default_joint["urdf"].read_text()
    print(f"\ndefault joint: MuJoCo {mj}; yourdfpy {yp}")
