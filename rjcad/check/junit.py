"""The checks' reports as JUnit XML, the test-result file CI systems display (``rjcad check --junit``).

Layout: ``<testsuites>`` holds one ``<testsuite>`` per mesh file (named by its path as given), and each suite
one ``<testcase>`` per check, in the report's order (watertight … slicer). A failed check is a ``<failure>``
(message: its value, limit and where; text: its detail), a skipped one ``<skipped>`` with the reason, a passed
one keeps its value, limit and detail in ``<system-out>``.

Granularity: one case per check, never per body. A ``CheckResult`` is one verdict over all the bodies (one
value, limit and location): the checks look at each body but keep only the first broken one (watertight,
manifold) or the worst one (min_feature, overhang), named in the detail. Cases per body would claim verdicts
the report does not hold (a body after the first broken one, a body not the worst). So a case whose result
names one body says which in its name, ``min_feature (worst: link1)``; the checks between bodies or over the
whole mesh (bodies, clearance, motion, bed, slicer) keep the bare name.

Times: a suite's ``time`` is the whole check of its mesh. The report times no single check, so a case's
``time`` is 0, except the slicer's: the slicing and G-code reading its detail gives (in the background, while
the other checks ran).
"""

from __future__ import annotations

import re
import socket
from collections.abc import Sequence
from datetime import datetime
from typing import NamedTuple
from xml.etree import ElementTree as ET

from rjcad.check.report import CheckResult, Report

#: The testcases' classname prefix (the mesh file's name follows, dots made underscores: a CI system reads
#: dots in a classname as packages).
CLASSNAME = "rjcad.check"

#: Where a check's detail names the one body its result is about, by check (tried in order; ``re.match``).
_BODY = {
    "watertight": (re.compile(r"(.+?): (?:inside out \(|\d+ edges not shared)"),),
    "manifold": (re.compile(r"(.+?): manifold3d says "),),
    "min_feature": (
        re.compile(r"gap inside a body too narrow: .*?; narrowest gap inside a body \S+ mm in (.+?) \((?:vert|hori)"),
        re.compile(r"(?:wall too thin: )?thinnest wall \S+ mm in (.+?) \(min wall "),
    ),
    "overhang": (re.compile(r"worst: (.+?), (?:other body|air), "),),
}

#: The slicer's own times in its detail [s].
_SLICER_TIMES = re.compile(r"sliced in ([\d.]+) s.*?G-code read in ([\d.]+) s")

#: Characters XML 1.0 cannot hold (control characters, lone surrogates, U+FFFE/U+FFFF).
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


class Run(NamedTuple):
    """One mesh's checks: its path as given, the report, the wall time [s] and when they started."""

    mesh: str
    report: Report
    seconds: float
    started: datetime


def _text(value: object) -> str:
    """``value`` as text XML can hold (ElementTree escapes the rest: &, <, >, quotes, newlines in attributes)."""
    return _NOT_XML.sub("\ufffd", str(value))


def worst_body(check: CheckResult, bodies: Sequence[str]) -> str | None:
    """The one body a check's result names (one of ``bodies``), or None (a check over several, or skipped)."""
    if check.passed is None:
        return None
    for pattern in _BODY.get(check.name, ()):
        m = pattern.match(check.detail)
        if m and m.group(1) in bodies:
            return m.group(1)
    return None


def case_name(check: CheckResult, bodies: Sequence[str]) -> str:
    """A check's testcase name: the check, and the body its result names, if one."""
    body = worst_body(check, bodies)
    return check.name if body is None else f"{check.name} (worst: {body})"


def _seconds(check: CheckResult) -> float:
    m = _SLICER_TIMES.search(check.detail) if check.name == "slicer" and check.passed is not None else None
    return float(m.group(1)) + float(m.group(2)) if m else 0.0


def _summary(check: CheckResult) -> str:
    """A result's value, limit and where, on one line."""
    parts = [] if check.value is None else [f"value {check.value}"]
    parts += [] if check.limit is None else [f"limit {check.limit}"]
    parts += [] if check.where is None else [f"at {check.where} mm"]
    return ", ".join(parts)


def _case(suite: ET.Element, check: CheckResult, classname: str, bodies: Sequence[str]) -> None:
    attrs = {"classname": classname, "name": case_name(check, bodies), "time": f"{_seconds(check):.3f}"}
    case = ET.SubElement(suite, "testcase", {k: _text(v) for k, v in attrs.items()})
    summary = _summary(check)
    if check.passed is None:
        ET.SubElement(case, "skipped", message=_text(check.detail))
    elif check.passed is False:
        message = f"{check.name} failed" + (f": {summary}" if summary else "")
        ET.SubElement(case, "failure", message=_text(message), type=_text(check.name)).text = _text(check.detail)
    else:
        ET.SubElement(case, "system-out").text = _text("\n".join(x for x in (summary, check.detail) if x))


def _counts(reports: Sequence[Report]) -> dict[str, str]:
    checks = [c for r in reports for c in r.checks]
    return {
        "tests": str(len(checks)),
        "failures": str(sum(c.passed is False for c in checks)),
        "errors": "0",
        "skipped": str(sum(c.passed is None for c in checks)),
    }


def junit_xml(runs: Sequence[Run]) -> bytes:
    """The JUnit XML document of ``runs`` (UTF-8, with its declaration)."""
    root = ET.Element("testsuites", {"name": "rjcad check"})
    root.attrib.update(_counts([r.report for r in runs]))
    root.set("time", f"{sum(r.seconds for r in runs):.3f}")
    host = socket.gethostname()
    for run in runs:
        suite = ET.SubElement(root, "testsuite", {"name": _text(run.mesh), **_counts([run.report])})
        suite.attrib.update(
            time=f"{run.seconds:.3f}", timestamp=run.started.isoformat(timespec="seconds"), hostname=_text(host)
        )
        name = re.split(r"[\\/]", run.mesh)[-1].replace(".", "_")
        for check in run.report.checks:
            _case(suite, check, _text(f"{CLASSNAME}.{name}"), run.report.body_names)
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True) + b"\n"
