r"""Run the examples of README.md and docs/ and compare what they print with the page (issue #39).

    python tools/docs_examples.py [--write] [PAGES...]     (from the repository's root; default: README.md
                                                            and docs/**/*.md)

The format: a ```console block whose first line starts with `$ rjcad` is run, each `$ ` command (continued
over lines ending in ` \`) by `bash -c`; the lines under a command are its output, a line `...` standing for
any number of left-out lines, each number agreeing within one unit of its last shown digit. A ```python block
is run (one namespace per page); a ```text block right under it is its output. `<!-- example: exit=2 tol=5% -->`
just above a block sets its exit code and a looser tolerance (`tol=0.5`: absolute); `<!-- file: NAME -->`
writes the block under it to NAME first; `*(Not run by the tests: REASON.)*` just above a block skips it.
Each page runs in a fresh folder holding copies of templates/ and examples/.

It prints each page's blocks run and every mismatch as `page:line: shown X, printed Y`, and exits 1 on any.
`--write` rewrites each shown output line that no longer matches with the line printed today (matched by its
text with the numbers taken out), keeping the cuts, markers and commands; a page with a line it cannot match,
or a block that failed, is reported and left unchanged.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

NUMBER = re.compile(r"[-+]?\d+(\.\d+)?([eE][-+]?\d+)?")
FENCE = re.compile(r"^(?P<indent> *)(?P<fence>```+)\s*(?P<info>[\w-]*)[^`]*$")
HIDDEN = re.compile(r"^<!-- (?P<kind>example|file): (?P<value>.+?) -->$")
VISIBLE = re.compile(r"^\*\(Not run by the tests: (?P<why>.+)\.\)\*$")
CUT = "..."
TIMEOUT = 600  # seconds, one command


@dataclass
class Step:
    """One command (shell or Python) and the output lines the page shows for it (None: not compared)."""

    code: str
    shown: list[str] | None
    at: int  # the page's line index (0-based) of shown[0]


@dataclass
class Block:
    """A fenced block the tests use: `console`, `python` (run) or `file` (written to the work folder)."""

    kind: str
    line: int  # the opening fence's line number (1-based)
    steps: list[Step] = field(default_factory=list)
    exit: int = 0
    tol: tuple[float, bool] | None = None  # (value, relative)
    skip: str | None = None  # the visible marker's reason: not run
    name: str | None = None  # a file block's name
    indent: str = ""


def options(text: str, line: int) -> dict:
    """`exit=2 tol=5%` → {"exit": 2, "tol": (0.05, True)}."""
    out: dict = {}
    for word in text.split():
        key, _, value = word.partition("=")
        if key == "exit":
            out["exit"] = int(value)
        elif key == "tol":
            out["tol"] = (float(value[:-1]) / 100, True) if value.endswith("%") else (float(value), False)
        else:
            raise ValueError(f"line {line}: unknown example option {word!r}")
    return out


def markers(lines: list[str], i: int) -> tuple[dict, str | None, str | None]:
    """The markers just above the fence at line index i: (example options, file name, not-run reason)."""
    opts: dict = {}
    name = why = None
    j = i - 1
    while j >= 0:
        text = lines[j].strip()
        hidden, visible = HIDDEN.match(text), VISIBLE.match(text)
        if hidden and hidden["kind"] == "example":
            opts = options(hidden["value"], j + 1) | opts
        elif hidden:
            name = hidden["value"].strip()
        elif visible:
            why = visible["why"]
        elif text.startswith("*(Not run"):
            raise ValueError(f"line {j + 1}: the not-run marker must read exactly *(Not run by the tests: REASON.)*")
        elif text:
            break
        j -= 1
    return opts, name, why


def fence_end(lines: list[str], i: int) -> int:
    """The line index of the fence that closes the block opened at line index i."""
    fence = FENCE.match(lines[i])["fence"]  # type: ignore[index]
    for j in range(i + 1, len(lines)):
        if lines[j].strip() == fence:
            return j
    raise ValueError(f"line {i + 1}: the block is not closed")


def parse(text: str) -> list[Block]:
    """The page's file, console (starting with `$ rjcad`) and python blocks, in page order."""
    lines = text.splitlines()
    blocks: list[Block] = []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        end = fence_end(lines, i)
        indent, info = m["indent"], m["info"]
        body = [s[len(indent) :] if s.startswith(indent) else s.lstrip() for s in lines[i + 1 : end]]
        opts, name, why = markers(lines, i)
        block = Block(info, i + 1, skip=why, indent=indent, **opts)
        if name:
            block.kind, block.name = "file", name
            block.steps = [Step("".join(s + "\n" for s in body), None, i + 1)]
        elif info == "console" and body and body[0].startswith("$ rjcad"):
            block.steps = console_steps(body, i + 1)
        elif info == "python":
            block.steps = [Step("".join(s + "\n" for s in body), None, i + 1)]
            k = end + 1
            while k < len(lines) and (not lines[k].strip() or lines[k].startswith("<!-- example:")):
                k += 1
            out = FENCE.match(lines[k]) if k < len(lines) else None
            if out and out["info"] == "text":
                more, _, _ = markers(lines, k)
                for key, value in more.items():
                    setattr(block, key, value)
                end = fence_end(lines, k)
                block.steps[0].shown = [s[len(out["indent"]) :] for s in lines[k + 1 : end]]
                block.steps[0].at = k + 1
        else:
            i = end + 1
            continue
        blocks.append(block)
        i = end + 1
    return blocks


def console_steps(body: list[str], at: int) -> list[Step]:
    """A console block's commands (`$ `, continued over lines ending in ` \\`) and the output under each."""
    steps: list[Step] = []
    k = 0
    while k < len(body):
        if body[k].startswith("$ "):
            command = body[k][2:]
            while command.endswith(" \\") and k + 1 < len(body):
                k += 1
                command += "\n" + body[k]
            steps.append(Step(command, [], at + k + 1))
        else:
            steps[-1].shown.append(body[k])  # type: ignore[union-attr]
        k += 1
    return steps


def skeleton(line: str) -> str:
    """A line with its numbers taken out: what --write matches a shown line to its printed line by."""
    return NUMBER.sub("#", line).rstrip()


def close(shown: str, printed: str, tol: tuple[float, bool] | None = None) -> bool:
    """A printed number within one unit of the shown number's last digit (or within `tol`)."""
    x, y = float(shown), float(printed)
    mantissa, _, exponent = shown.lower().partition("e")
    unit = 10.0 ** (int(exponent or 0) - len(mantissa.partition(".")[2]))
    if tol:
        unit = max(unit, tol[0] * abs(x) if tol[1] else tol[0])
    return abs(x - y) <= unit * (1 + 1e-9)


def likeness(shown: str, printed: str, tol: tuple[float, bool] | None = None) -> int:
    """How alike the numbers of two lines are, place by place: 2 for each equal number, 1 for each close one."""
    pairs = [(a[0], b[0]) for a, b in zip(NUMBER.finditer(shown), NUMBER.finditer(printed))]
    return sum(2 if float(a) == float(b) else close(a, b, tol) for a, b in pairs)


def same(shown: str, printed: str, tol: tuple[float, bool] | None = None) -> bool:
    """The same text, and each number within one unit of its last shown digit (or within `tol`)."""
    pairs = zip(NUMBER.finditer(shown), NUMBER.finditer(printed))
    return skeleton(shown) == skeleton(printed) and all(close(a[0], b[0], tol) for a, b in pairs)


def trim(lines: list[str]) -> list[str]:
    """Trailing spaces and trailing blank lines dropped."""
    lines = [s.rstrip() for s in lines]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def place(shown: list[str], printed: list[str], fits, score=None) -> list[int | None] | None:
    """Where each shown line is in `printed` (None for a cut), or None if the shown lines do not fit there.
    A run of lines between cuts goes where it first fits, or, given `score`, where it scores most."""
    out: list[int | None] = [None] * len(shown)
    runs: list[list[int]] = [[]]
    for k, s in enumerate(shown):
        if s.strip() == CUT:
            runs.append([])
        else:
            runs[-1].append(k)
    open_start = not runs[0]
    open_end = not runs[-1] and len(runs) > 1
    runs = [r for r in runs if r]
    pos = 0
    for n, run in enumerate(runs):
        lo, hi = pos, len(printed) - len(run)
        if n == 0 and not open_start:
            hi = min(hi, 0)
        if n == len(runs) - 1 and not open_end:
            lo = max(lo, len(printed) - len(run))
        starts = [p for p in range(lo, hi + 1) if all(fits(shown[k], printed[p + o]) for o, k in enumerate(run))]
        if score and n < len(runs) - 1:  # only where the rest still fits after it
            rest = shown[run[-1] + 1 :]
            starts = [p for p in starts if place(rest, printed[p + len(run) :], fits) is not None]
        if not starts:
            return None
        p = (
            max(starts, key=lambda p: sum(score(shown[k], printed[p + o]) for o, k in enumerate(run)))
            if score
            else starts[0]
        )
        for o, k in enumerate(run):
            out[k] = p + o
        pos = p + len(run)
    return out if open_end or pos == len(printed) else None


def matches(shown: list[str], printed: list[str], tol: tuple[float, bool] | None = None) -> bool:
    """The printed lines are what the shown lines (with their cuts) say."""
    return place(trim(shown), trim(printed), lambda a, b: same(a, b, tol)) is not None


def explain(shown: list[str], printed: list[str], fits) -> tuple[int, str]:
    """The first shown line (index) that does not fit, and what was printed in its place."""
    for k, s in enumerate(shown):
        if s.strip() == CUT or place(shown[: k + 1] + [CUT], printed, fits) is not None:
            continue
        before = place(shown[:k] + [CUT], printed, fits) or []
        last = max((p for p in before if p is not None), default=-1)
        if k and shown[k - 1].strip() == CUT:
            near = [p for p in range(last + 1, len(printed)) if skeleton(printed[p]) == skeleton(s)]
            return k, repr(printed[near[0]]) if near else "no such line"
        return k, repr(printed[last + 1]) if last + 1 < len(printed) else "nothing more"
    last = max((p for p in place(shown + [CUT], printed, fits) or [] if p is not None), default=-1)
    return len(shown), repr(printed[last + 1]) if last + 1 < len(printed) else "nothing more"


@dataclass
class Result:
    """A page's run: blocks run and not run, mismatches (`page:line: ...`), lines rewritten, seconds."""

    page: str
    run: int = 0
    skipped: int = 0
    mismatches: list[str] = field(default_factory=list)
    rewritten: list[str] = field(default_factory=list)
    seconds: float = 0.0


def check(result: Result, block: Block, step: Step, printed: list[str], lines: list[str] | None) -> None:
    """Compare a step's printed lines with the shown ones; with the page's `lines` (--write), rewrite them."""
    if step.shown is None:
        return
    shown, printed = trim(step.shown), trim(printed)
    fits = lambda a, b: same(a, b, block.tol)  # noqa: E731
    if place(shown, printed, fits) is not None:
        return
    # each shown line to a printed line of the same text, whose numbers are most alike
    loose = place(shown, printed, lambda a, b: skeleton(a) == skeleton(b), lambda a, b: likeness(a, b, block.tol))
    if loose is None:  # a line's text changed, or a line is missing or extra: one message, the first
        k, what = explain(shown, printed, fits)
        said = f"shown {shown[k]!r}" if k < len(shown) else "shown no more"
        line = step.at + min(k, len(shown) - 1) + 1 if shown else step.at
        fix = " (no line printed has its text: fix it by hand)" if lines is not None else ""
        result.mismatches.append(f"{result.page}:{line}: {said}, printed {what}{fix}")
        return
    for k, p in enumerate(loose):
        if p is not None and not fits(shown[k], printed[p]):
            message = f"{result.page}:{step.at + k + 1}: shown {shown[k]!r}, printed {printed[p]!r}"
            if lines is None:
                result.mismatches.append(message)
            else:
                lines[step.at + k] = block.indent + printed[p]
                result.rewritten.append(message)


@contextlib.contextmanager
def work_folder(root: Path):
    """A fresh work folder holding copies of templates/ and examples/, made the current directory, with the
    spec's environment: HOME a fresh folder, LC_ALL, COLUMNS, this Python's bin first on PATH."""
    saved_env, saved_cwd = dict(os.environ), os.getcwd()
    mpl = saved_env.get("MPLCONFIGDIR") or str(Path.home() / ".cache" / "matplotlib")  # its font cache, kept
    with tempfile.TemporaryDirectory(prefix="rjcad-docs-") as tmp:
        work, home = Path(tmp) / "work", Path(tmp) / "home"
        home.mkdir()
        work.mkdir()
        for name in ("templates", "examples"):
            if (root / name).is_dir():
                shutil.copytree(root / name, work / name)
        path = os.pathsep.join([str(Path(sys.executable).parent), saved_env.get("PATH", "")])
        os.environ.update(HOME=str(home), LC_ALL="C.UTF-8", COLUMNS="100", PATH=path, MPLCONFIGDIR=mpl)
        for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME"):
            os.environ.pop(name, None)
        os.chdir(work)
        try:
            yield work
        finally:
            os.chdir(saved_cwd)
            os.environ.clear()
            os.environ.update(saved_env)


def run_page(page: Path, root: Path, write: bool = False) -> Result:
    """Run a page's blocks in page order in a fresh work folder and compare their output with the page; with
    `write`, rewrite the page's changed lines unless one cannot be matched or a block failed."""
    start = time.perf_counter()
    text = page.read_text(encoding="utf-8")
    name = (
        str(page.resolve().relative_to(root.resolve())) if page.resolve().is_relative_to(root.resolve()) else str(page)
    )
    result = Result(name)
    lines = text.splitlines() if write else None
    blocks = parse(text)
    namespace: dict = {"__name__": "__docs__"}
    with work_folder(root) as work:
        for block in blocks:
            if block.kind == "file":
                target = work / str(block.name)
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_text(block.steps[0].code, encoding="utf-8")
        for block in blocks:
            if block.kind == "file":
                continue
            if block.skip:
                result.skipped += 1
                continue
            result.run += 1
            if block.kind == "python":
                printed = io.StringIO()
                try:
                    with contextlib.redirect_stdout(printed):
                        exec(compile(block.steps[0].code, f"{name}:{block.line}", "exec"), namespace)
                except (Exception, SystemExit):
                    error = traceback.format_exc(limit=-2).strip().replace("\n", "\n    ")
                    result.mismatches.append(f"{name}:{block.line}: the block raised\n    {error}")
                    break
                check(result, block, block.steps[0], printed.getvalue().splitlines(), lines)
                continue
            for step in block.steps:
                try:
                    run = subprocess.run(["bash", "-c", step.code], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                         stderr=subprocess.STDOUT, timeout=TIMEOUT)  # fmt: skip
                except subprocess.TimeoutExpired:
                    result.mismatches.append(f"{name}:{step.at}: `{step.code}` did not end in {TIMEOUT} s")
                    continue
                printed_lines = run.stdout.decode("utf-8", "replace").splitlines()
                if run.returncode != block.exit:
                    tail = "\n    ".join(printed_lines[-5:])
                    result.mismatches.append(f"{name}:{step.at}: `{step.code}` exited {run.returncode}, "
                                             f"not {block.exit}:\n    {tail}")  # fmt: skip
                    continue
                check(result, block, step, printed_lines, lines)
    result.seconds = time.perf_counter() - start
    if lines is not None and result.rewritten and not result.mismatches:
        page.write_text("\n".join(lines) + ("\n" if text.endswith("\n") else ""), encoding="utf-8")
    return result


def pages(root: Path) -> list[Path]:
    """README.md and docs/**/*.md."""
    return [p for p in [root / "README.md", *sorted((root / "docs").rglob("*.md"))] if p.is_file()]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="rewrite the output lines that changed")
    parser.add_argument("pages", nargs="*", type=Path, help="default: README.md and docs/**/*.md")
    args = parser.parse_args(argv)
    root = Path.cwd()
    failed = False
    for page in args.pages or pages(root):
        result = run_page(page, root, write=args.write)
        print(f"{result.page}: {result.run} blocks run, {result.skipped} not run, {result.seconds:.1f} s")
        for m in result.mismatches:
            print(m)
        for m in result.rewritten:
            print(m + (" (rewritten)" if not result.mismatches else " (not rewritten)"))
        failed |= bool(result.mismatches)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
