"""The project's own plumbing: CI script, Makefile exit codes, README quick start."""

import re
import shutil
import subprocess
import sys

import pytest


def test_ci_runs_the_readme_test_command(root):
    ci = (root / ".ci" / "run").read_text()
    quick = readme_quick_start(root)
    assert len(quick) == 2, quick
    assert quick[1] in ci


def readme_quick_start(root):
    text = (root / "README.md").read_text()
    section = re.search(r"^## Quick start\n(.*?)(?=^## )", text, re.S | re.M).group(1)
    blocks = re.findall(r"```(?:sh|bash|console)?\n(.*?)```", section, re.S)
    return [
        line.strip() for b in blocks for line in b.splitlines() if line.strip() and not line.strip().startswith("#")
    ]


def test_readme_quick_start_has_exactly_two_commands(root):
    cmds = readme_quick_start(root)
    assert cmds == ["make demo", "make test"]


@pytest.mark.skipif(shutil.which("make") is None, reason="make not installed")
def test_readme_is_short_and_every_section_past_the_tour_links_into_docs(root):
    """Issue #39: README.md at most 250 lines; the sections after the tour point into docs/, to pages that exist."""
    text = (root / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 250
    sections = re.split(r"^## ", text, flags=re.M)[1:]
    titles = [s.splitlines()[0] for s in sections]
    assert titles[:2] == ["Quick start", "A five-minute tour"], titles
    for section in sections[2:]:
        links = re.findall(r"\]\((docs/[\w./-]+\.md)\)", section)
        assert links, section.splitlines()[0]
        assert all((root / link).is_file() for link in links), links


def test_make_pytest_fails_on_a_failing_test_and_accepts_an_empty_suite(tmp_path, root):
    failing = tmp_path / "failing"
    failing.mkdir()
    (failing / "test_x.py").write_text("def test_fails():\n    assert 1 == 2\n")
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "README").write_text("no tests here\n")

    def make(target_dir):
        return subprocess.run(
            [
                "make",
                "-s",
                "-C",
                str(root),
                "pytest",
                f"PY={sys.executable}",
                f"PYTEST_ARGS=-p no:cacheprovider --rootdir={target_dir} {target_dir}",
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )

    bad = make(failing)
    assert bad.returncode != 0, bad.stdout
    assert "1 failed" in bad.stdout
    nothing = make(empty)
    assert nothing.returncode == 0, nothing.stdout + nothing.stderr
    assert "collected no tests" in nothing.stdout


@pytest.mark.skipif(shutil.which("make") is None, reason="make not installed")
def test_make_demo_installs_rjcad_alone_and_make_test_the_test_extra(tmp_path, root):
    for name in ("Makefile", "pyproject.toml"):
        shutil.copy(root / name, tmp_path / name)  # a checkout without .venv: every set-up step is due

    def installs(target):
        dry = subprocess.run(["make", "-n", target], cwd=tmp_path, capture_output=True, text=True, timeout=60)
        assert dry.returncode == 0, dry.stderr
        return [line for line in dry.stdout.splitlines() if "pip install" in line and "--upgrade pip" not in line]

    assert installs("demo") == [".venv/bin/pip install --quiet -e ."]  # no extra: no pytest, dask, mujoco
    for target in ("test", "test-fast", "lint", "docs", "docs-examples"):
        assert installs(target)[-1] == ".venv/bin/pip install --quiet -e '.[test]'", target
