"""What `pytest -m 'not slow'` keeps: one real joint build, and the rules that mark the other CAD tests slow."""

import ast
import json
import textwrap

import conftest
import pytest
import trimesh


@pytest.mark.fast_lane
def test_one_real_joint_builds(tmp_path):
    """Fast lane on purpose: the one CAD build left in `-m 'not slow'` (about 4 s), so that the quick run
    still catches a broken CAD kernel, builder or exporter. The default joint, read back from its STL and its
    manifest: two watertight bodies of the manifest's volumes."""
    from rjcad.cad.build import write_joint
    from rjcad.design.params import JointParams

    write_joint(JointParams(), tmp_path, png=False)
    manifest = json.loads((tmp_path / "joint.json").read_text())
    mesh = trimesh.load(str(tmp_path / "joint.stl"), force="mesh", process=True)
    bodies = mesh.split(only_watertight=False)
    assert len(bodies) == 2
    assert all(b.is_watertight and b.is_winding_consistent and b.volume > 0 for b in bodies)
    want = sorted(b["volume_mm3"] for b in manifest["bodies"])
    assert sorted(b.volume for b in bodies) == pytest.approx(want, rel=0.005)
    assert {b["name"] for b in manifest["bodies"]} == {"ground", "moving"}


def reason(src: str):
    return conftest.own_slow_reason(ast.parse(textwrap.dedent(src)))


@pytest.mark.parametrize(
    "src, words",
    [
        ("b = build(JointParams())", "builds CAD"),
        ("jb.write_joint(p, d)", "builds CAD"),
        ("build_finger_model(fp)", "builds CAD"),
        ("r = subprocess.run(['x'])", "subprocess"),
        ("LocalCluster(n_workers=2)", "process pool"),
        ("sw.run_sweep(spec, d, build=True, workers=0)", "build=True"),
        ("x = shutil.which('prusa-slicer')", "PrusaSlicer"),
        ("main(['joint', '--out', str(out)])\nassert e.value.code == 0", "rjcad joint"),
        ("cli('finger', tpl)", "rjcad finger"),
        ("main(['sweep', f, '--build'])", "--build"),
    ],
)
def test_slow_things_are_recognised(src, words):
    assert words in reason(src)


@pytest.mark.parametrize(
    "src",
    [
        "main(['joint', *args])\nassert e.value.code == 2",  # a usage error stops before any CAD
        "r = cli_process('finger', bad)\nassert r.returncode == 2",
        "main(['spring', '--json'])",
        "sw.run_sweep(spec, d, build=False)",
        "run_checks(hinge(), slicer='prusa')",  # the slicer itself is not looked for here
        "builds(JointParams)",
    ],
)
def test_fast_things_are_not_marked(src):
    assert reason(src) is None


def test_real_tests_get_the_right_verdict():
    """Through helpers (check_joint), fixtures' bodies, and not for a slicer test that fakes the slicer."""
    import test_check
    import test_joint
    import test_joint_properties

    assert "builds CAD (build)" in conftest.function_slow_reason(test_joint.test_moment_arm_follows_the_parameter)
    assert "(in check_joint)" in conftest.function_slow_reason(test_joint_properties.test_range_corners_build)
    assert conftest.function_slow_reason(test_joint.test_bad_joint_input_exit_2_and_no_files) is None
    assert conftest.function_slow_reason(test_check.test_slicer_missing_is_skipped_never_passed) is None
    assert conftest.function_slow_reason(reason) is None
    assert conftest.function_slow_reason(test_one_real_joint_builds)  # slow by its code, kept by its mark


def test_measured_and_longest_lists_name_real_tests(root):
    """Every node id in conftest's MEASURED_SLOW and LONGEST names a test function that exists (a renamed test
    would silently drop out of the list)."""
    for key in [*conftest.MEASURED_SLOW, *conftest.LONGEST]:
        path, name = key.split("::")
        assert f"def {name.split('[')[0]}(" in (root / path).read_text(), key


def test_the_longest_tests_are_dealt_round_the_workers():
    """Worker k's first tests are the k-th, (k+n)-th, ... longest; every test once; the others in their order."""

    class Item:
        def __init__(self, nodeid):
            self.nodeid = nodeid

    longest = sorted(conftest.LONGEST, key=lambda k: -conftest.LONGEST[k])
    items = [Item(f"tests/test_a.py::test_{i}") for i in range(40)] + [Item(k) for k in reversed(longest)]
    dealt = conftest.deal_longest(items, 2)
    assert sorted(map(id, dealt)) == sorted(map(id, items))
    half = len(items) // 2
    assert [it.nodeid for it in dealt[: len(longest[0::2])]] == longest[0::2]
    assert [it.nodeid for it in dealt[half : half + len(longest[1::2])]] == longest[1::2]
    short = [it.nodeid for it in dealt if it.nodeid.startswith("tests/test_a.py")]
    assert short == [f"tests/test_a.py::test_{i}" for i in range(40)]
