"""A check's result, the report of all checks, and its table."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from rjcad.errors import BadInput as BadInput  # re-exported: the checks raise it for an unusable mesh


@dataclass
class CheckResult:
    """One check: ``passed`` is True, False, or None when skipped (``detail`` says why)."""

    name: str
    passed: bool | None
    value: Any = None
    limit: Any = None
    where: list[float] | None = None
    detail: str = ""


def skipped(name: str, why: str) -> CheckResult:
    """A check that did not run, and why (``why`` starts with "skipped: ")."""
    return CheckResult(name, None, None, None, None, why)


@dataclass
class Report:
    checks: list[CheckResult] = field(default_factory=list)
    body_names: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """True when no check failed (skipped checks do not fail, nor pass silently: they say so)."""
        return all(c.passed is not False for c in self.checks)

    def to_dict(self) -> dict:
        return {"passed": self.passed, "bodies": self.body_names, "checks": [asdict(c) for c in self.checks]}

    def get(self, name: str) -> CheckResult:
        return next(c for c in self.checks if c.name == name)


def point(x) -> list[float]:
    """A location for a report: the first three coordinates, rounded to 0.001 mm."""
    return [round(float(v), 3) for v in np.asarray(x).ravel()[:3]]


def format_table(rep: Report) -> str:
    """The report as a readable table."""
    rows = [("check", "result", "value", "limit", "where [mm]")]
    for c in rep.checks:
        res = "skipped" if c.passed is None else ("pass" if c.passed else "FAIL")
        rows.append(
            (
                c.name,
                res,
                "" if c.value is None else str(c.value),
                "" if c.limit is None else str(c.limit),
                "" if c.where is None else str(c.where),
            )
        )
    w = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = ["  ".join(r[i].ljust(w[i]) for i in range(5)).rstrip() for r in rows]
    lines.insert(1, "  ".join("-" * x for x in w))
    lines.append("")
    lines += [f"{c.name}: {c.detail}" for c in rep.checks if c.detail]
    lines.append("")
    lines.append("PASSED" if rep.passed else "FAILED")
    return "\n".join(lines)
