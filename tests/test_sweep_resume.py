"""``rjcad sweep --resume`` on a damaged results.csv or log, and sweeps stopped by SIGINT, SIGTERM, SIGKILL (#17).

Resume keeps every intact row once, computes every other design, and says what it dropped; a file that is
not a results.csv is refused in one line. A stopped build-mode sweep leaves no process behind.
"""

from __future__ import annotations

import copy
import io
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rjcad import sweep as sw
from rjcad.sweep.resume import read_earlier

SPEC = {
    "params": {
        "stiffness_nmm_per_rad": {"range": [2, 12], "steps": 6},
        "rotation_deg": {"values": [60, 120]},
        "material": {"values": ["pla", "petg"]},
    },
    "fixed": {"preload_deg": 90},
}


@pytest.fixture(scope="module")
def first_once(tmp_path_factory):
    """The analytic sweep of 24 designs, run once for the module (plots and all: 3-5 s)."""
    d = tmp_path_factory.mktemp("first")
    spec = sw.SweepSpec.from_dict(SPEC)
    res = sw.run_sweep(spec, d, stream=io.StringIO())
    return d, spec, res.rows


@pytest.fixture
def first(first_once, tmp_path):
    """A finished analytic sweep of 24 designs: its directory (a copy in ``tmp_path``, files and mtimes), rows
    and results.csv bytes."""
    d, spec, rows = first_once
    shutil.copytree(d, tmp_path, dirs_exist_ok=True)
    return spec, copy.deepcopy(rows), (tmp_path / "results.csv").read_bytes()


def resume(spec, out: Path, monkeypatch) -> tuple[sw.SweepResult, list[str]]:
    """Resume the sweep; also the ids it computed again."""
    computed: list[str] = []
    real = sw.analytic_rows

    def counting(points):
        rows = real(points)
        computed.extend(r["id"] for r in rows)
        return rows

    monkeypatch.setattr(sw, "analytic_rows", counting)
    return sw.run_sweep(spec, out, resume=True, stream=io.StringIO()), computed


def assert_each_design_once(spec, out: Path):
    rows = sw.read_results(out / "results.csv")
    ids = [r["id"] for r in rows]
    assert sorted(ids) == sorted(sw.point_id(p) for p in spec.points())
    assert all(r["status"] in ("ok", "infeasible", "failed") for r in rows)
    assert not (out / "results.partial.jsonl").exists()


def _rows(data: bytes) -> list[bytes]:
    """The lines of a results.csv, header first, each with its CRLF."""
    return data.splitlines(keepends=True)


def _start_of(data: bytes, i: int) -> int:
    """Offset of row ``i`` (0: the first after the header; negative from the end)."""
    lines = _rows(data)
    return sum(len(ln) for ln in lines[: (i + 1 if i >= 0 else len(lines) + i)])


def _cut_inside(line: bytes, field: int) -> int:
    """Offset in ``line`` a few bytes into its ``field``-th field."""
    return len(b",".join(line.split(b",")[:field])) + 4


DAMAGE = {
    # name: (damaged bytes from the good ones, ids to compute again (by row index) , dropped reason words)
    "truncated mid-row": (lambda d: d[: len(d) - len(_rows(d)[-1]) // 2], [-1], "cut short"),
    "truncated inside the id": (
        lambda d: d[: len(d) - len(_rows(d)[-1]) + _cut_inside(_rows(d)[-1], 9)],
        [-1],
        "cut short",
    ),
    "truncated after the id": (
        lambda d: d[: len(d) - len(_rows(d)[-1]) + _cut_inside(_rows(d)[-1], 10) - 3],
        [-1],
        "cut short",
    ),
    "last line break lost": (lambda d: d[:-2], [-1], "cut short"),
    "garbage lines": (
        lambda d: b"".join(
            _rows(d)[:5] + [b"\x8f\xff garbage \x00\r\n", b'half "quoted, line\r\n', b"1,2,3\r\n"] + _rows(d)[5:]
        ),
        [],
        "unreadable bytes",
    ),
    "garbage tail": (lambda d: d + b"\x13\x37 tail without a line break \xff", [], "cut short"),
    "NUL tail (a crash)": (
        lambda d: d[: _start_of(d, -3)] + b"\0" * (len(d) - _start_of(d, -3)),
        [-3, -2, -1],
        "cut short",
    ),
    "NUL bytes in a row": (
        lambda d: d[: _start_of(d, 3)] + b"\0" * (len(_rows(d)[4]) - 2) + d[_start_of(d, 4) - 2 :],
        [3],
        "unreadable bytes",
    ),
    "rows repeated (869 for 819)": (lambda d: d + b"".join(_rows(d)[1:8]) + d, [], "repeating a design"),
}


@pytest.mark.parametrize("damage", list(DAMAGE))
def test_resume_on_a_damaged_results_csv_keeps_every_intact_row_once(first, tmp_path, monkeypatch, damage):
    spec, rows, good = first
    make, again, why = DAMAGE[damage]
    (tmp_path / "results.csv").write_bytes(make(good))
    res, computed = resume(spec, tmp_path, monkeypatch)
    assert sorted(computed) == sorted(rows[i]["id"] for i in again)  # the intact rows are not computed again
    assert_each_design_once(spec, tmp_path)
    assert res.notes and res.notes[0].startswith("resume: ") and why in res.notes[0]
    assert "## This run" in (tmp_path / "summary.md").read_text()


def test_resume_drops_nothing_from_a_whole_file(first, tmp_path, monkeypatch):
    spec, _rows, good = first
    res, computed = resume(spec, tmp_path, monkeypatch)
    assert computed == [] and res.notes == ["resume: 24 earlier rows kept"]
    assert (tmp_path / "results.csv").read_bytes() == good


@pytest.mark.parametrize(
    "bad, word",
    [
        (lambda d: d[d.index(b"\n") + 1 :], "id column"),  # no header
        (lambda d: d.replace(b",id,", b",ident,", 1), "id column"),  # no id column
        (lambda d: d.decode().encode("utf-16"), "UTF-16"),
        (lambda d: b"\0" * 40 + d, "header"),
    ],
)
def test_resume_refuses_a_file_that_is_not_a_results_csv_in_one_line(first, tmp_path, cli, bad, word, root):
    _, _, good = first
    (tmp_path / "results.csv").write_bytes(bad(good))
    f = tmp_path / "s.toml"
    f.write_text("[params.stiffness_nmm_per_rad]\nvalues = [4.0, 5.2]\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    code, _out, err = cli("sweep", f, "--out", tmp_path, "--resume")
    assert code == 2 and err.count("\n") == 1 and err.startswith("rjcad: error: ") and word in err
    assert "results.csv" in err and "without --resume" in err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_the_build_log_is_read_line_by_line(tmp_path):
    """An interrupted build-mode run's log: a cut last line, garbage, a repeat; rows of the CSV come first."""
    spec = sw.SweepSpec.from_dict({"params": {"stiffness_nmm_per_rad": {"values": [4.0, 5.0, 6.0]}}})
    pts = spec.points()
    rows = [{**p, "id": sw.point_id(p), "status": "ok", "feasible": True, "error": ""} for p in pts]
    sw.write_results(tmp_path, rows[:1])
    log = tmp_path / "results.partial.jsonl"
    lines = [json.dumps(r) for r in (rows[0], rows[1], rows[1])] + ["{not json", '["a list"]']
    log.write_text("\n".join(lines) + "\n" + json.dumps(rows[2])[:-5])
    got = read_earlier(tmp_path / "results.csv", log)
    assert [r["id"] for r in got.rows] == [rows[0]["id"], rows[1]["id"]]
    assert got.dropped == {
        "repeating a design already read": 2,
        "not a complete row": 2,
        "cut short at the end of the file": 1,
    }


def test_an_interrupted_sweep_leaves_the_earlier_results_as_they_were(first, tmp_path, monkeypatch):
    spec, _, _good = first
    before = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in tmp_path.iterdir()}

    def interrupted(points):
        raise KeyboardInterrupt

    monkeypatch.setattr(sw, "analytic_rows", interrupted)
    with pytest.raises(KeyboardInterrupt):
        sw.run_sweep(spec, tmp_path, stream=io.StringIO())
    assert {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in tmp_path.iterdir()} == before


def test_a_design_named_twice_is_one_row(tmp_path):
    spec = sw.SweepSpec.from_dict({"params": {"stiffness_nmm_per_rad": {"values": [4.0, 4.0, 5.0]}}})
    res = sw.run_sweep(spec, tmp_path, stream=io.StringIO())
    assert len(res.rows) == 2 == res.computed


def test_an_error_message_with_line_breaks_is_one_line(tmp_path, monkeypatch):
    spec = sw.SweepSpec.from_dict({"params": {"stiffness_nmm_per_rad": {"values": [4.0, 5.0]}}})
    row = {
        **spec.points()[0],
        "id": sw.point_id(spec.points()[0]),
        "status": "failed",
        "feasible": False,
        "error": "OCC says:\nno\r\nreally",
    }
    sw.write_results(tmp_path, [row])
    lines = (tmp_path / "results.csv").read_bytes().split(b"\r\n")
    assert len(lines) == 3 and b"OCC says: no really" in lines[1]
    assert [r["error"] for r in read_earlier(tmp_path / "results.csv", tmp_path / "none").rows] == [
        "OCC says: no really"
    ]


# ---------------------------------------------------------------- stopping a build-mode sweep

#: Two infeasible designs (no CAD: their rows come at once), then four that build (1.3-4 s each, two at a time; a
#: worker's first build imports OpenCASCADE): stopped after two rows, both workers are building and two designs
#: wait (with only two, a quiet machine finished both builds before the signal arrived, and the sweep exited 0).
VALUES = [500.0, 600.0, 4.0, 5.0, 6.0, 7.0]
#: The smallest rotation a joint takes: its motion check has the fewest poses (a build takes half the time of 90°'s).
ROTATION_DEG = 15
BUILD_SWEEP = f"[params.stiffness_nmm_per_rad]\nvalues = {VALUES}\n\n[params.rotation_deg]\nvalues = [{ROTATION_DEG}]\n"


def _start(tmp_path: Path, out: Path, *extra: str) -> subprocess.Popen:
    f = tmp_path / "build.toml"
    f.write_text(BUILD_SWEEP)
    # output to files, not pipes: a worker left behind would hold a pipe open and hang the test
    with open(tmp_path / "stdout", "ab") as o, open(tmp_path / "stderr", "ab") as e:
        # SIGINT at its default: a job a non-interactive shell starts in the background (CI's `make test`)
        # inherits SIGINT ignored, and Python then installs no KeyboardInterrupt for it
        return subprocess.Popen(
            [sys.executable, "-m", "rjcad", "sweep", str(f), "--out", str(out), "--build", "--workers", "2", *extra],
            stdout=o,
            stderr=e,
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )


def _rows_logged(out: Path) -> int:
    log = out / "results.partial.jsonl"
    return log.read_text().count("\n") if log.exists() else 0


def _alive(q) -> bool:
    """Running (a zombie waiting for its reaper has exited)."""
    import psutil

    try:
        return q.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGKILL, -9)])
def test_a_stopped_build_sweep_leaves_no_process_and_resumes_each_design_once(tmp_path, sig, code):
    psutil = pytest.importorskip("psutil")
    out = tmp_path / "out"
    p = _start(tmp_path, out)
    t0 = time.monotonic()
    while _rows_logged(out) < 2 and p.poll() is None and time.monotonic() - t0 < 240:
        time.sleep(0.2)
    assert p.poll() is None, "the sweep ended before it could be stopped"
    tree = psutil.Process(p.pid).children(recursive=True)  # workers, forkserver, resource tracker
    assert len(tree) >= 3
    p.send_signal(sig)
    assert p.wait(timeout=30) == code
    deadline = time.monotonic() + 10
    while any(_alive(q) for q in tree) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not [q for q in tree if _alive(q)], [" ".join(q.cmdline())[:80] for q in tree if _alive(q)]
    assert "leaked" not in (tmp_path / "stderr").read_text()  # the resource tracker cleans up without a word
    assert _rows_logged(out) >= 2 and not (out / "results.csv").exists()  # the finished rows are kept
    r = _start(tmp_path, out, "--resume")
    assert r.wait(timeout=300) == 0, (tmp_path / "stderr").read_text()[-2000:]
    rows = sw.read_results(out / "results.csv")
    spec = sw.SweepSpec.from_dict(
        {"params": {"stiffness_nmm_per_rad": {"values": VALUES}, "rotation_deg": {"values": [ROTATION_DEG]}}}
    )
    assert sorted(r["id"] for r in rows) == sorted(sw.point_id(pt) for pt in spec.points())
    assert [r["status"] for r in rows].count("infeasible") == 2 and all(r["status"] for r in rows)


def test_a_stopped_build_sweep_says_what_its_log_keeps(tmp_path):
    """The line a stopped build sweep prints counts the rows its log keeps, and says so when there is none."""
    from rjcad.cli.sweep import _stopped

    log = tmp_path / "results.partial.jsonl"
    assert _stopped(log) == "sweep: stopped before any design was built: nothing to resume"
    log.write_text("")
    assert _stopped(log).endswith("nothing to resume")
    log.write_text('{"id": "a"}\n{"id": "b"}\n{"id": "c"')  # the last row cut by the stop
    assert _stopped(log) == f"sweep: stopped; 2 designs built so far in {log}: --resume continues from them"
    link = tmp_path / "link.jsonl"
    link.symlink_to(log)
    assert _stopped(link).endswith("nothing to resume")  # never read through a link
