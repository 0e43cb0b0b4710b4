"""The ``rjcad`` program's exit (``rjcad.cli.entry``): the interpreter's usual one, and nothing is lost."""

from __future__ import annotations

import json
import subprocess
import sys

from conftest import ROOT

#: A program that registers what a normal exit does (an atexit handler, a thread still running), then runs
#: ``rjcad ARGS`` through ``entry`` as the console script does.
PROGRAM = """
import atexit, sys, threading, time
from pathlib import Path
mark = Path(sys.argv[1])
atexit.register(lambda: mark.with_suffix(".atexit").write_text("ran"))
threading.Thread(target=lambda: (time.sleep(0.3), mark.with_suffix(".thread").write_text("joined"))).start()
sys.argv = ["rjcad", *sys.argv[2:]]
from rjcad.cli import entry
entry()
"""


def _run(tmp_path, *args):
    return subprocess.run(
        [sys.executable, "-c", PROGRAM, str(tmp_path / "mark"), *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )


def test_the_program_joins_threads_runs_atexit_and_flushes(tmp_path):
    r = _run(tmp_path, "spring", "--config", "templates/spring.toml", "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["joint_stiffness_nmm_per_rad"] > 0  # the whole JSON came through the pipe
    assert (tmp_path / "mark.atexit").read_text() == "ran"
    assert (tmp_path / "mark.thread").read_text() == "joined"  # a thread that is not a daemon is waited for


def test_a_user_error_still_exits_2_with_its_one_line(tmp_path):
    r = _run(tmp_path, "spring", "--stiffness", "-1")
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.startswith("rjcad: error: stiffness = -1") and r.stderr.count("\n") == 1
    assert (tmp_path / "mark.atexit").read_text() == "ran"


def test_main_alone_still_raises_system_exit_for_callers_in_process(cli):
    code, out, _ = cli("spring", "--config", "templates/spring.toml", "--json")
    assert code == 0 and json.loads(out)


#: What BLAS the program's NumPy runs with: threadpoolctl's report of the loaded OpenBLAS libraries.
BLAS = """
import sys
sys.argv = ["rjcad", "profiles"]
import atexit, json
from rjcad.cli import entry
def report():
    from threadpoolctl import threadpool_info
    import numpy  # noqa: F401  (loaded by then in most commands; here for the report)
    print(json.dumps([i["num_threads"] for i in threadpool_info() if i["internal_api"] == "openblas"]))
atexit.register(report)
entry()
"""


def _blas_threads(env_value: str | None) -> list[int]:
    import os

    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if env_value is not None:
        env["OPENBLAS_NUM_THREADS"] = env_value
    r = subprocess.run([sys.executable, "-c", BLAS], capture_output=True, text=True, cwd=ROOT, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_the_program_runs_one_blas_thread_unless_the_environment_says_otherwise():
    assert _blas_threads(None) and set(_blas_threads(None)) == {1}
    assert set(_blas_threads("2")) == {2}  # the user's setting wins
