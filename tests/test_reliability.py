"""Issue #38, the rules at their root (the fuzz corpus, tests/fuzz/, checks them command by command): inputs are
regular files, outputs are never written through a link, a signal never leaves "terminated" with a new set in
place, a killed run's leftovers are cleared, a locale or an environment that rjcad cannot use is worked around."""

from __future__ import annotations

import os
import stat
import subprocess
import sys

import pytest
from conftest import ROOT

from rjcad.errors import RjcadError
from rjcad.io import outputs
from rjcad.io.config import write_atomic
from rjcad.io.outputs import OutputError, write_set
from rjcad.io.untrusted import check_zip, parse_json_lines, read_bytes, read_text


@pytest.mark.parametrize("kind", ["fifo", "device", "directory"])
def test_only_a_regular_file_is_read_and_nothing_blocks(tmp_path, kind):
    path = tmp_path / "in.toml"
    {"fifo": lambda: os.mkfifo(path), "device": lambda: path.symlink_to("/dev/zero"), "directory": path.mkdir}[kind]()
    with pytest.raises(RjcadError, match=r"in\.toml: (not a regular file|is a directory)"):
        read_text(path, "TOML")  # a FIFO without a writer: refused at once, not waited on


def test_a_file_over_its_cap_is_refused_by_its_size_before_it_is_read(tmp_path):
    big = tmp_path / "finger.glb"
    with big.open("wb") as f:
        f.truncate(1 << 31)  # 2 GB, sparse: refused by its size, nothing read
    with pytest.raises(RjcadError, match="too large: a mesh file must be at most 256 MB"):
        read_bytes(big, "mesh")


def test_a_zip_bomb_is_refused_before_it_is_inflated():
    with pytest.raises(RjcadError, match="inflates to 300 MB"):
        check_zip(_zip_bomb(300), "bomb.3mf")


def test_json_lines_keep_the_depth_guard():
    rows = parse_json_lines('{"id": "a"}\n' + "[" * 200_000 + "]" * 200_000 + "\n[1]\n", "log")
    assert rows == [{"id": "a"}, None, [1]]


@pytest.mark.parametrize("kind", ["link", "fifo"])
def test_an_output_is_never_written_through_a_link_nor_replaces_a_fifo(tmp_path, kind):
    outside = tmp_path / "outside.txt"
    outside.write_text("not rjcad's")
    target = tmp_path / "o" / "r.json"
    target.parent.mkdir()
    target.symlink_to(outside) if kind == "link" else os.mkfifo(target)
    with pytest.raises(OutputError, match=r"r\.json: cannot write: is a (symbolic link|FIFO)"):
        write_atomic(target, "{}")
    with pytest.raises(OutputError, match=r"r\.json: cannot write: is a (symbolic link|FIFO)"):
        write_set(tmp_path / "o", {"r.json": "{}"})
    assert outside.read_text() == "not rjcad's"
    assert target.is_symlink() if kind == "link" else stat.S_ISFIFO(target.lstat().st_mode)
    assert sorted(p.name for p in target.parent.iterdir()) == ["r.json"]  # no temporary left


def test_any_legal_name_is_written_and_made_folders_go_on_failure(tmp_path):
    name = "n" * 251 + ".png"  # 255 bytes: the temporary beside it must be shorter than the name
    write_atomic(tmp_path / name, b"x")
    assert [p.name for p in tmp_path.iterdir()] == [name]
    with pytest.raises(OutputError):
        write_atomic(tmp_path / "new" / "deeper" / ("n" * 256), b"x")  # too long: refused
    assert not (tmp_path / "new").exists()  # the folders it made are gone


def test_a_killed_runs_leftovers_are_cleared_by_the_next_run(tmp_path):
    dead = tmp_path / ".rjcad-999999999-abc.tmp"  # no such pid
    dead.mkdir()
    (dead / "joint.stl").write_text("half")
    live = tmp_path / f".rjcad-{os.getppid()}-def.tmp"  # a running process's stage: left alone
    live.mkdir()
    write_set(tmp_path, {"a.txt": "a"})
    assert not dead.exists() and live.is_dir()


def test_a_signal_after_the_set_is_in_place_lets_the_command_finish():
    from rjcad.cli import Terminated, _on_sigint, _on_sigterm

    try:
        outputs.PLACED = False
        with pytest.raises(Terminated):
            _on_sigterm(15, None)
        with pytest.raises(KeyboardInterrupt):
            _on_sigint(2, None)
        outputs.PLACED = True
        _on_sigterm(15, None)  # ignored: the command finishes and exits 0
        _on_sigint(2, None)
    finally:
        outputs.PLACED = False


def test_one_number_spelt_three_ways_is_one_design():
    from rjcad.sweep.spec import INPUTS, point_id

    base = dict.fromkeys(INPUTS)
    ids = {point_id({**base, "preload_deg": v, "stiffness_nmm_per_rad": 5.2}) for v in (90, 90.0, 90.00)}
    assert len(ids) == 1
    assert point_id({**base, "preload_deg": 90.5}) != point_id({**base, "preload_deg": 90})


def test_mujoco_warnings_are_kept_not_printed_nor_logged(tmp_path, monkeypatch):
    pytest.importorskip("mujoco")
    import math

    import mujoco

    from rjcad.mjcf.simulate import WARNINGS, quiet_mujoco, raise_warnings

    monkeypatch.chdir(tmp_path)
    quiet_mujoco()
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint type="hinge"/><geom size="0.1"/></body></worldbody></mujoco>'
    )
    d = mujoco.MjData(m)
    d.qpos[0] = math.nan
    mujoco.mj_step(m, d)
    assert WARNINGS and not (tmp_path / "MUJOCO_LOG.TXT").exists()
    with pytest.raises(RjcadError, match=r"bad\.xml: MuJoCo warned: Nan"):
        raise_warnings("bad.xml")


def _program(tmp_path, env: dict, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "rjcad", *args],
        capture_output=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT), **env},
        timeout=120,
    )


def test_a_bad_backend_and_an_unwritable_home_are_worked_around(tmp_path):
    home = "/sys/no-home"  # a read-only file system: not even root can make a folder there
    temp = tmp_path / "temp"
    temp.mkdir()
    env = {"MPLBACKEND": "nonsense", "HOME": home, "XDG_CONFIG_HOME": "", "XDG_CACHE_HOME": "", "MPLCONFIGDIR": ""}
    r = _program(tmp_path, {**env, "TMPDIR": str(temp)}, "simulate", "joint", "--rotation", "90", "--plot", "j.png")
    assert r.returncode == 0 and r.stderr == b"", r.stderr.decode()
    assert (tmp_path / "j.png").stat().st_size > 0
    assert not any(temp.iterdir())  # Matplotlib's private folder was made there, and removed at exit


@pytest.mark.parametrize("encoding", ["latin-1", "ascii"])
def test_a_terminal_that_cannot_encode_the_symbols_gets_ascii(tmp_path, encoding):
    r = _program(tmp_path, {"PYTHONIOENCODING": encoding}, "simulate", "finger")
    assert r.returncode == 0 and r.stderr == b"", r.stderr.decode()
    out = r.stdout.decode("latin-1" if encoding == "latin-1" else "utf-8")  # click writes UTF-8 on plain ASCII
    assert "theta = (" in out or "θ = (" in out


def test_files_beside_a_manifest_stay_in_its_folder_unless_allowed(tmp_path):
    from rjcad.view import ViewerError, read_built

    folder = tmp_path / "built"
    folder.mkdir()
    man = folder / "finger.json"
    man.write_bytes((ROOT / "tests" / "data" / "manifest_v0_finger.json").read_bytes())
    (tmp_path / "elsewhere.glb").write_bytes(b"not a GLB")
    (folder / "finger.glb").symlink_to("../elsewhere.glb")
    with pytest.raises(RjcadError, match=r"is outside .* \(symlinks followed\)"):
        read_built(man)
    with pytest.raises(ViewerError, match="not a GLB"):  # allowed: read, and refused for what it holds
        read_built(man, allow_outside=True)


#: Runs ``rjcad ARGS`` and writes its peak resident memory [kB] and its time [s] at exit to the first argument.
#: The peak is the process's own (VmHWM): ru_maxrss also keeps the peak of the process it was forked from.
MEASURED = """
import atexit, re, sys, time
t0 = time.monotonic()
out = sys.argv[1]
def peak():
    return re.search(r"VmHWM:\\s*(\\d+)", open("/proc/self/status").read()).group(1)
atexit.register(lambda: open(out, "w").write(f"{peak()} {time.monotonic() - t0}"))
sys.argv = ["rjcad", *sys.argv[2:]]
from rjcad.cli import main
main()
"""


def _huge(path, size):
    with path.open("wb") as f:
        f.truncate(size)


@pytest.mark.parametrize(
    ("name", "make", "args"),
    [
        ("bomb.3mf", lambda p: p.write_bytes(_zip_bomb(300)), ["check", "bomb.3mf"]),
        ("huge.stl", lambda p: _huge(p, 300 << 20), ["check", "huge.stl"]),
        ("finger.glb", lambda p: _huge(p, 3 << 29), ["view", "finger.json", "--out", "o"]),
    ],
)
def test_a_rejected_input_costs_under_500_mb_and_5_s(tmp_path, name, make, args):
    make(tmp_path / name)
    if name == "finger.glb":
        (tmp_path / "finger.json").write_bytes((ROOT / "tests" / "data" / "manifest_v0_finger.json").read_bytes())
    r = subprocess.run(
        [sys.executable, "-c", MEASURED, str(tmp_path / "usage"), *args],
        capture_output=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=60,
    )
    assert r.returncode == 2 and name in r.stderr.decode() and len(r.stderr.splitlines()) == 1, r.stderr
    peak_kb, seconds = (float(x) for x in (tmp_path / "usage").read_text().split())
    assert peak_kb < 500 * 1024 and seconds < 5.0, (peak_kb, seconds)


def _zip_bomb(mb: int) -> bytes:
    import io
    import zipfile

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z, z.open("3D/3dmodel.model", "w", force_zip64=True) as f:
        for _ in range(mb):
            f.write(bytes(1 << 20))
    return buf.getvalue()


def test_an_append_only_folder_is_refused_and_left_as_it_was(tmp_path):
    folder = tmp_path / "ap"
    folder.mkdir()
    if subprocess.run(["chattr", "+a", str(folder)], capture_output=True).returncode != 0:
        pytest.skip("chattr +a is not available here")
    try:
        with pytest.raises(OutputError, match="append-only"):
            write_atomic(folder / "s.png", b"x")
        with pytest.raises(OutputError, match="append-only"):
            write_set(folder, {"a.txt": "a"})
        assert not any(folder.iterdir())  # no temporary left (it could not have been removed)
    finally:
        subprocess.run(["chattr", "-a", str(folder)], capture_output=True)


@pytest.mark.parametrize("delay_ms", [0, 3, 10, 30])
def test_a_signal_as_the_set_is_staged_stops_before_it_or_finishes_it(tmp_path, delay_ms):
    """SIGTERM ``delay_ms`` after the stage appears: either the command stops (143) and the folder it made is gone,
    or the whole set is in place and it exits 0; never "terminated" with new files in place."""
    import signal
    import time

    out = tmp_path / "o"
    p = subprocess.Popen(
        [sys.executable, "-m", "rjcad", "bench", "--out", str(out), "--samples", "200"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    deadline = time.monotonic() + 60
    while p.poll() is None and time.monotonic() < deadline and not (out.is_dir() and any(out.glob(".rjcad-*"))):
        time.sleep(0.0005)
    time.sleep(delay_ms / 1000)
    if p.poll() is None:
        p.send_signal(signal.SIGTERM)
    code = p.wait(timeout=60)
    err = p.stderr.read().decode() if p.stderr else ""
    files = sorted(f.name for f in out.iterdir()) if out.exists() else []
    if code == 143:
        assert files == [] and err.strip() == "rjcad: terminated", (files, err)
    else:
        assert code == 0 and "campaign.toml" in files and "truth.json" in files, (code, files, err)
        assert not [f for f in files if f.startswith(".rjcad-")]


def test_a_build_sweep_stopped_early_leaves_no_empty_folder(tmp_path):
    """SIGTERM as soon as a fresh build sweep makes its output folder: the folder goes unless it keeps rows."""
    import signal
    import time

    from fuzz.corpus import SWEEP_TOML

    (tmp_path / "s.toml").write_text(SWEEP_TOML)
    out = tmp_path / "o"
    p = subprocess.Popen(
        [sys.executable, "-m", "rjcad", "sweep", "s.toml", "--out", str(out), "--build", "--workers", "2"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    deadline = time.monotonic() + 60
    while p.poll() is None and not out.exists() and time.monotonic() < deadline:
        time.sleep(0.001)
    p.send_signal(signal.SIGTERM)
    said, _ = p.communicate(timeout=60)
    assert p.returncode == 143
    left = sorted(f.name for f in out.iterdir()) if out.exists() else []
    assert left in ([], ["results.partial.jsonl"]), left  # a log only with the rows it holds
    # what it says is what it left: a log to resume from, or nothing
    last = (said.decode().strip().splitlines() or [""])[-1]
    if left:
        rows = [r for r in (out / "results.partial.jsonl").read_text().splitlines() if r.strip()]
        assert last.startswith(f"sweep: stopped; {len(rows)} design") and "--resume" in last, last
    else:  # (or stopped before the sweep began, when it prints nothing)
        assert last in ("", "sweep: stopped before any design was built: nothing to resume"), last


def test_a_file_size_limit_on_a_single_file_leaves_no_folder_it_made(tmp_path):
    import resource
    import signal

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))

    r = subprocess.run(
        [sys.executable, "-m", "rjcad", "spring", "--stiffness", "5.2", "--plot", "new/deeper/s.png"],
        cwd=tmp_path,
        capture_output=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        preexec_fn=limit,
        timeout=120,
    )
    assert r.returncode == 2 and b"s.png" in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr
    assert not (tmp_path / "new").exists()
