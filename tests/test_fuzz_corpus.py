"""The fuzz corpus (tests/fuzz/): every abusive case keeps the CLI's promise.

One line on stderr and exit code 2 for every user error, no traceback, no warning, no partial output,
an earlier run untouched, no lost or duplicated sweep row, no process left behind. The cases that test
only an option's value (``corpus.parse_only``, about half) run here, through ``rjcad.cli.main`` in this
process, while the others run as real processes in tests/fuzz/runner.py (a warm interpreter forked per
case, two at a time: signals, files, processes, read-only dirs, full disks); both get the same verdict,
and every broken promise is listed in one failure.
"""

from __future__ import annotations

import collections
import hashlib
import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import warnings
from pathlib import Path

import pytest
from fuzz import corpus

RUNNER = Path(__file__).resolve().parent / "fuzz" / "runner.py"
ROOT = Path(__file__).resolve().parents[1]
MIN_CASES = 1145  # the corpus only grows (951 before issue #38, 1109 after it)
NO_CAPS = 97  # runner.NO_CAPS
NOISE = re.compile(r"Traceback|Warning:|warnings\.warn|^\s+warn\(", re.M)
#: The one line a former spelling adds to stderr (docs/cli.md): not a warning, not the error line; a case tagged
#: ``note`` may (``"allowed"``) or must (``"required"``) print it, once, first; no other case may.
NOTE = re.compile(r"^rjcad: note: \S.* is deprecated; use .+ \(the old spelling goes in the next release\)$")


def content_digest(p: Path) -> str:
    """SHA-1 of a regular file's data extents, each with its offset. A sparse file's holes read as zeros and are
    not data: the corpus's 1.5 GB sparse file hashes its few written bytes, not 1.5 GB of zeros (twice per run).
    Any byte written into a hole makes a new extent, so the digest still sees every change."""
    h = hashlib.sha1()
    with open(p, "rb") as f:
        fd, size, pos = f.fileno(), os.fstat(f.fileno()).st_size, 0
        while pos < size:
            try:
                start = os.lseek(fd, pos, os.SEEK_DATA)
                end = os.lseek(fd, start, os.SEEK_HOLE)
            except OSError:  # ENXIO: no data after pos
                break
            f.seek(start)
            h.update(start.to_bytes(8, "little"))
            while start < end:
                chunk = f.read(min(1 << 20, end - start))
                if not chunk:
                    break
                h.update(chunk)
                start += len(chunk)
            pos = end
    return h.hexdigest()


def snapshot(d: Path) -> dict:
    """Every entry under ``d``: kind, size, content digest (data extents), modification time, mode."""
    out = {}
    for p in sorted(d.rglob("*")):
        st = p.lstat()
        digest = content_digest(p) if p.is_file() and not p.is_symlink() else None
        out[str(p.relative_to(d))] = (p.is_dir(), st.st_size, digest, st.st_mtime_ns, st.st_mode)
    return out


def _named(line: str, words) -> bool:
    norm = lambda s: s.lower().replace("_", "-")  # noqa: E731
    return not words or any(norm(w) in norm(line) for w in words)


def verdict(case: corpus.Case, res: dict, err: str, out: str, before: dict, after: dict) -> list[str]:
    """The broken promises of one case (empty: it kept them all)."""
    problems = []
    code = res["code"]
    if code is None:
        return [f"no answer within {case.timeout:.0f} s"]
    if res["stray"]:
        problems.append("left processes running after it exited")
    if NOISE.search(err) or NOISE.search(out):
        problems.append(f"traceback or warning: {err[-300:]!r}")
    for word in case.forbid:
        if word in err or word in out:
            problems.append(f"printed {word!r}")
    lines = err.splitlines()
    notes = [i for i, line in enumerate(lines) if NOTE.match(line)]
    want = case.tags.get("note")
    if notes and (want is None or notes != [0]):
        problems.append(f"a deprecation note it should not print, or twice, or not first: {err[:300]!r}")
    elif want == "required" and not notes and code == 0:
        problems.append(f"no deprecation note for a former spelling: {err[:300]!r}")
    lines = [line for i, line in enumerate(lines) if i not in notes]
    err = "\n".join(lines) + ("\n" if lines else "")
    allowed = {"error": {2}, "ok": {0}, "either": {0, 2}, "checked": {0, 1}, "either-checked": {0, 1, 2}}[case.expect]
    if code not in allowed:
        problems.append(f"exit {code}, expected {sorted(allowed)}: {err[-300:]!r}")
    elif code == 2:
        if len(lines) != 1 or not lines[0].startswith("rjcad: error: "):
            problems.append(f"stderr is not one 'rjcad: error:' line: {err[:300]!r}")
        elif len(lines[0]) > corpus.MAX_LINE:
            problems.append(f"error line of {len(lines[0])} characters")
        elif not _named(lines[0], case.mention):
            problems.append(f"error line names none of {case.mention}: {lines[0]!r}")
        if before != after:
            changed = sorted(set(before) ^ set(after) | {k for k in before if k in after and before[k] != after[k]})
            problems.append(f"failed but changed its directory: {changed[:5]}")
    elif case.expect.endswith("checked") and err.strip():
        problems.append(f"stderr not empty: {err[:300]!r}")
    return problems


def _children() -> set[int]:
    """The processes whose parent is this one (Linux /proc)."""
    me, kids = os.getpid(), set()
    for pid in os.listdir("/proc"):
        if pid.isdigit():
            try:
                with open(f"/proc/{pid}/stat", "rb") as fh:
                    ppid = int(fh.read().rsplit(b")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            if ppid == me:
                kids.add(int(pid))
    return kids


class _TimedOut(BaseException):
    """The in-process case ran past its timeout."""


def _on_alarm(signum, frame):
    raise _TimedOut()


def run_in_process(case: corpus.Case, d: Path, out_file: Path, err_file: Path) -> dict:
    """Run one parse-only case through ``rjcad.cli.main`` here, in ``d``, as the runner's child runs it: its
    stdout and stderr (Python's streams and file descriptors 1 and 2) into ``out_file``/``err_file``, a warning
    that a fresh interpreter would print written there, an uncaught exception's traceback too. Returns the
    runner's result: ``code`` (None past the timeout), ``seconds``, ``stray`` (a child process left)."""
    from rjcad.cli import main

    before, cwd, streams = _children(), os.getcwd(), (sys.stdout, sys.stderr)
    fds = [os.dup(1), os.dup(2)]
    timer = threading.current_thread() is threading.main_thread()  # signals reach the main thread only
    old_alarm = signal.signal(signal.SIGALRM, _on_alarm) if timer else None
    t0 = time.monotonic()
    with open(out_file, "wb") as out, open(err_file, "wb") as err:
        py_out, py_err = io.StringIO(), io.StringIO()
        try:
            for stream in streams:
                stream.flush()
            os.dup2(out.fileno(), 1)
            os.dup2(err.fileno(), 2)
            sys.stdout, sys.stderr = py_out, py_err
            os.chdir(d)
            if timer:
                signal.setitimer(signal.ITIMER_REAL, case.timeout)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")  # Python's default filters: what a fresh `python -m rjcad` prints
                for quiet in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
                    warnings.simplefilter("ignore", quiet)
                try:
                    main(list(case.argv))
                    code = 0
                except SystemExit as e:
                    code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
                    if isinstance(e.code, str):
                        sys.stderr.write(e.code + "\n")
                except _TimedOut:
                    code = None
                except BaseException:  # what an uncaught exception does to `python -m rjcad`
                    traceback.print_exc()
                    code = 1
            if timer:
                signal.setitimer(signal.ITIMER_REAL, 0)
            for w in caught:
                sys.stderr.write(warnings.formatwarning(w.message, w.category, w.filename, w.lineno))
        finally:
            if timer:
                signal.setitimer(signal.ITIMER_REAL, 0)
                signal.signal(signal.SIGALRM, old_alarm)
            os.chdir(cwd)
            sys.stdout, sys.stderr = streams
            os.dup2(fds[0], 1)
            os.dup2(fds[1], 2)
            for fd in fds:
                os.close(fd)
            out.write(py_out.getvalue().encode("utf-8", "backslashreplace"))
            err.write(py_err.getvalue().encode("utf-8", "backslashreplace"))
    return {"code": code, "seconds": round(time.monotonic() - t0, 3), "stray": bool(_children() - before)}


@pytest.fixture(scope="module")
def corpus_run():
    """Build the shared inputs and every case's directory, run them all, collect the verdicts."""
    base = Path(tempfile.mkdtemp(prefix="rjcad-fuzz-"))
    base.chmod(0o755)
    mounts = []
    try:
        shared = corpus.make_shared(base / "_shared", sys.executable, ROOT)
        mountable = os.geteuid() == 0 and corpus.can_mount(base)
        results_dir = corpus.open_dir(base / "_results")
        corpus.open_dir(base / "_mpl")
        cases = [c for c in corpus.all_cases(shared) if c.needs != "mount" or mountable]
        only = os.environ.get("RJCAD_FUZZ_ONLY")  # id prefixes, comma-separated: for whoever works on a class
        if only:
            cases = [c for c in cases if c.id.startswith(tuple(only.split(",")))]
        jobs, before, here = [], {}, []
        for c in cases:
            d = corpus.open_dir(base / c.id)
            c.setup(d)
            if c.needs == "mount":
                mounts.append(d / "fulldisk")
            before[c.id] = snapshot(d)
            if corpus.parse_only(c):
                here.append(c)
                continue
            jobs.append(
                {
                    "id": c.id,
                    "argv": c.argv,
                    "cwd": str(d),
                    "timeout": c.timeout,
                    "read_only": c.read_only,
                    "fsize": c.fsize,
                    "encoding": c.tags.get("encoding"),
                    "out": str(results_dir / f"{c.id}.out"),
                    "err": str(results_dir / f"{c.id}.err"),
                }
            )
        (base / "cases.json").write_text(json.dumps(jobs))
        env = dict(
            os.environ,
            MPLBACKEND="Agg",
            MPLCONFIGDIR=str(base / "_mpl"),
            PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
        )
        runner = subprocess.Popen(
            [sys.executable, str(RUNNER), str(base / "cases.json"), str(base / "results.json"), "--jobs", "2"],
            cwd=ROOT,
            env=env,
        )
        try:  # the parse-only cases here, while the runner runs the others
            with pytest.MonkeyPatch.context() as mp:
                mp.setenv("MPLBACKEND", "Agg")
                mp.setenv("MPLCONFIGDIR", str(base / "_mpl"))
                results = {
                    c.id: run_in_process(c, base / c.id, results_dir / f"{c.id}.out", results_dir / f"{c.id}.err")
                    for c in here
                }
            assert runner.wait(timeout=1500) == 0
        finally:
            if runner.poll() is None:
                runner.kill()
                runner.wait()
        results.update(json.loads((base / "results.json").read_text()))
        verdicts, skipped = {}, []
        for c in cases:
            d = base / c.id
            if c.read_only and results[c.id]["code"] == NO_CAPS:
                skipped.append(c.id)  # root could not be made to obey file modes here
                continue
            err = (results_dir / f"{c.id}.err").read_text(errors="replace")
            out = (results_dir / f"{c.id}.out").read_text(errors="replace")
            problems = verdict(c, results[c.id], err, out, before[c.id], snapshot(d))
            if not problems and c.post is not None:
                try:
                    c.post(d, results[c.id]["code"])
                except AssertionError as e:
                    problems.append(f"files: {e}")
            verdicts[c.id] = (problems, results[c.id])
        yield cases, verdicts, mountable, skipped, len(here)
    finally:
        for m in mounts:
            subprocess.run(["umount", str(m)], capture_output=True)
        shutil.rmtree(base, ignore_errors=True)


def test_every_case_keeps_the_promise(corpus_run):
    cases, verdicts, mountable, skipped, here = corpus_run
    per_class = collections.Counter(c.id.split("-")[0] for c in cases)
    slowest = sorted(verdicts.items(), key=lambda kv: -(kv[1][1]["seconds"] or 0))[:3]
    print(
        f"\nfuzz corpus: {len(cases)} cases ({dict(per_class)}; {here} parse-only in this process, "
        f"{len(cases) - here} as processes); full-disk cases "
        f"{'run' if mountable else 'skipped (cannot mount a tmpfs)'}; read-only cases "
        f"{f'skipped: {len(skipped)} (cannot drop CAP_DAC_OVERRIDE)' if skipped else 'run'}; slowest "
        + ", ".join(f"{k} {v[1]['seconds']:.1f} s" for k, v in slowest)
    )
    failed = {k: v[0] for k, v in verdicts.items() if v[0]}
    if os.environ.get("RJCAD_FUZZ_REPORT"):  # the whole verdict, for whoever works on the failures
        Path(os.environ["RJCAD_FUZZ_REPORT"]).write_text(json.dumps(verdicts, indent=1))
    assert len(cases) >= MIN_CASES or os.environ.get("RJCAD_FUZZ_ONLY")
    assert not failed, f"{len(failed)} of {len(cases)} cases broke a promise:\n" + "\n".join(
        f"  {k}: {'; '.join(p)}" for k, p in sorted(failed.items())
    )


def test_the_snapshot_sees_a_byte_written_into_a_sparse_hole(tmp_path):
    """content_digest hashes a sparse file's data only, yet a byte written into a hole, or a changed byte,
    changes the digest; equal files give equal digests."""
    a, b = tmp_path / "a", tmp_path / "b"
    for p in (a, b):
        with open(p, "wb") as f:
            f.write(b"head")
            f.truncate(1 << 30)  # 1 GB, sparse
    assert content_digest(a) == content_digest(b)
    with open(b, "r+b") as f:
        f.seek(700 << 20)
        f.write(b"\x00x")
    assert content_digest(a) != content_digest(b)
    with open(a, "r+b") as f:
        f.seek(700 << 20)
        f.write(b"\x00y")
    assert content_digest(a) != content_digest(b)
    dense = tmp_path / "dense"
    dense.write_bytes(b"abc" * 1000)
    before = content_digest(dense)
    dense.write_bytes(b"abd" * 1000)
    assert content_digest(dense) != before
