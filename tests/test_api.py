"""The Python API (rjcad.api, docs/api.md): its names, keywords and errors are the CLI's, `import rjcad` stays
light, and what it builds and writes is what `rjcad joint`, `rjcad finger`, `rjcad check` and `rjcad simulate
finger` make."""

from __future__ import annotations

import ast
import importlib.util
import inspect
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rjcad
from rjcad import DEG, MissingExtra, ParameterError, RjcadError
from rjcad.fields import JOINT_FIELDS, SPRING_FIELDS

HEAVY = ("OCP", "trimesh", "scipy", "numba", "cadquery")
API_NAMES = [
    "CheckReport",
    "CheckResult",
    "Closure",
    "Finger",
    "Joint",
    "Spring",
    "build_finger",
    "build_joint",
    "design_spring",
    "finger_params",
    "joint_params",
]

IMPORTED = """
import json, sys
import rjcad
first = sorted(m for m in sys.modules if m.split(".")[0] in {heavy} or m == "rjcad.api")
rjcad.build_joint, rjcad.Finger  # the API module, loaded on first use: still no CAD kernel nor meshes
second = sorted(m for m in sys.modules if m.split(".")[0] in {heavy})
print(json.dumps([first, second]))
"""


@pytest.mark.fast_lane
def test_import_rjcad_loads_no_heavy_module(root):
    """Fast lane on purpose (one short process, about 0.2 s): `import rjcad` is the API's import budget (0.3 s;
    about 6 ms measured), kept by loading no CAD kernel, mesh library, SciPy or numba, nor the API itself."""
    code = IMPORTED.format(heavy=repr(set(HEAVY)))
    run = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    first, second = json.loads(run.stdout)
    assert first == [] and second == [], (first, second)


def test_the_api_names_are_public_and_load_on_first_use():
    for name in API_NAMES:
        assert name in rjcad.__all__ and name in dir(rjcad)
        assert getattr(rjcad, name) is not None
    assert rjcad.build_joint is rjcad.api.build_joint and rjcad.CheckReport.__name__ == "Report"
    with pytest.raises(AttributeError, match="no attribute 'build_jiont'"):
        rjcad.build_jiont  # noqa: B018
    assert issubclass(MissingExtra, ImportError) and issubclass(MissingExtra, RjcadError)


def test_the_type_stub_names_what_the_package_exports(root):
    """rjcad/__init__.pyi (what type checkers read) and rjcad/__init__.py export the same names."""
    tree = ast.parse((root / "rjcad" / "__init__.pyi").read_text())
    stub_all = next(
        ast.literal_eval(n.value)
        for n in tree.body
        if isinstance(n, ast.Assign) and any(getattr(t, "id", "") == "__all__" for t in n.targets)
    )
    assert sorted(stub_all) == sorted(rjcad.__all__)


def keywords(fn) -> list[str]:
    params = inspect.signature(fn).parameters.values()
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params), fn
    return [p.name for p in params]


def test_keywords_are_the_cli_options_toml_keys():
    joint = [f.keyword for f in JOINT_FIELDS] + ["config"]
    assert keywords(rjcad.joint_params) == joint and keywords(rjcad.build_joint) == joint
    assert keywords(rjcad.design_spring) == [f.keyword for f in SPRING_FIELDS] + ["config"]
    for f in JOINT_FIELDS + SPRING_FIELDS:
        assert f.keyword == ("stiffness" if f.name == "stiffness" else f.toml)
        assert f.keyword.endswith("_deg") == f.degrees


def test_defaults_are_rjcad_joints_and_degrees_become_radians():
    from rjcad.design.params import JointParams

    assert rjcad.joint_params() == JointParams()
    p = rjcad.joint_params(rotation_deg=80, preload_deg=100, clearance_mm=0.45, link_length_mm=42)
    assert p.rotation == pytest.approx(80 * DEG) and p.preload == pytest.approx(100 * DEG)
    assert (p.clearance, p.link_length) == (0.45, 42.0)
    assert rjcad.joint_params(printer="dimension-elite").layout == "stacked"  # strings passed on unchanged


@pytest.mark.parametrize(
    "kw, argv, named",
    [
        (dict(stiffness=-1.0), ["--stiffness", "-1"], "stiffness"),
        (dict(rotation_deg=5), ["--rotation", "5"], "rotation"),
        (dict(preload_deg=200), ["--preload", "200"], "preload"),
        (dict(material="unobtainium"), ["--material", "unobtainium"], "material"),
        (dict(clearance_mm=0.05), ["--clearance", "0.05"], "clearance"),
        (dict(layout="sideways"), ["--layout", "sideways"], "layout"),
        (dict(end="pinned"), ["--end", "pinned"], "end"),
    ],
)
def test_a_bad_value_is_the_error_rjcad_joint_prints(cli, tmp_path, kw, argv, named):
    with pytest.raises(ParameterError) as e:
        rjcad.joint_params(**kw)
    assert e.value.parameter == named
    r = cli("joint", *argv, "--out", str(tmp_path / "j"))
    assert r.code == 2 and r.err == f"rjcad: error: {e.value}\n"


@pytest.mark.parametrize(
    "kw, named",
    [
        (dict(stiffness="5.2"), "stiffness"),
        (dict(stiffness=True), "stiffness"),
        (dict(rotation_deg=[90]), "rotation_deg"),
        (dict(link_length_mm=10**400), "link_length_mm"),
        (dict(material=3), "material"),
    ],
)
def test_a_value_of_the_wrong_type_names_its_keyword(kw, named):
    with pytest.raises(ParameterError, match=f"^{named} = .* is invalid: must be a ") as e:
        rjcad.joint_params(**kw)
    assert e.value.parameter == named


def test_numpy_numbers_are_numbers():
    assert rjcad.joint_params(stiffness=np.float64(5.2), rotation_deg=np.int64(90)) == rjcad.joint_params()


def test_config_is_rjcad_joints_config_and_keywords_win(tmp_path):
    toml = tmp_path / "j.toml"
    toml.write_text("stiffness_nmm_per_rad = 4.0\nrotation_deg = 60\n")
    p = rjcad.joint_params(config=toml, rotation_deg=70)
    assert p.stiffness == 4.0 and p.rotation == pytest.approx(70 * DEG)
    toml.write_text("rotation = 60\n")
    with pytest.raises(ParameterError, match=r"^j\.toml: rotation = 60 is invalid: unknown key"):
        rjcad.joint_params(config=toml)


def test_design_spring_is_rjcad_spring(cli):
    kw = dict(stiffness=8.0, rotation_deg=60, preload_deg=45, material="petg", printer="generic-0.4")
    spring = rjcad.design_spring(**kw)
    r = cli("spring", "--stiffness", "8", "--rotation", "60", "--preload", "45", "--material", "petg", "--json")
    assert r.code == 0 and spring.manifest == json.loads(r.out)
    assert spring.design.width == spring.manifest["width_mm"] and "Spring(b=" in repr(spring)
    with pytest.raises(ParameterError, match=r"^stiffness = None is invalid: is required"):
        rjcad.design_spring(rotation_deg=90)
    with pytest.raises(ParameterError, match=r"^springs = 2 is invalid: must be an integer"):
        rjcad.design_spring(stiffness=5.2, springs=2.0)


def test_a_finger_template_is_a_file_or_a_dict_and_errors_are_rjcad_fingers(cli, root, tmp_path):
    import tomllib

    data = tomllib.loads((root / "templates" / "finger.toml").read_text())
    from_file = rjcad.finger_params(root / "templates" / "finger.toml")
    assert rjcad.finger_params(data).joints == from_file.joints == rjcad.finger_params().joints
    assert rjcad.finger_params(printer="dimension-elite", material="pla").joints[0].layout == "stacked"
    data["joint"][1]["stiffness_nmm_per_rad"] = -2.0
    with pytest.raises(ParameterError, match=r"^joint\[2\]\.stiffness_nmm_per_rad = -2 N·mm/rad is invalid"):
        rjcad.finger_params(data)
    bad = tmp_path / "bad.toml"
    bad.write_text("wheels = 4\n" + (root / "templates" / "finger.toml").read_text())
    with pytest.raises(ParameterError) as e:
        rjcad.finger_params(bad)
    assert e.value.parameter == "bad.toml: wheels"
    r = cli("finger", str(bad), "--out", str(tmp_path / "f"))
    assert r.code == 2 and r.err == f"rjcad: error: {e.value}\n"


def test_the_simulation_limits_are_rjcad_simulate_fingers():
    from rjcad.api import MAX_MU_T, MAX_STROKE_MM, STEPS
    from rjcad.cli import simulate

    assert (MAX_STROKE_MM, MAX_MU_T) == (simulate.MAX_STROKE_MM, simulate.MAX_MU_T)
    steps = next(p for p in simulate.simulate_finger.params if p.name == "steps").type
    assert STEPS == (steps.min, steps.max)


# ---------------------------------------------------------------- built (slow: each builds CAD)


def output_digest(root: Path):
    """tools/output_digest.py: which outputs are deterministic, and how the others are compared."""
    spec = importlib.util.spec_from_file_location("output_digest", root / "tools" / "output_digest.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def joint():
    """The default joint, built by the API (shared by this module's tests: read it, never change it)."""
    return rjcad.build_joint()


def test_build_joint_writes_the_files_of_rjcad_joint(joint, cli, root, tmp_path):
    written = joint.write(tmp_path / "api")
    r = cli("joint", "--out", str(tmp_path / "cli"))
    assert r.code == 0, r.err
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert sorted(p.name for p in written) == sorted(p.name for p in (tmp_path / "api").iterdir()) == names
    assert len(names) == 6
    od = output_digest(root)
    for name in names:
        a, b = ((tmp_path / d / name).read_bytes() for d in ("api", "cli"))
        if name.endswith((".json", ".glb")):  # byte for byte
            assert a == b, name
        else:  # STL, 3MF, STEP, PNG: as tools/output_digest.py compares them
            assert od.digest(a, name) == od.digest(b, name), name
    assert joint.manifest == json.loads((tmp_path / "api" / "joint.json").read_text())


def test_a_joint_shows_its_manifest_meshes_solids_and_spring(joint):
    from OCP.TopoDS import TopoDS_Shape

    m = joint.manifest
    names = [b["name"] for b in m["bodies"]]
    assert names == list(joint.meshes) == list(joint.solids) == ["ground", "moving"]
    assert all(isinstance(s, TopoDS_Shape) for s in joint.solids.values())
    for b in m["bodies"]:
        assert joint.meshes[b["name"]].volume == pytest.approx(b["volume_mm3"], rel=0.005)
    assert joint.spring.manifest == m["spring"] and joint.params == rjcad.joint_params()
    m["bodies"].clear()  # a copy
    assert joint.manifest["bodies"] and "5.19" in repr(joint)


def test_cq_solids_are_cadquery_shapes_or_a_clear_error(joint, monkeypatch):
    if importlib.util.find_spec("cadquery") is not None:
        shapes = joint.cq_solids()
        assert list(shapes) == ["ground", "moving"]
        vol = joint.manifest["bodies"][0]["volume_mm3"]
        assert shapes["ground"].Volume() == pytest.approx(vol, rel=1e-6)
    monkeypatch.setitem(sys.modules, "cadquery", None)  # as if not installed
    with pytest.raises(
        MissingExtra, match=r"needs CadQuery, which is not installed: pip install 'rjcad\[cadquery\]'"
    ) as e:
        joint.cq_solids()
    assert isinstance(e.value, ImportError) and isinstance(e.value, RjcadError)


def test_a_joint_check_is_rjcad_checks_report(joint, cli, tmp_path):
    report = joint.check()
    assert isinstance(report, rjcad.CheckReport) and report.passed
    assert all(isinstance(c, rjcad.CheckResult) for c in report.checks)
    joint.write(tmp_path, png=False)
    r = cli("check", str(tmp_path / "joint.3mf"), "--manifest", str(tmp_path / "joint.json"), "--json")
    want = json.loads(r.out)
    assert r.code == 0 and want["bodies"] == report.body_names == ["ground", "moving"]
    assert [(c["name"], c["passed"], c["limit"]) for c in want["checks"]] == [
        (c.name, c.passed, c.limit) for c in report.checks
    ]
    with pytest.raises(ParameterError, match=r"^slicer = 'cura'"):
        joint.check(slicer="cura")


#: ``my.toml`` of the example: a printer profile of one's own (docs/profiles.md).
MY_PRINTER = """\
name = "My printer, 0.4 mm nozzle"
nozzle_mm = 0.4
layer_mm = 0.2
bed_mm = [250.0, 210.0, 220.0]
soluble_support = false
"""


def test_the_issues_example_runs_as_written(cli, root, tmp_path, monkeypatch, capsys):
    """The issue's example, exactly, in a fresh folder holding templates/ and my.toml (a printer profile)."""
    shutil.copytree(root / "templates", tmp_path / "templates")
    (tmp_path / "my.toml").write_text(MY_PRINTER)
    monkeypatch.chdir(tmp_path)

    spring = rjcad.design_spring(stiffness=5.2, rotation_deg=90, preload_deg=90, material="petg", printer="my.toml")
    joint = rjcad.build_joint(stiffness=5.2, rotation_deg=90, preload_deg=90, printer="my.toml")
    joint.write("out/joint")  # the same files as `rjcad joint --out out/joint`
    finger = rjcad.build_finger("templates/finger.toml")  # or a dict of the same keys
    finger.write("out/finger")
    report = finger.check()  # a CheckReport: .passed, .checks
    closure = finger.simulate(stroke_mm=25)  # arrays: tendon_mm, theta_deg, tension_n

    assert capsys.readouterr().out == ""  # the API prints nothing
    assert spring.manifest["material"] == "petg" and spring.manifest["printer"] == joint.manifest["printer"] == "my"
    assert joint.manifest["printer_profile"]["file"] == str(tmp_path / "my.toml")  # in the manifest, as the CLI's
    assert sorted(p.name for p in Path("out/joint").iterdir()) == [
        f"joint.{e}" for e in ("3mf", "glb", "json", "png", "step", "stl")
    ]
    assert finger.manifest == json.loads(Path("out/finger/finger.json").read_text())
    written = {p.name for p in finger.write("out/finger", png=False, html=True)}  # as `rjcad finger --no-png --html`
    assert written == {f"finger.{e}" for e in ("stl", "3mf", "step", "glb", "json", "html")}
    assert {p.name for p in Path("out/finger").iterdir()} == written  # the earlier run's finger.png removed
    assert list(finger.solids) == list(finger.meshes) == ["base", "link1", "link2", "distal"]
    assert isinstance(report, rjcad.CheckReport) and report.passed and report.checks
    # the closure is `rjcad simulate finger out/finger/finger.json --stroke 25 --json`'s
    r = cli("simulate", "finger", "out/finger/finger.json", "--stroke", "25", "--json")
    want = json.loads(r.out)
    assert closure.theta_deg.shape == (1001, 3) and closure.tension_n.shape == closure.tendon_mm.shape == (1001,)
    np.testing.assert_allclose(closure.tendon_mm, want["tendon_mm"], rtol=0, atol=0)
    np.testing.assert_allclose(closure.theta_deg, np.array(want["theta_deg"]).T, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(closure.tension_n, want["tension_n"], rtol=1e-12, atol=1e-12)
    assert closure.phase[0] == "pull" and closure.phase[-1] == "release"
    assert math.isclose(closure.tendon_mm.max(), 25.0)
    # each joint's friction from its bearing: `rjcad simulate finger … --friction bearing --mu 0.3`'s closure
    rough = finger.simulate(stroke_mm=25, steps=100, bearing_mu=0.3)
    r = cli("simulate", "finger", "out/finger/finger.json", "--stroke", "25", "--steps", "100", "--friction",
            "bearing", "--mu", "0.3", "--json")  # fmt: skip
    np.testing.assert_allclose(rough.theta_deg, np.array(json.loads(r.out)["theta_deg"]).T, rtol=1e-12, atol=1e-12)
    assert rough.tension_n.max() > 2 * closure.tension_n.max()
    with pytest.raises(ParameterError, match=r"^bearing_mu = 0.5 is invalid: too high for this finger: joint 1"):
        finger.simulate(bearing_mu=0.5)
    with pytest.raises(ParameterError, match=r"^stroke_mm = 0 mm is invalid"):
        finger.simulate(stroke_mm=0)
    with pytest.raises(ParameterError, match=r"^steps = 5 is invalid"):
        finger.simulate(steps=5)
