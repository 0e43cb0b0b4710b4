"""Output places that cannot be written, and output sets that are whole or not there (#17).

Each failure is one error line naming the path and the system's reason (exit 2 through the CLI), and the
output directory keeps an earlier run's files exactly: names, bytes and mtimes (and its own mtime).
"""

from __future__ import annotations

import errno
import os
import pickle
import subprocess
import sys
from pathlib import Path

import pytest

from rjcad.errors import RjcadError
from rjcad.io import outputs
from rjcad.io.config import write_atomic
from rjcad.io.outputs import OutputError, check_writable, output_set, write_set

OLD = {"joint.stl": b"old stl", "joint.json": b'{"joint_stiffness_nmm_per_rad": 5.2}\n', "joint.png": b"old png"}
NEW = {"joint.stl": b"new stl" * 100, "joint.3mf": b"new 3mf", "joint.json": b'{"k": 8}\n'}


def snapshot(d: Path) -> dict:
    """Every entry under ``d`` (hidden ones too): bytes and mtime of files, and ``d``'s own mtime."""
    if not d.exists():
        return {}
    files = {
        p.relative_to(d).as_posix(): (p.read_bytes() if p.is_file() else "dir", p.stat().st_mtime_ns)
        for p in sorted(d.rglob("*"))
    }
    return {".": d.stat().st_mtime_ns, **files}


@pytest.fixture
def earlier(tmp_path) -> Path:
    """An output directory holding an earlier run (mtimes in the past) and a file of the user's."""
    out = tmp_path / "out"
    out.mkdir()
    for name, data in {**OLD, "notes.txt": b"mine"}.items():
        (out / name).write_bytes(data)
        os.utime(out / name, ns=(1_600_000_000_000_000_000, 1_600_000_000_000_000_000))
    os.utime(out, ns=(1_600_000_000_000_000_000, 1_600_000_000_000_000_000))
    return out


def test_a_set_replaces_the_earlier_one_and_leaves_nothing_else(earlier):
    paths = write_set(earlier, NEW, remove=("joint.png",))
    assert paths == [earlier / n for n in NEW]
    assert {p.name: p.read_bytes() for p in earlier.iterdir()} == {**NEW, "notes.txt": b"mine"}


@pytest.mark.parametrize("k", range(3))
def test_a_full_disk_while_staging_leaves_the_earlier_run_exactly(earlier, monkeypatch, k):
    before = snapshot(earlier)
    real, calls = Path.write_bytes, []

    def full(self, data):
        calls.append(self.name)
        if len(calls) > k:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full)
    with pytest.raises(OutputError) as e:
        write_set(earlier, NEW)
    assert str(e.value) == f"{earlier / list(NEW)[k]}: cannot write: No space left on device"
    assert snapshot(earlier) == before


def fail_rename(monkeypatch, k: int) -> None:
    """Make the (k+1)-th ``os.replace`` of rjcad.io.outputs fail with EIO; the others go through."""
    real, calls = os.replace, []

    def flaky(src, dst):
        calls.append(dst)
        if len(calls) == k + 1:
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        return real(src, dst)

    monkeypatch.setattr(outputs.os, "replace", flaky)


@pytest.mark.parametrize("k", range(6))
def test_a_rename_failing_half_way_puts_the_earlier_files_back(earlier, monkeypatch, k):
    """The commit sets aside the files it replaces (2 + joint.png removed), then renames the 3 new ones in."""
    before = snapshot(earlier)
    inodes = {p.name: p.stat().st_ino for p in earlier.iterdir()}
    fail_rename(monkeypatch, k)
    with pytest.raises(OutputError, match="cannot write: Input/output error"):
        write_set(earlier, NEW, remove=("joint.png",))
    assert snapshot(earlier) == before
    assert {p.name: p.stat().st_ino for p in earlier.iterdir()} == inodes  # the same files, not copies


def test_an_interrupt_while_staging_changes_nothing(earlier):
    before = snapshot(earlier)
    with pytest.raises(KeyboardInterrupt), output_set(earlier) as stage:
        (stage / "joint.stl").write_bytes(b"half")
        raise KeyboardInterrupt
    assert snapshot(earlier) == before


def test_a_failed_set_leaves_no_new_directory(tmp_path, monkeypatch):
    def full(self, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Path, "write_bytes", full)
    with pytest.raises(OutputError):
        write_set(tmp_path / "a" / "b" / "c", NEW)
    assert list(tmp_path.iterdir()) == []


def test_a_file_in_the_way_is_named(tmp_path):
    (tmp_path / "f").write_text("x")
    for call in (
        lambda: write_set(tmp_path / "f" / "out", NEW),
        lambda: check_writable(tmp_path / "f" / "out"),
        lambda: write_atomic(tmp_path / "f" / "out" / "a.png", b"png"),
    ):
        with pytest.raises(OutputError, match=f"cannot write: {tmp_path / 'f'} is not a directory"):
            call()
    with pytest.raises(OutputError, match="f: cannot write: not a directory"):
        write_set(tmp_path / "f", NEW)
    assert [p.name for p in tmp_path.iterdir()] == ["f"] and (tmp_path / "f").read_text() == "x"


def test_a_directory_in_the_way_of_a_member_changes_nothing(earlier):
    (earlier / "joint.3mf").mkdir()
    before = snapshot(earlier)
    with pytest.raises(OutputError, match=r"joint\.3mf: cannot write: Is a directory"):
        write_set(earlier, NEW)
    assert snapshot(earlier) == before


FOLDER = {"joint.stl": b"new stl", "mjcf/finger.xml": "<mujoco/>", "mjcf/meshes/base.stl": b"stl"}


def test_a_folder_of_the_set_replaces_the_earlier_folder_whole(earlier):
    """Members under a folder (an MJCF's model, scene and meshes/) replace that folder whole; a ``remove`` name
    ending in "/" removes a folder this run does not write."""
    (earlier / "mjcf" / "meshes").mkdir(parents=True)
    (earlier / "mjcf" / "meshes" / "gone.stl").write_bytes(b"old")
    write_set(earlier, FOLDER)
    assert sorted(p.relative_to(earlier).as_posix() for p in (earlier / "mjcf").rglob("*")) == [
        "mjcf/finger.xml",
        "mjcf/meshes",
        "mjcf/meshes/base.stl",
    ]
    write_set(earlier, NEW, remove=("mjcf/", "joint.png"))
    assert sorted(p.name for p in earlier.iterdir()) == sorted([*NEW, "notes.txt"])
    with pytest.raises(ValueError, match="relative path"):
        write_set(earlier, {"mjcf/../x": b""})


@pytest.mark.parametrize("k", range(4))
def test_a_rename_failing_half_way_puts_an_earlier_folder_back(earlier, monkeypatch, k):
    (earlier / "mjcf").mkdir()
    (earlier / "mjcf" / "finger.xml").write_text("old")
    before = snapshot(earlier)
    fail_rename(monkeypatch, k)
    with pytest.raises(OutputError, match="cannot write: Input/output error"):
        write_set(earlier, FOLDER)
    assert snapshot(earlier) == before


def test_output_error_is_a_user_error_and_crosses_processes(tmp_path):
    e = OutputError(tmp_path / "x", "Read-only file system")
    assert isinstance(e, RjcadError) and str(e) == f"{tmp_path / 'x'}: cannot write: Read-only file system"
    back = pickle.loads(pickle.dumps(e))
    assert str(back) == str(e) and back.path == e.path


# ---------------------------------------------------------------- real read-only and full filesystems


def _mount(*args) -> bool:
    return os.geteuid() == 0 and subprocess.run(["mount", *args], capture_output=True).returncode == 0


@pytest.fixture
def read_only(earlier):
    """``earlier`` made read-only: by its mode for a user, by a read-only tmpfs for root (else skip)."""
    if os.geteuid() != 0:
        earlier.chmod(0o555)
        yield earlier, "Permission denied"
        earlier.chmod(0o755)
        return
    files = {p.name: p.read_bytes() for p in earlier.iterdir()}
    if not _mount("-t", "tmpfs", "-o", "size=1m", "tmpfs", str(earlier)):
        pytest.skip("cannot mount a tmpfs here")
    try:
        for name, data in files.items():
            (earlier / name).write_bytes(data)
        assert _mount("-o", "remount,ro", str(earlier))
        yield earlier, "Read-only file system"
    finally:
        subprocess.run(["umount", str(earlier)], check=True)


def test_a_read_only_directory_is_refused_in_one_line_and_left_alone(read_only, tmp_path):
    out, reason = read_only
    before = snapshot(out)
    for call in (
        lambda: write_set(out, NEW),
        lambda: check_writable(out),
        lambda: write_atomic(out / "a.png", b"x"),
        lambda: check_writable(out / "new" / "sub"),
        lambda: write_set(out / "new", NEW),
    ):
        with pytest.raises(OutputError, match=f"cannot write: {reason}$"):
            call()
    assert snapshot(out) == before


@pytest.fixture
def tiny_fs(tmp_path):
    """A 200 KiB tmpfs (root only)."""
    d = tmp_path / "tiny"
    d.mkdir()
    if not _mount("-t", "tmpfs", "-o", "size=200k", "tmpfs", str(d)):
        pytest.skip("needs root to mount a tmpfs")
    yield d
    subprocess.run(["umount", str(d)], check=True)


def test_a_really_full_disk_leaves_the_earlier_set(tiny_fs):
    out = tiny_fs / "j"
    write_set(out, {"joint.stl": b"a" * 60_000, "joint.json": b"{}\n"})
    before = snapshot(out)
    with pytest.raises(OutputError, match=r"j/joint.stl: cannot write: No space left on device$"):
        write_set(out, {"joint.json": b'{"k": 8}\n', "joint.stl": b"b" * 300_000})
    assert snapshot(out) == before


# ---------------------------------------------------------------- every command that writes, through the CLI


@pytest.fixture(scope="module")
def campaign(tmp_path_factory) -> Path:
    from rjcad.identify.bench import write_campaign

    d = tmp_path_factory.mktemp("campaign")
    write_campaign(d, samples=300)
    return d / "campaign.toml"


#: Every command that writes, with its output place (``{o}``: a directory, or the directory of a file).
WRITERS = {
    "joint": ["joint", "--out", "{o}"],
    "finger": ["finger", "--out", "{o}"],
    "identify --json": ["identify", "{campaign}", "--json", "{o}/id.json"],
    "identify --report": ["identify", "{campaign}", "--report", "{o}"],
    "sweep": ["sweep", "{root}/templates/sweep_stiffness.toml", "--out", "{o}"],
    "bench": ["bench", "--out", "{o}", "--samples", "300"],
    "spring --plot": ["spring", "--stiffness", "5.2", "--plot", "{o}/spring.png"],
    "simulate joint --plot": ["simulate", "joint", "--rotation", "90", "--plot", "{o}/loop.png"],
    "simulate finger --plot": ["simulate", "finger", "--plot", "{o}/closure.png"],
    "finger-design": ["finger-design", "--target", "65,50,50", "--stroke", "20", "--out", "{o}"],
    "finger-design --out FILE": ["finger-design", "--target", "65,50,50", "--stroke", "20", "--out", "{o}/f.toml"],
    "paper-finger": ["paper-finger", "--out", "{o}"],
    "life --plot": ["life", "--plot", "{o}/life.png"],
    "life --doc": ["life", "--doc", "{o}", "--sims", "10"],
}


@pytest.mark.parametrize("command", list(WRITERS))
def test_every_writer_refuses_a_place_under_a_file_in_one_line(command, cli, tmp_path, campaign, root):
    (tmp_path / "f").write_text("x")
    args = [a.format(o=tmp_path / "f" / "out", campaign=campaign, root=root) for a in WRITERS[command]]
    code, _out, err = cli(args)
    assert code == 2, err
    if "FILE" in command or command == "identify --json":  # a former spelling: its note comes first
        note, err = err.split("\n", 1)
        assert note.startswith("rjcad: note: --") and " is deprecated; use " in note
    assert err.count("\n") == 1 and err.startswith("rjcad: error: ") and "Traceback" not in err
    assert f"cannot write: {tmp_path / 'f'} is not a directory" in err
    assert [p.name for p in tmp_path.iterdir()] == ["f"]


def _fake_joint(monkeypatch, size: int = 1000):
    """``rjcad joint`` without CAD: the builder gives a manifest, the renderer five files of ``size`` bytes."""
    import types

    import rjcad.cad.build as cb

    def build(p, cad=None, progress=None):
        m = {"joint_stiffness_nmm_per_rad": p.stiffness}
        return types.SimpleNamespace(manifest=m)

    def render(b, name="joint", png=True, progress=None):
        k = b.manifest["joint_stiffness_nmm_per_rad"]
        files = {f"joint.{e}": f"{e} K={k} ".encode() * (size // 8) for e in ("stl", "3mf", "step", "png")}
        files["joint.json"] = f'{{"joint_stiffness_nmm_per_rad": {k}}}\n'
        return files if png else {n: d for n, d in files.items() if n != "joint.png"}

    monkeypatch.setattr(cb, "build", build)
    monkeypatch.setattr(cb, "render_files", render)
    monkeypatch.setattr("rjcad.cli.build.print_joint", lambda m: None)


def test_joint_on_a_full_disk_keeps_the_earlier_set_whole(cli, tmp_path, monkeypatch):
    """The issue's case: an earlier joint (5.2 N·mm/rad); `--stiffness 8` fails on the disk: no new STL/3MF
    beside the old manifest."""
    _fake_joint(monkeypatch)
    out = tmp_path / "j"
    assert cli("joint", "--out", out).code == 0
    before = snapshot(out)
    real, n = Path.write_bytes, []

    def full(self, data):
        n.append(1)
        if len(n) > 2:  # the third file of the set
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full)
    code, _, err = cli("joint", "--out", out, "--stiffness", "8")
    assert code == 2 and err.count("\n") == 1
    assert err.startswith(f"rjcad: error: {out}/joint.") and err.endswith(": cannot write: No space left on device\n")
    assert snapshot(out) == before
    monkeypatch.setattr(Path, "write_bytes", real)
    assert cli("joint", "--out", out, "--stiffness", "8", "--no-png").code == 0
    assert sorted(p.name for p in out.iterdir()) == ["joint.3mf", "joint.json", "joint.step", "joint.stl"]
    assert "8" in (out / "joint.json").read_text() and b"K=8" in (out / "joint.stl").read_bytes()


def test_the_real_joint_on_a_full_tmpfs_keeps_the_earlier_set(tiny_fs, tmp_path):
    """The issue's case end to end (CAD, root only): a 2.5 MB tmpfs holds one joint's set, not two."""
    subprocess.run(["umount", str(tiny_fs)], check=True)
    assert _mount("-t", "tmpfs", "-o", "size=2500k", "tmpfs", str(tiny_fs))
    out = tiny_fs / "j"
    run = [sys.executable, "-m", "rjcad", "joint", "--out", str(out)]
    assert subprocess.run(run, capture_output=True).returncode == 0
    before = snapshot(out)
    r = subprocess.run(run + ["--stiffness", "8"], capture_output=True, text=True)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.startswith(f"rjcad: error: {out}/joint.") and r.stderr.count("\n") == 1
    assert r.stderr.endswith("cannot write: No space left on device\n")
    assert snapshot(out) == before


FOLDER_OLD = {"m.urdf": b"old urdf", "meshes/a.stl": b"old a", "meshes/gone.stl": b"old gone"}
FOLDER_NEW = {"m.urdf": b"new urdf", "meshes/a.stl": b"new a", "meshes/b.stl": b"new b"}


@pytest.fixture
def earlier_folder(tmp_path) -> Path:
    """An output directory holding an earlier set with a folder (mtimes in the past) and a file of the user's."""
    out = tmp_path / "out"
    write_set(out, FOLDER_OLD)
    (out / "notes.txt").write_bytes(b"mine")
    for p in sorted(out.rglob("*"), reverse=True):
        os.utime(p, ns=(1_600_000_000_000_000_000, 1_600_000_000_000_000_000))
    os.utime(out, ns=(1_600_000_000_000_000_000, 1_600_000_000_000_000_000))
    return out


def test_a_folder_member_is_replaced_whole(earlier_folder):
    write_set(earlier_folder, FOLDER_NEW)
    files = {p.relative_to(earlier_folder).as_posix(): p.read_bytes() for p in earlier_folder.rglob("*") if p.is_file()}
    assert files == {**FOLDER_NEW, "notes.txt": b"mine"}  # meshes/gone.stl went with its set


@pytest.mark.parametrize("k", range(4))
def test_a_rename_failing_half_way_puts_the_earlier_folder_back(earlier_folder, monkeypatch, k):
    """The commit sets aside m.urdf and meshes/, then renames the new ones in; a failure puts the old ones back."""
    before = snapshot(earlier_folder)
    fail_rename(monkeypatch, k)
    with pytest.raises(OutputError, match="cannot write: Input/output error"):
        write_set(earlier_folder, FOLDER_NEW)
    assert snapshot(earlier_folder) == before


@pytest.mark.parametrize("name", ["../x.stl", "meshes/../x.stl", "meshes/.hidden", "/abs.stl", "meshes//a.stl"])
def test_a_member_name_must_stay_in_its_set(tmp_path, name):
    with pytest.raises(ValueError, match="plain file name"):
        write_set(tmp_path / "out", {name: b"x"})
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "args",
    [
        ["joint", "--out", "{f}/out"],
        ["spring", "--stiffness", "5.2", "--plot", "{f}/s.png"],
        ["life", "--plot", "{f}/l.png"],
        ["simulate", "joint", "--plot", "{f}/j.png"],
        ["check", "{mesh}", "--junit", "{f}/r.xml"],
    ],
)
def test_an_output_place_under_a_file_is_refused_before_any_work(args, cli, tmp_path, monkeypatch):
    """--out and the output files (--plot, --junit) are refused as the option is read, naming the option and its
    value: the command's work (a CAD build, a spring design, a check) is never started."""
    import rjcad.cad.build
    import rjcad.check

    def never(*a, **k):
        raise AssertionError("the command started its work")

    for module, name in ((rjcad.cad.build, "write_joint"), (rjcad.check, "run_checks")):
        monkeypatch.setattr(module, name, never)
    (tmp_path / "f").write_text("x")
    mesh = tmp_path / "m.stl"
    mesh.write_text("solid x\nendsolid x\n")
    argv = [a.format(f=tmp_path / "f", mesh=mesh) for a in args]
    code, _out, err = cli(argv)
    option = next(a for a in argv if a.startswith("--") and "{f}" in args[argv.index(a) + 1])
    assert code == 2 and err.count("\n") == 1, err
    assert err.startswith(f"rjcad: error: {option} {tmp_path / 'f'}/") and "not a directory" in err, err
