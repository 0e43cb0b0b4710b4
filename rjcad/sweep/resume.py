"""``--resume``: the rows an earlier run left (results.csv, then the log of an interrupted build-mode run).

Every intact row is kept once; everything else is dropped, counted, and its design computed again.
A row is intact when its line is whole (ends with its line break: the writer always ends one), it has
every column of the header, a 12-hex-digit id, a known status, ``feasible`` True/False and numbers where
the inputs are numbers. A repeated id keeps its first intact row. A file that is not a results.csv of
``rjcad sweep`` (no header with the id, status and input columns; UTF-16 text) is refused in one line:
resuming from it would overwrite it.
"""

from __future__ import annotations

import csv
import io
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from rjcad.errors import RjcadError
from rjcad.io.untrusted import parse_json_lines, read_bytes, regular_or_absent
from rjcad.sweep.spec import INPUTS

STATUSES = ("ok", "check_failed", "infeasible", "failed")
_ID = re.compile(r"[0-9a-f]{12}\Z")
#: Lines a quoted field (an error message with a line break) may span; a stray quote spoils no more.
_MAX_SPAN = 20
CUT, DAMAGED, NOT_A_ROW, REPEATED = (
    "cut short at the end of the file",
    "with unreadable bytes (NUL, not UTF-8)",
    "not a complete row",
    "repeating a design already read",
)


@dataclass
class Earlier:
    """An earlier run's intact rows (first of each id, file order) and how many lines were dropped, by reason."""

    rows: list[dict] = field(default_factory=list)
    dropped: Counter = field(default_factory=Counter)

    def note(self) -> str:
        """One line for the user: rows kept, lines dropped and why."""
        why = ", ".join(f"{n} {reason}" for reason, n in self.dropped.items())
        return (
            f"resume: {len(self.rows)} earlier rows kept"
            if not self.dropped
            else f"resume: {len(self.rows)} earlier rows kept; dropped {sum(self.dropped.values())} lines ({why}); "
            "a design without an intact row is computed again"
        )


def read_earlier(csv_path: Path, log_path: Path) -> Earlier:
    """The intact rows of ``csv_path`` (results.csv) then of ``log_path`` (the build-mode JSON-lines log)."""
    earlier = Earlier()
    seen: set[str] = set()
    if regular_or_absent(csv_path):
        _read_csv(csv_path, earlier, seen)
    if regular_or_absent(log_path):
        _read_log(log_path, earlier, seen)
    return earlier


def _text(path: Path) -> str:
    """The file as text; UTF-16 (a spreadsheet's 'Unicode text') is refused, bad bytes become U+FFFD."""
    data = read_bytes(path, "CSV")
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise RjcadError(
            f"{path}: UTF-16 text, not a results file written by rjcad sweep (UTF-8); "
            "move it away or run without --resume"
        )
    return data.removeprefix(b"\xef\xbb\xbf").decode("utf-8", errors="replace")


def _lines(text: str, earlier: Earlier) -> list[str]:
    """Whole lines (without their line break); an unterminated last line is counted as cut and left out."""
    lines = text.split("\n")
    if lines[-1]:
        earlier.dropped[CUT] += 1
    return [ln.removesuffix("\r") for ln in lines[:-1]]


def _read_csv(path: Path, earlier: Earlier, seen: set[str]) -> None:
    lines = _lines(_text(path), earlier)
    if not lines:
        return
    header = _fields(lines[0]) or []
    need = ["id", "status", "feasible", *INPUTS]
    if "\ufffd" in lines[0] or "\0" in lines[0] or not all(c in header for c in need):
        missing = next((c for c in need if c not in header), "id")
        raise RjcadError(
            f"{path}: its first line is not the header rjcad sweep writes (no {missing} column); "
            "move the file away or run without --resume"
        )
    i = 1
    while i < len(lines):
        line = lines[i]
        i += 1
        if not line.strip():
            continue
        if "\0" in line or "\ufffd" in line:
            earlier.dropped[DAMAGED] += 1
            continue
        record, span = line, 0
        while record.count('"') % 2 and span < _MAX_SPAN and i + span < len(lines):
            record += "\n" + lines[i + span]  # a quoted field with a line break in it
            span += 1
        row = _row(header, _fields(record))
        if row is None:
            earlier.dropped[NOT_A_ROW] += 1  # a stray quote: this line only, the next ones are read on
            continue
        i += span
        _keep(row, earlier, seen)


def _fields(record: str) -> list[str] | None:
    """The fields of one CSV record (None if it does not parse as exactly one)."""
    if '"' not in record:
        return record.split(",")
    try:
        parsed = list(csv.reader(io.StringIO(record, newline="")))
    except csv.Error:
        return None
    return parsed[0] if len(parsed) == 1 else None


def _row(header: list[str], fields: list[str] | None) -> dict | None:
    """The row as a dict if it is intact (see the module docstring), else None."""
    if fields is None or len(fields) != len(header):
        return None
    row = dict(zip(header, fields))
    return row if _intact(row) else None


def _intact(row: dict) -> bool:
    if not _ID.match(str(row.get("id", ""))) or row.get("status") not in STATUSES:
        return False
    if str(row.get("feasible")) not in ("True", "False"):
        return False
    for name, (kind, _) in INPUTS.items():
        value = row.get(name)
        if kind is float:
            try:
                float(value)  # type: ignore[arg-type]  # None (a missing cell) raises TypeError: rejected
            except (TypeError, ValueError):
                return False
        elif not isinstance(value, str) or not value:
            return False
    return True


def _keep(row: dict, earlier: Earlier, seen: set[str]) -> None:
    if row["id"] in seen:
        earlier.dropped[REPEATED] += 1
        return
    seen.add(row["id"])
    earlier.rows.append(row)


def _read_log(path: Path, earlier: Earlier, seen: set[str]) -> None:
    """Rows an interrupted build-mode run logged, one JSON object a line."""
    for line in _lines(_text(path), earlier):
        if not line.strip():
            continue
        row = parse_json_lines(line, str(path))[0]  # the same depth and number guards as every JSON read
        if not isinstance(row, dict) or not _intact({**row, "feasible": str(row.get("feasible"))}):
            earlier.dropped[DAMAGED if "\0" in line or "\ufffd" in line else NOT_A_ROW] += 1
            continue
        _keep(row, earlier, seen)
