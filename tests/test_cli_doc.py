"""docs/cli.md, the command line's grammar, against the commands' click definitions (what `--help` shows):
every command in the table and no other, its positional input, `--out` a folder, `--json` a flag, `--config`,
the shared options it lists, and every former spelling in the deprecation table still accepted."""

from __future__ import annotations

import re
from pathlib import Path

import click
import pytest

from rjcad.cli import COMMANDS, cli
from rjcad.cli.options import OutDir

NONE = "—"
DOC = Path(__file__).resolve().parents[1] / "docs" / "cli.md"


def _table(text: str, heading: str) -> list[list[str]]:
    """The rows (cells, stripped) of the first table after ``heading``, its header and rule dropped."""
    section = text.split(heading, 1)[1]
    rows = []
    for line in section.splitlines():
        if line.startswith("|"):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
        elif rows:
            break
    return rows[2:]


TEXT = DOC.read_text(encoding="utf-8")
COMMAND_ROWS = _table(TEXT, "## Commands")
FORMER_ROWS = _table(TEXT, "## Former spellings")


def _leaves() -> dict[str, click.Command]:
    """Every runnable command by its path ("simulate joint"); a group that runs by itself (profiles) too."""
    ctx = click.Context(cli)
    out: dict[str, click.Command] = {}
    for name in COMMANDS:
        cmd = cli.get_command(ctx, name)
        assert cmd is not None
        if isinstance(cmd, click.Group):
            if cmd.invoke_without_command:
                out[name] = cmd
            for sub, subcmd in cmd.commands.items():
                out[f"{name} {sub}"] = subcmd
        else:
            out[name] = cmd
    return out


def _code(cell: str) -> list[str]:
    return re.findall(r"`([^`]+)`", cell)


def _option(cmd: click.Command, flag: str) -> click.Option | None:
    return next((p for p in cmd.params if isinstance(p, click.Option) and flag in p.opts), None)


def test_every_command_is_in_the_table_once():
    names = [_code(r[0])[0] for r in COMMAND_ROWS]
    assert len(names) == len(set(names))
    assert sorted(names) == sorted(_leaves())


@pytest.mark.parametrize("row", COMMAND_ROWS, ids=lambda r: r[0].strip("`"))
def test_each_row_matches_the_command(row):
    name, positional, out, js, config, shared = row
    cmd = _leaves()[_code(name)[0]]
    args = [p.human_readable_name for p in cmd.params if isinstance(p, click.Argument)]
    assert args == (_code(positional)[:1] if positional != NONE else []), (args, positional)
    opt = _option(cmd, "--out")
    if out == NONE:
        assert opt is None
    else:
        assert opt is not None and isinstance(opt.type, click.Path) and not opt.type.file_okay and opt.type.dir_okay
        assert out.startswith("DIR")
        assert ("required" in out) == opt.required
    opt = _option(cmd, "--json")
    if js == NONE:
        assert opt is None
    else:
        assert js == "yes" and opt is not None
        assert opt.is_flag or opt.flag_value == "-", "--json takes no value"  # identify: the former FILE optional
    assert (_option(cmd, "--config") is not None) == (config == "yes")
    for flag in _code(shared):
        o = _option(cmd, flag)
        assert o is not None and not o.hidden, f"{name} has no {flag}"


def test_help_shows_the_grammar(cli):
    """`--help` of a command with a former `--out FILE` now says it is a folder; `--json` takes no value."""
    code, out, _ = cli("view", "--help")
    assert code == 0 and "--out DIRECTORY" in out
    code, out, _ = cli("identify", "--help")
    assert code == 0 and re.search(r"^\s+--json\s", out, re.M) and "[CAMPAIGN]" in out


@pytest.mark.parametrize("row", FORMER_ROWS, ids=lambda r: f"{r[0]} {r[1]}".replace("`", ""))
def test_every_former_spelling_is_still_accepted(row):
    name, old, new = (_code(c)[0] for c in row)
    cmd = _leaves()[name]
    if old.startswith("--out FILE"):
        opt = _option(cmd, "--out")
        assert isinstance(opt.type, OutDir) and opt.type.is_legacy("x" + old.removeprefix("--out FILE"))
        assert new.startswith("--out DIR")
    elif old == "--json FILE":
        opt = _option(cmd, "--json")
        assert not opt.is_flag and opt.flag_value == "-" and new == "--json"
    else:
        opt = _option(cmd, old)
        assert opt is not None and opt.hidden and _option(cmd, new) is not None
