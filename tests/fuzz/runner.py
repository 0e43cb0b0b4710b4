"""Run many `rjcad` command lines as real processes, fast: import once, fork per case.

Usage: python runner.py CASES.json RESULTS.json [--jobs N]

Each case (JSON object): ``id``, ``argv`` (after ``rjcad``), ``cwd``, ``timeout`` [s], ``out``/``err``
(files that receive the child's fd 1 and 2), optional ``read_only`` (true: root loses the capabilities that
bypass file modes, so a directory of mode 0555 is read-only to the command), ``fsize`` (RLIMIT_FSIZE in bytes: a write beyond it fails with EFBIG, a disk that
fills up). The child is a fork of this process after the heavy imports, so it starts in milliseconds
yet has its own warnings state, file descriptors, limits and process group, as `python -m rjcad` has.
The result per case: ``code`` (exit status; -N killed by signal N; null on timeout), ``seconds`` and
``stray`` (processes of its group still alive after it exited: a worker that outlived its command).
"""

from __future__ import annotations

import contextlib
import json
import os
import resource
import signal
import sys
import time
import traceback

NO_CAPS = 97  # exit code: this process could not make root obey file permissions (case skipped)
CAP_DAC = (1, 2, 3)  # CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, CAP_FOWNER


def _obey_permissions() -> bool:
    """Make this process (and what it execs) obey file modes although it may run as root.

    Drops CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH and CAP_FOWNER from the bounding, effective,
    permitted and inheritable sets (Linux capget/capset), so a directory of mode 0555 cannot be
    written; unlike switching to another user, the interpreter can still read its own files.
    True when done, or when the process is not root (permissions already apply).
    """
    if os.geteuid() != 0:
        return True
    import ctypes

    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Data(ctypes.Structure):
        _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32), ("inheritable", ctypes.c_uint32)]

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        for cap in CAP_DAC:
            libc.prctl(24, cap, 0, 0, 0)  # PR_CAPBSET_DROP
        header, data = Header(0x20080522, 0), (Data * 2)()  # _LINUX_CAPABILITY_VERSION_3
        if libc.capget(ctypes.byref(header), data) != 0:
            return False
        keep = ~sum(1 << c for c in CAP_DAC) & 0xFFFFFFFF
        for name in ("effective", "permitted", "inheritable"):
            setattr(data[0], name, getattr(data[0], name) & keep)
        if libc.capset(ctypes.byref(header), data) != 0:
            return False
        probe = os.open("/", os.O_RDONLY)
        os.close(probe)
        return True
    except (OSError, AttributeError):
        return False


def _preload() -> None:
    """Import what the commands import lazily, and compile the finger solver, so that every child starts warm:
    every rjcad module (a child that imported the identification's modules itself spent 0.8 s of CPU on SciPy's
    signal and stats, 73 cases of them) and the libraries they import inside functions."""
    import pkgutil

    os.environ.setdefault("MPLBACKEND", "Agg")
    import rjcad

    names = [m.name for m in pkgutil.walk_packages(rjcad.__path__, "rjcad.") if not m.name.endswith("__main__")]
    for name in (*names, "matplotlib.pyplot", "scipy.optimize", "platformdirs", "multiprocessing"):
        with contextlib.suppress(Exception):  # a missing optional module is the command's business, not the runner's
            __import__(name)
    try:  # the finger solver's compiled kernels, so that no child compiles them (numba's cache may still be cold)
        import io
        from pathlib import Path

        from rjcad.cli import main

        template = Path(__file__).resolve().parents[2] / "templates" / "finger.toml"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(["simulate", "finger", str(template), "--json"])
    except (Exception, SystemExit):
        pass
    try:  # the preview's VTK modules (imports only: an OpenGL context is made in each child, after the fork)
        from rjcad.cad.render import _vtk

        _vtk()
    except Exception:
        pass


def _child(case: dict) -> None:
    """In the forked child: set up the process as the case asks, run the CLI, exit with its code."""
    code = 1
    try:
        os.setpgrp()
        out = os.open(case["out"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o666)
        err = os.open(case["err"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o666)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.dup2(out, 1)
        os.dup2(err, 2)
        os.chdir(case["cwd"])
        if case.get("fsize"):
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (case["fsize"], case["fsize"]))
        if case.get("read_only") and not _obey_permissions():
            os._exit(NO_CAPS)
        if case.get("encoding"):  # a terminal in another locale (e.g. ISO-8859-1): its streams' encoding
            for stream in (sys.stdout, sys.stderr):
                stream.reconfigure(encoding=case["encoding"], errors="strict")
        from rjcad.cli import main

        try:
            main(list(case["argv"]))
            code = 0
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
            if isinstance(e.code, str):
                sys.stderr.write(e.code + "\n")
    except BaseException:  # what an uncaught exception does to `python -m rjcad`
        traceback.print_exc()
        code = 1
    finally:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(code)


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except (ProcessLookupError, PermissionError):
        return False
    return True


def _finish(pid: int, status: int, started: float, timed_out: bool) -> dict:
    """The result of one child; kills what is left of its process group (and reports it)."""
    stray = False
    deadline = time.monotonic() + 2.0
    while _group_alive(pid) and time.monotonic() < deadline:  # give a pool a moment to wind down
        time.sleep(0.05)
    if _group_alive(pid):
        stray = True
        os.killpg(pid, signal.SIGKILL)
    code = None if timed_out else (os.waitstatus_to_exitcode(status))
    return {"code": code, "seconds": round(time.monotonic() - started, 3), "stray": stray}


def run(cases: list[dict], jobs: int = 1) -> dict:
    """Run every case, ``jobs`` at a time; results by case id."""
    _preload()
    sys.stdout.flush()
    sys.stderr.flush()
    pending, running, results = list(cases), {}, {}
    while pending or running:
        while pending and len(running) < jobs:
            case = pending.pop(0)
            pid = os.fork()
            if pid == 0:
                _child(case)
            running[pid] = (case, time.monotonic())
        pid, status = os.waitpid(-1, os.WNOHANG)
        if pid == 0:
            now = time.monotonic()
            for p, (case, t0) in list(running.items()):
                if now - t0 > case.get("timeout", 60):
                    os.killpg(p, signal.SIGKILL)
                    os.waitpid(p, 0)
                    results[case["id"]] = _finish(p, 0, t0, True)
                    del running[p]
            time.sleep(0.005)
            continue
        if pid in running:
            case, t0 = running.pop(pid)
            results[case["id"]] = _finish(pid, status, t0, False)
    return results


def main(argv: list[str]) -> None:
    jobs = int(argv[argv.index("--jobs") + 1]) if "--jobs" in argv else 1
    with open(argv[0], encoding="utf-8") as fh:
        cases = json.load(fh)
    results = run(cases, jobs)
    with open(argv[1], "w", encoding="utf-8") as fh:
        json.dump(results, fh)


if __name__ == "__main__":
    main(sys.argv[1:])
