"""`rjcad check --junit` and several meshes per run: the XML read back by junitparser (a JUnit parser from PyPI)."""

from __future__ import annotations

import json
import os
from datetime import datetime

import pytest
from junitparser import Failure, JUnitXml, Skipped
from test_check import write as write_pair
from test_check_mutations import delete_triangle, part, thin_wall
from test_check_mutations import write as write_part
from test_check_print import printable_pair

from rjcad.check import CheckResult, Report, run_checks
from rjcad.check.junit import Run, case_name, junit_xml

CHECKS = ["watertight", "manifold", "bodies", "clearance", "motion", "min_feature", "bed", "overhang", "slicer"]


def cases(suite) -> dict:
    """{check name: testcase} of a suite (the name before any " (worst: …)")."""
    return {c.name.split(" (")[0]: c for c in suite}


def kind(case) -> str:
    res = case.result
    if any(isinstance(r, Failure) for r in res):
        return "failure"
    return "skipped" if any(isinstance(r, Skipped) for r in res) else "passed"


def test_a_passing_mesh_reads_back_one_case_per_check(tmp_path, cli):
    path, man = write_pair(tmp_path, printable_pair(), joint=False)
    out = tmp_path / "ci" / "report.xml"
    code, table, err = cli("check", str(path), "--manifest", str(man), "--junit", str(out))
    assert code == 0 and err == "", err
    xml = JUnitXml.fromfile(str(out))
    (suite,) = list(xml)
    assert suite.name == str(path) and suite.tests == 9 and suite.failures == 0 and suite.errors == 0
    assert suite.skipped == 2 and suite.time > 0  # motion (no joint in the manifest), slicer (no --slicer)
    assert [c.name for c in suite] == [
        "watertight",
        "manifold",
        "bodies",
        "clearance",
        "motion",
        "min_feature (worst: bridge)",  # its thinnest wall
        "bed",
        "overhang",
        "slicer",
    ]
    by = cases(suite)
    assert {c.classname for c in suite} == {"rjcad.check.mesh_stl"}
    assert [n for n in CHECKS if kind(by[n]) == "skipped"] == ["motion", "slicer"]
    assert by["slicer"].result[0].message == "skipped: no --slicer given"
    assert "tightest pair" in by["clearance"].system_out or "no two bodies" in by["clearance"].system_out
    assert by["min_feature"].system_out.startswith("value ")
    # the table is the one printed without --junit
    assert cli("check", str(path), "--manifest", str(man)).out == table


def test_a_failing_mesh_is_written_with_its_failures(tmp_path, cli):
    bodies, _ = thin_wall(part())
    path = write_part(tmp_path, bodies, "3mf")
    out = tmp_path / "report.xml"
    code, _, _ = cli("check", str(path), "--bodies", "2", "--clearance", "0.25", "--junit", str(out))
    assert code == 1
    rep = run_checks(str(path), clearance=0.25, bodies=2)
    (suite,) = list(JUnitXml.fromfile(str(out)))
    assert suite.tests == 9 and suite.failures == 2 and suite.skipped == 2  # min_feature, overhang; motion, slicer
    by = cases(suite)
    assert by["min_feature"].name == "min_feature (worst: ground)"  # the 0.2 mm wall of the ground's comb
    assert by["overhang"].name == "overhang (worst: moving)"  # the tube starts 0.4 mm over the plate
    for name in ("min_feature", "overhang"):
        (fail,) = by[name].result
        c = rep.get(name)
        assert isinstance(fail, Failure) and fail.type == name and fail.text == c.detail
        assert fail.message == f"{name} failed: value {c.value}, limit {c.limit}, at {c.where} mm"
    assert by["clearance"].name == "clearance" and kind(by["clearance"]) == "passed"


def test_a_broken_body_names_it_and_skips_what_needs_it():
    bodies, _ = delete_triangle(part())
    rep = run_checks(bodies, clearance=0.25, bodies=2)
    xml = junit_xml([Run("part.stl", rep, 1.5, datetime(2026, 1, 2, 3, 4, 5))])
    suite = next(iter(JUnitXml.fromstring(xml)))
    by = cases(suite)
    assert by["watertight"].name == "watertight (worst: ground)" and by["manifold"].name == "manifold (worst: ground)"
    assert [n for n in CHECKS if kind(by[n]) == "skipped"] == ["clearance", "motion", "min_feature", "slicer"]
    assert by["clearance"].result[0].message == "skipped: needs watertight, manifold bodies"
    assert suite.time == 1.5 and suite.timestamp == "2026-01-02T03:04:05"


def test_odd_text_is_escaped_and_a_name_not_a_body_is_not_one():
    odd = "a<b>&\"c'\x01\ud800"
    rep = Report(
        [
            CheckResult("watertight", False, 3, 0, [1.0, 2.0, 3.0], f"{odd}: 3 edges not shared by exactly two faces"),
            CheckResult("manifold", False, "x", "NoError", None, "nobody: manifold3d says NotManifold"),
            CheckResult("slicer", True, 0, 0, None, f"fine ]]> {odd}; sliced in 2.5 s, G-code read in 0.5 s"),
        ],
        [odd, "b"],
    )
    xml = junit_xml([Run(f"dir/{odd}.stl", rep, 0.25, datetime(2026, 1, 1))])
    suite = next(iter(JUnitXml.fromstring(xml)))
    clean = "a<b>&\"c'\ufffd\ufffd"
    assert suite.name == f"dir/{clean}.stl" and suite.failures == 2
    by = {c.name: c for c in suite}
    assert set(by) == {f"watertight (worst: {clean})", "manifold", "slicer"}  # "nobody" is no body of the mesh
    assert by[f"watertight (worst: {clean})"].result[0].text.startswith(clean)
    assert by["slicer"].time == 3.0 and by["manifold"].time == 0.0
    assert case_name(CheckResult("overhang", None, 1.0, 0.0, None, "skipped: … worst: b, air, …"), ["b"]) == "overhang"


def test_several_meshes_one_suite_each_and_exit_1_if_any_fails(tmp_path, cli):
    good, _ = write_pair(tmp_path, printable_pair(), "good", joint=False)
    bad = write_part(tmp_path, thin_wall(part())[0], "stl")
    out = tmp_path / "report.xml"
    code, text, _ = cli("check", str(good), str(bad), "--bodies", "2", "--junit", str(out))
    assert code == 1
    assert text.startswith(f"{good}\ncheck ") and f"\n\n{bad}\ncheck " in text
    assert text.rstrip().endswith(f"FAILED: 1 of 2 meshes ({bad})")
    xml = JUnitXml.fromfile(str(out))
    assert [s.name for s in xml] == [str(good), str(bad)] and [s.failures for s in xml] == [0, 2]
    assert xml.tests == 18 and xml.failures == 2
    code, text, _ = cli("check", str(good), str(good), "--bodies", "2", "--json")
    d = json.loads(text)
    assert code == 0 and d["passed"] is True and [m["mesh"] for m in d["meshes"]] == [str(good)] * 2
    assert [c["name"] for c in d["meshes"][0]["checks"]] == CHECKS


def test_bad_input_writes_nothing_and_keeps_an_earlier_report(tmp_path, cli):
    good, man = write_pair(tmp_path, printable_pair(), "good", joint=False)
    out = tmp_path / "report.xml"
    out.write_text("earlier\n")
    before = out.stat().st_mtime_ns
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"\0" * 80 + (0).to_bytes(4, "little"))
    for args in (
        [str(good), str(empty)],  # the second mesh is unreadable
        [str(good), str(tmp_path / "nope.stl")],  # refused before the first is checked
        [str(good), str(good), "--manifest", str(man)],  # a manifest describes one mesh
    ):
        code, text, err = cli("check", *args, "--junit", str(out))
        assert code == 2 and text == "", (args, text)
        assert len(err.splitlines()) == 1 and err.startswith("rjcad: error: "), err
        assert out.read_text() == "earlier\n" and out.stat().st_mtime_ns == before
    assert cli("check", str(good), str(empty)).err.startswith(f"rjcad: error: {empty}: ")
    assert "--manifest" in cli("check", str(good), str(good), "--manifest", str(man)).err
    mesh = good.read_bytes()
    code, _, err = cli("check", str(good), "--junit", str(good))  # the report would replace a mesh
    assert code == 2 and "--junit" in err and good.read_bytes() == mesh
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".")]  # no temporary file left


def test_the_report_is_never_written_through_a_symlink_nor_replaces_it(tmp_path, cli):
    good, man = write_pair(tmp_path, printable_pair(), "good", joint=False)
    target = tmp_path / "elsewhere.xml"
    target.write_text("not mine\n")
    link = tmp_path / "report.xml"
    link.symlink_to(target)
    code, _, err = cli("check", str(good), "--manifest", str(man), "--junit", str(link))
    assert code == 2 and "report.xml" in err and "symbolic link" in err and len(err.splitlines()) == 1
    assert link.is_symlink() and target.read_text() == "not mine\n"  # issue #38: refused, both as they were


def test_an_unwritable_report_is_refused_before_checking(tmp_path, cli, monkeypatch):
    import rjcad.check as chk

    good, _ = write_pair(tmp_path, printable_pair(), "good", joint=False)
    monkeypatch.setattr(chk, "run_checks", lambda *a, **k: pytest.fail("checked before refusing"))
    (tmp_path / "afile").write_text("x")
    code, _, err = cli("check", str(good), "--junit", str(tmp_path / "afile" / "report.xml"))
    assert code == 2 and "not a directory" in err and len(err.splitlines()) == 1
    code, _, err = cli("check", str(good), "--junit", str(tmp_path))  # a directory: a forgotten file name
    assert code == 2 and "is a directory" in err and len(err.splitlines()) == 1
