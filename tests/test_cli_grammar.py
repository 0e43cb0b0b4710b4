"""The command line's grammar (docs/cli.md): former spellings that still work with one note line, `--out` a
folder, `--json` on stdout, a campaign's folder, shell completion of the profiles, a closed pipe, and the
progress line: on a terminal only, never with `--quiet`."""

from __future__ import annotations

import json
import os
import pty
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def note(old: str, new: str) -> str:
    return f"rjcad: note: {old} is deprecated; use {new} (the old spelling goes in the next release)\n"


# ------------------------------------------------------------------------------------------ former spellings


def test_pulley_radius_is_the_tendon_moment_arm(cli):
    """`simulate joint --pulley-radius` (former) gives what `--tendon-moment-arm` gives, with the note."""
    base = ("simulate", "joint", "--drive", "tendon", "--rotation", "60", "--normal-load", "0", "--json")
    new = cli(*base, "--tendon-moment-arm", "8")
    old = cli(*base, "--pulley-radius", "8")
    default = cli(*base)
    assert new.code == old.code == default.code == 0
    assert new.err == default.err == "" and old.err == note("--pulley-radius", "--tendon-moment-arm")
    assert old.out == new.out != default.out
    assert json.loads(default.out) == json.loads(cli(*base, "--tendon-moment-arm", "6").out)  # default 6 mm


def test_a_former_and_a_new_name_together_are_one_error(cli):
    r = cli("simulate", "joint", "--rotation", "60", "--pulley-radius", "8", "--tendon-moment-arm", "8")
    assert r.code == 2 and r.err.count("\n") == 1 and "--tendon-moment-arm" in r.err and "--pulley-radius" in r.err


def test_a_bad_value_of_a_former_name_names_it(cli):
    r = cli("simulate", "joint", "--rotation", "60", "--pulley-radius", "nan")
    lines = r.err.splitlines()
    assert r.code == 2 and lines[0] == note("--pulley-radius", "--tendon-moment-arm").strip()
    assert len(lines) == 2 and lines[1].startswith("rjcad: error: --pulley-radius")


def test_finger_design_out_is_a_folder_and_the_former_file_still_works(cli, tmp_path):
    args = ("finger-design", "--target", "65,50,50", "--stroke", "25")
    new = cli(*args, "--out", tmp_path / "new")
    old = cli(*args, "--out", tmp_path / "old.toml")
    assert new.code == old.code == 0, new.err + old.err
    assert new.err == "" and old.err == note("--out FILE.toml", "--out DIR (it writes DIR/finger.toml)")
    assert (tmp_path / "new" / "finger.toml").read_bytes() == (tmp_path / "old.toml").read_bytes()
    assert new.out.startswith(f"wrote {tmp_path / 'new' / 'finger.toml'}\n")
    (tmp_path / "afile").write_text("x")
    r = cli(*args, "--out", tmp_path / "afile")
    assert r.code == 2 and r.err.count("\n") == 1 and "afile" in r.err and "is a file" in r.err
    assert (tmp_path / "afile").read_text() == "x"


@pytest.fixture
def viewable(tmp_path, root):
    """A finger manifest with a GLB beside it (a box per body): what `rjcad view` reads."""
    import trimesh

    from rjcad.cad.mesh_export import glb_bytes

    d = tmp_path / "built"
    d.mkdir()
    man = json.loads((root / "tests" / "data" / "manifest_v0_finger.json").read_text())
    (d / "finger.json").write_text(json.dumps(man))
    boxes = {b["name"]: trimesh.creation.box((10, 10, 10)) for b in man["bodies"]}
    (d / "finger.glb").write_bytes(glb_bytes(boxes))
    return d / "finger.json"


def test_view_out_is_a_folder_and_the_former_file_still_works(cli, tmp_path, viewable):
    pytest.importorskip("rjcad.view").vendored_three()
    new = cli("view", viewable, "--out", tmp_path / "pages", "--steps", "10")
    old = cli("view", viewable, "--out", tmp_path / "page.html", "--steps", "10")
    beside = cli("view", viewable, "--steps", "10")
    assert new.code == old.code == beside.code == 0, new.err + old.err + beside.err
    assert new.err == beside.err == ""
    assert old.err == note("--out FILE.html", "--out DIR (it writes DIR/finger.html)")
    page = (tmp_path / "pages" / "finger.html").read_bytes()
    assert page == (tmp_path / "page.html").read_bytes() == viewable.with_suffix(".html").read_bytes()
    (tmp_path / "afile").write_text("x")
    r = cli("view", viewable, "--out", tmp_path / "afile")
    assert r.code == 2 and r.err.count("\n") == 1 and r.err.startswith("rjcad: error: ") and "afile" in r.err


def test_identify_takes_a_campaign_folder(cli, tmp_path):
    from rjcad.identify.bench import write_campaign

    write_campaign(tmp_path / "c", samples=300)
    by_file = cli("identify", tmp_path / "c" / "campaign.toml", "--json")
    by_folder = cli("identify", tmp_path / "c", "--json")
    assert by_file.code == by_folder.code == 0 and by_file.out == by_folder.out and by_folder.err == ""
    (tmp_path / "empty").mkdir()
    r = cli("identify", tmp_path / "empty")
    assert r.code == 2 and r.err.count("\n") == 1 and "no campaign.toml" in r.err


# ------------------------------------------------------------------------------------------ completion


def _complete(monkeypatch, capsys, words: str) -> list[str]:
    """What bash completion offers for the last word of ``words`` (click's bash_complete protocol)."""
    from rjcad.cli import main

    parts = words.split(" ")
    monkeypatch.setenv("_RJCAD_COMPLETE", "bash_complete")
    monkeypatch.setenv("COMP_WORDS", words)
    monkeypatch.setenv("COMP_CWORD", str(len(parts) - 1))
    with pytest.raises(SystemExit) as e:
        main([])
    assert e.value.code == 0
    return [line.split(",", 1)[1] for line in capsys.readouterr().out.splitlines() if line]


@pytest.mark.parametrize(
    "words, kind",
    [
        ("rjcad spring --material ", "materials"),
        ("rjcad joint --printer ", "printers"),
        ("rjcad finger --material ", "materials"),
        ("rjcad finger-design --printer ", "printers"),
        ("rjcad check m.stl --printer ", "printers"),
    ],
)
def test_material_and_printer_complete_from_the_profiles(monkeypatch, capsys, tmp_path, words, kind):
    from rjcad.materials import MATERIALS, PRINTERS

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))  # a profile of the user's own is offered too
    mine = tmp_path / "rjcad" / kind / "my-own.toml"
    mine.parent.mkdir(parents=True)
    mine.write_text(
        'name = "mine"\nnozzle_mm = 0.4\nlayer_mm = 0.2\nbed_mm = [200, 200, 200]\nsoluble_support = false\n'
        if kind == "printers"
        else 'name = "mine"\nyoungs_modulus_mpa = 2000\nyield_mpa = 40\ndensity_g_cm3 = 1.2\n'
    )
    offered = _complete(monkeypatch, capsys, words)
    assert set(offered) == set(PRINTERS if kind == "printers" else MATERIALS) | {"my-own"}
    some = next(iter(PRINTERS if kind == "printers" else MATERIALS))
    assert _complete(monkeypatch, capsys, words + some[:3]) == [k for k in offered if k.startswith(some[:3])]


def test_completion_script_for_bash(monkeypatch, capsys):
    """What docs/cli.md tells bash users to eval: click's script for `rjcad`."""
    from rjcad.cli import main

    monkeypatch.setenv("_RJCAD_COMPLETE", "bash_source")
    with pytest.raises(SystemExit):
        main([])
    out = capsys.readouterr().out
    assert "_RJCAD_COMPLETE=bash_complete" in out and "complete " in out


# ------------------------------------------------------------------------------------------ a closed pipe


def test_a_closed_pipe_exits_quietly_with_0():
    """`rjcad spring --stiffness 5.2 | head -1`: head has its line, rjcad exits 0 with nothing on stderr."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    cmd = f"'{sys.executable}' -m rjcad spring --stiffness 5.2 | head -1; echo \"exit ${{PIPESTATUS[0]}}\" >&2"
    r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, env=env, cwd=ROOT, timeout=120)
    assert r.stdout.startswith("Spiral spring for a 5.2 N·mm/rad joint") and r.stdout.count("\n") == 1
    assert r.stderr == "exit 0\n"
    # the reader gone before the first byte: the same
    p = subprocess.Popen(
        [sys.executable, "-m", "rjcad", "life", "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
        cwd=ROOT,
    )
    p.stdout.close()
    assert p.wait(timeout=120) == 0 and p.stderr.read() == b""


# ------------------------------------------------------------------------------------------ progress


def _run_on_terminal(args: list[str], cwd: Path, timeout: float = 120) -> tuple[int, str, str]:
    """Run `rjcad ARGS` with stderr on a pseudo-terminal and stdout on a pipe: (exit code, stdout, what the
    terminal got)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    env["COLUMNS"] = "100"
    master, slave = pty.openpty()
    p = subprocess.Popen([sys.executable, "-m", "rjcad", *args], stdout=subprocess.PIPE, stderr=slave, env=env, cwd=cwd)
    os.close(slave)
    seen, deadline = b"", time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the terminal's other side closed: the command exited
                break
            if not chunk:
                break
            seen += chunk
        elif p.poll() is not None:
            break
    out = p.stdout.read().decode()
    code = p.wait(timeout=30)
    os.close(master)
    return code, out, seen.decode(errors="replace")


@pytest.fixture(scope="module")
def small_campaign(tmp_path_factory) -> Path:
    from rjcad.identify.bench import write_campaign

    d = tmp_path_factory.mktemp("campaign")
    write_campaign(d, samples=300)
    return d


def test_progress_shows_on_a_terminal(small_campaign):
    code, out, tty = _run_on_terminal(["identify", str(small_campaign), "--json"], small_campaign)
    assert code == 0 and json.loads(out)["effects"] == []  # stdout: the JSON alone
    for step in ("identify: reading the campaign", "identify: fitting the design model", "identify: forward step 1"):
        assert step in tty, tty
    assert tty.endswith("\r") and "\n" not in tty  # one line, redrawn in place, then erased


def test_no_progress_with_quiet_or_off_a_terminal(small_campaign):
    code, out, tty = _run_on_terminal(["identify", str(small_campaign), "--json", "--quiet"], small_campaign)
    assert code == 0 and json.loads(out) and tty == ""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    r = subprocess.run(
        [sys.executable, "-m", "rjcad", "identify", str(small_campaign), "--json"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert r.returncode == 0 and r.stderr == "" and json.loads(r.stdout)


def test_the_progress_line_draws_steps_counts_and_time(monkeypatch):
    """The CLI's reporter through tqdm, on a stream that says it is a terminal; nothing when it is not."""
    import io

    from rjcad.cli import progress

    class Tty(io.StringIO):
        def isatty(self):
            return True

    for stream, quiet, shown in ((Tty(), False, True), (Tty(), True, False), (io.StringIO(), False, False)):
        monkeypatch.setattr(sys, "stderr", stream)
        monkeypatch.setattr(progress, "QUIET", quiet)
        with progress.progress_line("finger") as report:
            assert (report is not None) == shown
            if report:
                report("designing the springs")
                report("building link1", 1, 4)
        text = stream.getvalue()
        if shown:
            assert "finger: designing the springs" in text and "finger: building link1  1/4 |" in text
            assert text.endswith("\r")  # erased at the end
        else:
            assert text == ""
