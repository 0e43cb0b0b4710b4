"""``rjcad joint`` building in a forked CAD process (``rjcad.cad.process``): the same files as in one process,
errors said as before, and no process left behind."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT

#: ``rjcad ARGS`` through the program's entry; at exit (entry runs the atexit handlers) it records whether
#: OpenCASCADE (OCP) was imported in this process, into the file named by the first argument.
PROGRAM = """
import atexit, json, sys
from pathlib import Path
record = Path(sys.argv[1])
atexit.register(lambda: record.write_text(json.dumps({"occ_here": "OCP" in sys.modules})))
sys.argv = ["rjcad", *sys.argv[2:]]
from rjcad.cli import entry
entry()
"""


def _program(tmp_path, *args, env=None, **kw):
    return subprocess.run(
        [sys.executable, "-c", PROGRAM, str(tmp_path / "record.json"), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, **(env or {})},
        **kw,
    )


def _step_body(data: bytes) -> bytes:
    """A STEP file without its FILE_NAME record (it holds the time of writing)."""
    return re.sub(rb"FILE_NAME\(.*?\);", b"FILE_NAME();", data, flags=re.S)


@pytest.mark.slow
@pytest.mark.parametrize("layout", ["desktop", "stacked"])
def test_the_cad_process_writes_the_files_of_a_build_in_one_process(tmp_path, layout):
    """Built in the CAD process, the triangles and measurements pickled to the program: every file is byte for
    byte the one-process build's (STEP but for its time stamp)."""
    forked = _program(tmp_path, "--debug", "joint", "--layout", layout, "--out", str(tmp_path / "forked"))
    assert forked.returncode == 0, forked.stderr
    assert json.loads((tmp_path / "record.json").read_text()) == {"occ_here": False}  # built in the child
    alone = _program(
        tmp_path, "joint", "--layout", layout, "--out", str(tmp_path / "alone"), env={"RJCAD_CAD_PROCESS": "0"}
    )
    assert alone.returncode == 0, alone.stderr
    assert json.loads((tmp_path / "record.json").read_text()) == {"occ_here": True}
    assert forked.stdout.replace("forked", "alone") == alone.stdout
    names = sorted(p.name for p in (tmp_path / "alone").iterdir())
    assert (
        names
        == sorted(p.name for p in (tmp_path / "forked").iterdir())
        == ["joint.3mf", "joint.glb", "joint.json", "joint.png", "joint.step", "joint.stl"]
    )
    for name in names:
        a, b = (tmp_path / "alone" / name).read_bytes(), (tmp_path / "forked" / name).read_bytes()
        if name.endswith(".step"):
            a, b = _step_body(a), _step_body(b)
        assert a == b, name


def test_a_bad_value_stops_before_the_build_in_one_line(tmp_path):
    t0 = time.perf_counter()
    r = _program(tmp_path, "joint", "--stiffness", "-1", "--out", str(tmp_path / "j"))
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.startswith("rjcad: error: stiffness = -1") and r.stderr.count("\n") == 1
    assert not (tmp_path / "j").exists()
    assert time.perf_counter() - t0 < 60


_ASK = """
import sys
from rjcad.cad import process
assert process.usable()
with process.CadProcess() as cad:
    pid = cad._proc.pid
    {body}
"""


def _run_cad(body: str):
    return subprocess.run(
        [sys.executable, "-c", _ASK.format(body=body)], cwd=ROOT, capture_output=True, text=True, timeout=300
    )


@pytest.mark.slow
def test_an_error_in_the_cad_process_is_raised_in_the_caller_with_its_traceback_as_a_note():
    body = """try:
        cad.joint("not parameters").shape()
    except AttributeError as e:
        print("raised:", e, "|", "in the CAD process:" in "".join(e.__notes__))
    print("alive after:", cad._proc.is_alive())
print("reaped:", cad._proc.exitcode is not None)"""
    r = _run_cad(body)
    assert r.returncode == 0, r.stderr
    assert "raised: 'str' object has no attribute" in r.stdout and "| True" in r.stdout
    assert "reaped: True" in r.stdout
    assert r.stderr == ""  # the child printed nothing of its own


@pytest.mark.slow
def test_a_cad_process_that_dies_is_said_not_waited_for():
    body = """import os, signal
    os.kill(pid, signal.SIGKILL)
    try:
        cad.joint(None).shape()
    except process.CadProcessError as e:
        print("said:", e)"""
    r = _run_cad(body)
    assert r.returncode == 0, r.stderr
    assert "said: the CAD process ended without an answer (exit code -9)" in r.stdout


def _session_processes(sid: int) -> list[int]:
    """Live (not zombie) processes of session ``sid``."""
    pids = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                stat = Path(f"/proc/{d}/stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2 :].split()
            if int(fields[3]) == sid and fields[0] != "Z":
                pids.append(int(d))
    return pids


@pytest.mark.slow
@pytest.mark.parametrize("sig, code, group", [(signal.SIGINT, 130, True), (signal.SIGTERM, 143, False)])
def test_an_interrupted_joint_leaves_no_files_and_no_process(tmp_path, sig, code, group):
    """Ctrl-C (SIGINT to the whole group, as a terminal sends it) or SIGTERM to the program alone, while the CAD
    process imports OpenCASCADE: the program exits with its code, writes nothing, and ends its child."""
    out = tmp_path / "j"
    p = subprocess.Popen(
        [sys.executable, "-m", "rjcad", "joint", "--out", str(out)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 60
    while len(_session_processes(p.pid)) < 2 and time.monotonic() < deadline:  # the CAD process has started
        time.sleep(0.02)
    assert len(_session_processes(p.pid)) == 2
    time.sleep(0.3)
    (os.killpg if group else os.kill)(p.pid, sig)
    _, err = p.communicate(timeout=60)
    # 130/143, or ended by the signal itself (-2/-15; a shell shows 130/143 for both): which one is a race not yet
    # understood (seen in 1 of 6 to 5 of 8 runs on the 2-core machine, the session's first commit as well; the
    # program printed "aborted" and still ended by SIGINT): open
    assert p.returncode in (code, -sig), err
    assert err.strip() == ("rjcad: aborted" if group else "rjcad: terminated")  # click adds a newline first
    assert not out.exists()
    deadline = time.monotonic() + 10
    while _session_processes(p.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _session_processes(p.pid) == []
