"""The examples of README.md and docs/ (issue #39): tools/docs_examples.py's parser and comparison on made-up
pages, then every page run and compared with what it shows."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load():
    spec = importlib.util.spec_from_file_location("docs_examples", ROOT / "tools" / "docs_examples.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["docs_examples"] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


de = _load()


def run(tmp_path: Path, text: str, write: bool = False):
    """Run a made-up page (in the repository's work folder set-up) and give the Result."""
    page = tmp_path / "page.md"
    page.write_text(text, encoding="utf-8")
    result = de.run_page(page, ROOT, write=write)
    result.mismatches = [m.replace(f"{tmp_path}/", "") for m in result.mismatches]
    return result


# ---------------------------------------------------------------- the comparison


def test_numbers_agree_within_one_unit_of_their_last_shown_digit():
    assert de.matches(["  joint stiffness      5.1943  N·mm/rad"], ["  joint stiffness      5.1942  N·mm/rad"])
    assert de.matches(["stress 20 MPa"], ["stress 21 MPa"])
    assert de.matches(["E = 4.07e+05"], ["E = 4.08e+05"])
    assert de.matches(["width 4.600 mm   "], ["width 4.600 mm"])  # trailing spaces ignored
    assert not de.matches(["  joint stiffness      5.1943  N·mm/rad"], ["  joint stiffness      5.1945  N·mm/rad"])
    assert not de.matches(["stress 20 MPa"], ["stress 22 MPa"])
    assert not de.matches(["width 4.6 mm"], ["width 4.6 cm"])  # the text must be equal
    assert not de.matches(["a 1 b 2"], ["a 1 b"])  # numbers in the same places


def test_a_marker_tolerance_widens_the_agreement():
    assert not de.matches(["time 100 ms"], ["time 104 ms"])
    assert de.matches(["time 100 ms"], ["time 104 ms"], tol=(0.05, True))
    assert not de.matches(["time 100 ms"], ["time 106 ms"], tol=(0.05, True))
    assert de.matches(["x 1.00"], ["x 1.40"], tol=(0.5, False))
    assert not de.matches(["x 1.00"], ["x 1.60"], tol=(0.5, False))


def test_cuts_stand_for_any_number_of_lines_and_the_shown_lines_must_be_consecutive():
    out = ["first", "a", "b", "c", "last"]
    assert de.matches(["first", "...", "last"], out)
    assert de.matches(["...", "b", "c", "..."], out)
    assert de.matches(["first", "...", "a", "...", "last"], out)  # a cut may stand for no line
    assert de.matches(["..."], out) and de.matches(["..."], [])
    assert not de.matches(["first", "a", "c", "..."], out)  # b left out without a cut
    assert not de.matches(["a", "..."], out)  # the first line shown must be the first printed
    assert not de.matches(["...", "c"], out)  # and the last the last
    assert not de.matches(["first", "...", "missing", "...", "last"], out)  # a line that is not printed
    assert not de.matches([], ["something"])  # nothing shown, no cut: it must print nothing
    assert de.matches([], [])


# ---------------------------------------------------------------- the parser

PAGE = """# A page

<!-- file: conf/my.toml -->
```toml
x = 1
```

```console
$ rjcad spring --stiffness 5.2 \\
    --rotation 90
Spiral spring ...
...
$ rjcad life
```

*(Not run by the tests: it needs a display.)*
```console
$ rjcad view out/finger/finger.json
```

```console
$ make demo
```

```sh
rjcad spring --stiffness 5.2
```

```python
print(1)
```

<!-- example: tol=5% -->
```text
1
```

<!-- example: exit=2 -->
```console
$ rjcad spring --stiffness -1
rjcad: error: ...
```
"""


def test_the_parser_finds_files_commands_outputs_markers_and_python_outputs():
    blocks = de.parse(PAGE)
    assert [(b.kind, b.skip) for b in blocks] == [
        ("file", None),
        ("console", None),
        ("console", "it needs a display"),
        ("python", None),
        ("console", None),
    ]
    file, console, _, python, refusal = blocks
    assert file.name == "conf/my.toml" and file.steps[0].code == "x = 1\n"
    assert [s.code for s in console.steps] == ["rjcad spring --stiffness 5.2 \\\n    --rotation 90", "rjcad life"]
    assert console.steps[0].shown == ["Spiral spring ...", "..."] and console.steps[1].shown == []
    lines = PAGE.splitlines()
    assert lines[console.steps[0].at] == "Spiral spring ..."  # where --write rewrites
    assert python.steps[0].code == "print(1)\n" and python.steps[0].shown == ["1"]
    assert python.tol == (0.05, True) and lines[python.steps[0].at] == "1"
    assert (refusal.exit, refusal.tol) == (2, None)


def test_an_rjcad_console_block_is_run_unless_it_carries_the_visible_marker():
    shown = "```console\n$ rjcad view x.json\n```\n"
    assert de.parse("Text.\n\n" + shown)[0].skip is None
    assert de.parse("<!-- not run: a display -->\n" + shown)[0].skip is None  # hidden reasons do not count
    assert de.parse("Text.\n*(Not run by the tests: a display.)*\n\n" + shown)[0].skip == "a display"
    with pytest.raises(ValueError, match="not-run marker"):
        de.parse("*(Not run by tests: a display.)*\n" + shown)
    with pytest.raises(ValueError, match="unknown example option"):
        de.parse("<!-- example: exits=2 -->\n" + shown)


def test_every_page_parses(root):
    for page in de.pages(root):
        de.parse(page.read_text(encoding="utf-8"))


def runnable(page: Path) -> list:
    return [b for b in de.parse(page.read_text(encoding="utf-8")) if b.kind != "file" and not b.skip]


def test_the_pages_hold_at_least_forty_runnable_examples(root):
    counts = {str(p.relative_to(root)): len(runnable(p)) for p in de.pages(root)}
    assert sum(counts.values()) >= 40, counts


# ---------------------------------------------------------------- running made-up pages (fast commands only)


def test_a_page_runs_its_files_python_and_commands_in_order(tmp_path):
    text = (
        "<!-- file: data/n.txt -->\n```text\n21\n```\n\n"
        "```python\nn = int(open('data/n.txt').read())\nprint(f'n = {n / 3:.4f}')\n```\n\n```text\nn = 7.0001\n```\n\n"
        "```console\n$ rjcad --version\nrjcad, version ...\n```\n"
    )
    assert not de.matches(["rjcad, version ..."], ["rjcad, version 0.1.0"])  # `...` is a cut only on its own line
    result = run(tmp_path, text.replace("version ...", "version " + _version()))
    assert (result.run, result.skipped, result.mismatches) == (2, 0, [])
    bad = run(tmp_path, text.replace("7.0001", "7.0002").replace("version ...", "version 9.9"))
    assert bad.mismatches == [
        "page.md:12: shown 'n = 7.0002', printed 'n = 7.0000'",
        f"page.md:17: shown 'rjcad, version 9.9', printed 'rjcad, version {_version()}'",
    ]


def _version() -> str:
    import rjcad

    return rjcad.__version__


def test_exit_codes_and_a_block_that_raises_are_mismatches(tmp_path):
    refusal = "```console\n$ rjcad --no-such-option\n...\n```\n"
    assert run(tmp_path, "<!-- example: exit=2 -->\n" + refusal).mismatches == []
    (message,) = run(tmp_path, refusal).mismatches
    assert message.startswith("page.md:2: `rjcad --no-such-option` exited 2, not 0")
    piped = "<!-- example: exit=1 -->\n```console\n$ rjcad --version | grep -q no-such-text\n```\n"
    assert run(tmp_path, piped).mismatches == []
    (message,) = run(tmp_path, "```python\n1 / 0\n```\n\n```python\nprint(2)\n```\n").mismatches
    assert message.startswith("page.md:1: the block raised") and "ZeroDivisionError" in message


def test_skipped_blocks_are_not_run(tmp_path):
    result = run(tmp_path, "*(Not run by the tests: it fails.)*\n```python\nraise SystemExit(3)\n```\n")
    assert (result.run, result.skipped, result.mismatches) == (0, 1, [])


def test_write_rewrites_changed_lines_and_keeps_cuts_markers_and_commands(tmp_path):
    text = (
        "Text.\n\n```python\nfor i in range(5):\n    print(f'row {i}: {i / 7:.3f} N')\n```\n\n"
        "<!-- example: tol=1% -->\n```text\nrow 0: 0.000 N\n...\nrow 2: 0.999 N\n...\nrow 4: 0.560 N\n```\n\n"
        "```console\n$ rjcad --version\nrjcad, version 0.0.7\n```\n"
    )
    result = run(tmp_path, text, write=True)
    assert len(result.rewritten) == 3 and result.mismatches == []  # row 2 found among rows of the same text
    new = (tmp_path / "page.md").read_text(encoding="utf-8")
    assert new == text.replace("0.999", "0.286").replace("0.560", "0.571").replace("0.0.7", _version())
    assert run(tmp_path, new).mismatches == []
    unmatched = text.replace("row 4", "line 4")
    result = run(tmp_path, unmatched, write=True)
    assert "fix it by hand" in result.mismatches[0]
    assert (tmp_path / "page.md").read_text(encoding="utf-8") == unmatched  # left unchanged


# ---------------------------------------------------------------- the pages themselves

#: rjcad commands that take well under a second each: a page of at most four of them (and no Python) stays in
#: the fast lane; every other page with examples is `slow`.
CHEAP = re.compile(r"rjcad (spring|life|profiles|simulate joint|--version|--help)\b")


def _marks(page: Path) -> list:
    try:
        blocks = runnable(page)
    except ValueError:  # a malformed marker: test_every_page_parses and the page's own test say where
        return []
    commands = [s.code for b in blocks for s in b.steps]
    cheap = all(b.kind == "console" for b in blocks) and len(commands) <= 4 and all(map(CHEAP.match, commands))
    return [] if cheap else [pytest.mark.slow(why=f"runs the page's {len(blocks)} examples")]


@pytest.mark.parametrize(
    "page", [pytest.param(p, marks=_marks(p), id=str(p.relative_to(ROOT))) for p in de.pages(ROOT)]
)
def test_the_page_prints_what_it_shows(page, root):
    result = de.run_page(page, root)
    assert not result.mismatches, "\n".join(result.mismatches)
