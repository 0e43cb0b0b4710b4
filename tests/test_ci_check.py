"""`rjcad check` in CI (docs/ci.md): the documented workflow's commands on the default finger, read back by a
JUnit parser; the repository's pre-commit hooks run by pre-commit in a test repository."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
from pathlib import Path
from urllib.parse import urlparse

import pytest
from junitparser import Failure, JUnitXml

CHECKS = ["watertight", "manifold", "bodies", "clearance", "motion", "min_feature", "bed", "overhang", "slicer"]
#: Workflow commands the test does not run: installing rjcad and PrusaSlicer (this environment has both or not).
INSTALLS = ("pip ", "sudo apt-get ", "apt-get ")


def workflow(root: Path) -> dict:
    """The GitHub Actions workflow of docs/ci.md, parsed."""
    yaml = pytest.importorskip("yaml")
    text = (root / "docs" / "ci.md").read_text()
    section = re.search(r"^## A GitHub Actions workflow\n(.*?)(?=^## |\Z)", text, re.S | re.M).group(1)
    (block,) = re.findall(r"```yaml\n(.*?)```", section, re.S)
    return yaml.safe_load(block)


def run_lines(flow: dict) -> list[str]:
    return [line.strip() for s in flow["jobs"]["check"]["steps"] for line in s.get("run", "").splitlines() if line]


def env_with(root: Path, **extra) -> dict:
    """This environment with this tree's rjcad first on the import path."""
    env = dict(os.environ, **extra)
    env["PYTHONPATH"] = os.pathsep.join([str(root), *filter(None, [os.environ.get("PYTHONPATH")])])
    return env


def test_the_documented_workflow_checks_the_default_finger_one_case_per_check(tmp_path, root):
    """The acceptance: `rjcad check --junit` on the default finger, one case per check, as docs/ci.md runs it."""
    flow = workflow(root)
    lines = run_lines(flow)
    commands = [shlex.split(line.split(" #")[0]) for line in lines if not line.startswith(INSTALLS)]
    assert all(c[0] == "rjcad" for c in commands), lines  # every other command is one the test runs
    assert [c[1] for c in commands] == ["finger", "check"] and "--junit" in commands[1]
    (tmp_path / "templates").mkdir()
    shutil.copy(root / "templates" / "finger.toml", tmp_path / "templates")
    for c in commands:
        done = subprocess.run(
            [sys.executable, "-m", "rjcad", *c[1:]],
            cwd=tmp_path,
            env=env_with(root),
            capture_output=True,
            text=True,
            timeout=900,
        )
        assert done.returncode == 0, (c, done.stdout[-3000:], done.stderr)
    report = tmp_path / commands[1][commands[1].index("--junit") + 1]
    uploaded = [s for s in flow["jobs"]["check"]["steps"] if "upload-artifact" in s.get("uses", "")]
    assert uploaded and uploaded[0]["with"]["path"] == report.name
    xml = JUnitXml.fromfile(str(report))
    (suite,) = list(xml)
    assert suite.name == "out/finger/finger.3mf" and suite.tests == len(CHECKS) and suite.failures == 0
    by = {c.name.split(" (")[0]: c for c in suite}
    assert list(by) == CHECKS and all(c.classname == "rjcad.check.finger_3mf" for c in suite)
    assert suite.skipped == (0 if shutil.which("prusa-slicer") else 1)
    assert not any(isinstance(r, Failure) for c in suite for r in c.result)
    assert "base" in by["bodies"].system_out and "distal" in by["bodies"].system_out
    assert by["min_feature"].name.startswith("min_feature (worst: ")


# ---------------------------------------------------------------- the pre-commit hooks


def test_the_hooks_offered_and_the_files_they_take(root):
    yaml = pytest.importorskip("yaml")
    hooks = {h["id"]: h for h in yaml.safe_load((root / ".pre-commit-hooks.yaml").read_text())}
    assert list(hooks) == ["rjcad-check", "rjcad-check-system"]
    assert [h["language"] for h in hooks.values()] == ["python", "system"]
    for h in hooks.values():
        assert h["entry"] == "rjcad check" and h["pass_filenames"] is True and h["require_serial"] is True
        files = re.compile(h["files"])
        assert all(files.search(f) for f in ("a.stl", "dir/b.3mf", "C.STL", "d.3MF"))
        assert not any(files.search(f) for f in ("a.step", "a.stl.json", "stl", "a.glb"))
    text = (root / "docs" / "ci.md").read_text()
    assert all(f"`{i}`" in text for i in hooks)


def meshes() -> tuple[bytes, bytes]:
    """A mesh that passes every check it gets without a manifest, and one with a 0.2 mm wall (min_feature fails)."""
    from test_check_mutations import part, thin_wall
    from test_check_print import printable_pair

    from rjcad.cad.mesh_export import stl_bytes

    return stl_bytes(list(printable_pair().values())), stl_bytes(list(thin_wall(part())[0].values()))


def git(cwd: Path, *args: str) -> str:
    return subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True, text=True).stdout.strip()


def hook_repository(tmp_path: Path, root: Path, hook: str) -> Path:
    """A git repository whose .pre-commit-config.yaml takes ``hook`` from this tree's HEAD, holding a sound mesh."""
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    pytest.importorskip("pre_commit")
    try:
        rev = git(root, "rev-parse", "HEAD")
    except subprocess.CalledProcessError:
        pytest.skip("the tree is not a git checkout: pre-commit clones a hook repository")
    if "id: " + hook not in git(root, "show", "HEAD:.pre-commit-hooks.yaml"):
        pytest.fail(f"HEAD's .pre-commit-hooks.yaml offers no {hook} (commit it: pre-commit clones HEAD)")
    repo = tmp_path / "repo"
    repo.mkdir()
    git(repo, "init", "-q")
    git(repo, "config", "user.email", "test@example.com")
    git(repo, "config", "user.name", "test")
    config = f"repos:\n  - repo: {root}\n    rev: {rev}\n    hooks:\n      - id: {hook}\n"
    (repo / ".pre-commit-config.yaml").write_text(config)
    (repo / "notes.txt").write_text("not a mesh\n")
    good, _ = meshes()
    (repo / "good.stl").write_bytes(good)
    git(repo, "add", "-A")
    return repo


def pre_commit(repo: Path, env: dict, timeout: float) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "pre_commit", "run", "--all-files", "--verbose"],
        cwd=repo,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def pass_then_fail(repo: Path, env: dict, name: str, timeout: float) -> None:
    """The hook passes the sound mesh (and ignores notes.txt), then fails the commit when a bad mesh is added."""
    done = pre_commit(repo, env, timeout)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert re.search(rf"{re.escape(name)}\.+Passed", done.stdout), done.stdout
    assert "good.stl" not in done.stdout and "PASSED" in done.stdout  # one mesh: the table, as ever
    _, bad = meshes()
    (repo / "bad.stl").write_bytes(bad)
    git(repo, "add", "-A")
    done = pre_commit(repo, env, timeout)
    assert done.returncode == 1, done.stdout[-4000:]
    assert re.search(rf"{re.escape(name)}\.+Failed", done.stdout) and "exit code: 1" in done.stdout
    assert "FAILED: 1 of 2 meshes (bad.stl)" in done.stdout and "notes.txt" not in done.stdout


def test_the_system_hook_runs_in_a_test_repository(tmp_path, root):
    """`rjcad-check-system` (language: system) with this interpreter's rjcad as `rjcad` on PATH."""
    repo = hook_repository(tmp_path, root, "rjcad-check-system")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    shim = bin_dir / "rjcad"
    shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m rjcad "$@"\n')
    shim.chmod(0o755)
    env = env_with(root, PRE_COMMIT_HOME=str(tmp_path / "cache"), PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    pass_then_fail(repo, env, "rjcad check (installed rjcad)", timeout=600)


def _index_reachable() -> bool:
    """Whether the package index answers (pre-commit installs rjcad and its dependencies from it)."""
    host = urlparse(os.environ.get("PIP_INDEX_URL", "https://pypi.org/simple")).hostname or "pypi.org"
    try:
        socket.create_connection((host, 443), timeout=5).close()
    except OSError:
        return False
    return True


#: Installer tools in this environment's site-packages that the hook's environment keeps its own of.
TOOLS = ("pip", "setuptools", "wheel", "_distutils_hack", "pkg_resources", "virtualenv")


def dependencies_only(folder: Path) -> Path:
    """``folder`` holding links to every distribution installed here but rjcad (and the installer's own tools):
    on the hook's PYTHONPATH, pip finds rjcad's dependencies installed and installs rjcad alone from HEAD. No .pth
    file is linked (Python reads them only in site directories): this tree's editable rjcad stays out."""
    import sysconfig

    folder.mkdir()
    site = Path(sysconfig.get_paths()["purelib"])
    for entry in site.iterdir():
        name = entry.name.split("-")[0].split(".")[0].lower()
        if name in ("rjcad", "__editable__", "__pycache__") or name in TOOLS or entry.suffix == ".pth":
            continue
        (folder / entry.name).symlink_to(entry)
    return folder


@pytest.mark.slow
def test_the_python_hook_installs_rjcad_and_runs(tmp_path, root):
    """`rjcad-check` (language: python): pre-commit clones this tree's HEAD, makes the hook its own environment and
    pip-installs rjcad there from the clone (its build backend from the package index), then checks the meshes with
    that environment's `rjcad`. rjcad's dependencies come from this environment (pip finds them installed on the
    hook's PYTHONPATH), not from the index: installing them, 1.6 GB, took 30 s of this test's 40 and proved that the
    index serves them, which setting up this environment proves (`pip install -e '.[test]'`)."""
    if not _index_reachable():
        pytest.skip("no network: the hook's pip installs rjcad's build backend from the package index")
    repo = hook_repository(tmp_path, root, "rjcad-check")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # the hook's own rjcad, nothing of ours
    env["PYTHONPATH"] = str(dependencies_only(tmp_path / "dependencies"))
    cache = tmp_path / "cache"
    try:
        pass_then_fail(repo, dict(env, PRE_COMMIT_HOME=str(cache)), "rjcad check", timeout=1800)
        # the rjcad that ran is the one pip installed into the hook's environment, with its command
        (hook_env,) = cache.glob("repo*/py_env-*")
        assert list(hook_env.glob("lib/python*/site-packages/rjcad/check/__init__.py")), "rjcad not installed"
        assert (hook_env / "bin" / "rjcad").is_file()
    finally:
        shutil.rmtree(cache, ignore_errors=True)
