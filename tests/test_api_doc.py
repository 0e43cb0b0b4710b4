"""docs/api.md: every public name of the API is on the page, and its examples run, in order, as written."""

from __future__ import annotations

import re
import shutil

import pytest

import rjcad
from rjcad import api

#: A ```python block, and the line before it (``<!-- not run: reason -->`` skips the block).
BLOCK = re.compile(r"(?:^(?P<before>[^\n]*)\n)?^```python\n(?P<code>.*?)^```$", re.S | re.M)
#: A file the examples read, shown on the page: ``<!-- file: NAME -->`` and the block under it.
FILE = re.compile(r"^<!-- file: (?P<name>[\w.-]+) -->\n```\w*\n(?P<text>.*?)^```$", re.S | re.M)


def blocks(text: str) -> list[tuple[str, str]]:
    """(code, why not run or "") of each python block, in order."""
    out = []
    for m in BLOCK.finditer(text):
        skip = re.fullmatch(r"<!-- not run: (.+) -->", (m.group("before") or "").strip())
        out.append((m.group("code"), skip.group(1) if skip else ""))
    return out


def test_blocks_are_found_and_a_block_is_skipped_only_when_it_says_why():
    text = "x\n```python\na = 1\n```\n<!-- not run: needs a printer -->\n```python\nb = 2\n```\n"
    assert blocks(text) == [("a = 1\n", ""), ("b = 2\n", "needs a printer")]


def test_every_public_name_is_documented(root):
    doc = (root / "docs" / "api.md").read_text(encoding="utf-8")
    names = set(rjcad.__all__) - {"__version__"}
    for cls in (api.Spring, api.Joint, api.Finger, api.Closure, rjcad.CheckReport, rjcad.CheckResult):
        names |= {n for n in dir(cls) if not n.startswith("_")}
    names |= set(api.Closure.__dataclass_fields__)
    missing = sorted(n for n in names if not re.search(rf"\b{re.escape(n)}\b", doc))
    assert not missing, missing
    assert "__version__" in doc


@pytest.mark.slow(why="builds a joint and a finger (the page's examples)")
def test_the_examples_run_in_order(root, tmp_path, monkeypatch):
    text = (root / "docs" / "api.md").read_text(encoding="utf-8")
    code = blocks(text)
    assert len([src for src, why in code if not why]) >= 4
    shutil.copytree(root / "templates", tmp_path / "templates")
    for m in FILE.finditer(text):
        (tmp_path / m.group("name")).write_text(m.group("text"), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__api_doc__"}
    for i, (src, why) in enumerate(code, 1):
        if not why:
            exec(compile(src, f"docs/api.md, block {i}", "exec"), namespace)
    assert (tmp_path / "out" / "joint" / "joint.json").is_file() and (tmp_path / "out" / "spring.png").is_file()
    assert namespace["joint"].manifest["printer"] == "my"  # the page's my.toml
    assert namespace["report"].passed and namespace["closure"].theta_deg.shape == (1001, 3)
