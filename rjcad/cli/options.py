"""What several commands share: design options as click options, the table printer, the grammar's helpers
(``OutDir``, the deprecation note, completion of profile names); docs/cli.md is the grammar.

The design options themselves (``Field``: flag, TOML key, API keyword, type, help, angle or not), the tables of
``rjcad spring`` and ``rjcad joint`` and ``--config`` merging live in ``rjcad.fields``, which the Python API
shares; they are re-exported here.
"""

from __future__ import annotations

import click

from rjcad.fields import REQUIREMENT, Field, merge_config, requirement
from rjcad.io.untrusted import shown_path

__all__ = [
    "REQUIREMENT",
    "Field",
    "OutDir",
    "OutFile",
    "complete_profiles",
    "deprecated",
    "design_options",
    "echo_profiles",
    "merge_config",
    "print_table",
    "profile_path",
    "renamed",
    "requirement",
]

#: Options whose values are profile names, completed from the profiles rjcad sees (``rjcad profiles``).
PROFILE_OPTIONS = {"material": "materials", "printer": "printers"}


def deprecated(old: str, new: str) -> None:
    """The one-line note on stderr for an old spelling that still works this release."""
    click.echo(f"rjcad: note: {old} is deprecated; use {new} (the old spelling goes in the next release)", err=True)


def complete_profiles(kind: str):
    """A click ``shell_complete`` callback: the names of the ``kind`` profiles ("materials" or "printers") that
    start with what was typed, each with its title; a path (a ``/`` or ``.toml`` typed) completes as a file."""

    def complete(ctx: click.Context, param: click.Parameter, incomplete: str):
        from click.shell_completion import CompletionItem

        if "/" in incomplete or incomplete.endswith(".toml"):
            return [CompletionItem(incomplete, type="file")]
        from rjcad.materials import everything

        try:
            profiles = everything(kind)
        except Exception:  # a broken profile of the user's must not break the shell's completion
            return []
        return [CompletionItem(p.key, help=p.name) for p in profiles if p.key.startswith(incomplete)]

    return complete


class OutDir(click.Path):
    """``--out``: a folder, always (created if missing; an existing file is refused in one line). ``legacy``:
    file suffixes of the former form (``--out page.html``), passed through unchecked for the command to accept
    with a deprecation note."""

    name = "directory"

    def __init__(self, legacy: tuple[str, ...] = ()) -> None:
        super().__init__(file_okay=False, dir_okay=True)
        self.legacy = tuple(s.lower() for s in legacy)

    def is_legacy(self, value: str) -> bool:
        """True for the former form: a name with a legacy suffix that is not an existing folder."""
        import os

        return bool(self.legacy) and str(value).lower().endswith(self.legacy) and not os.path.isdir(value)

    def convert(self, value, param, ctx):
        if self.is_legacy(value):  # checked by the command, after its deprecation note
            return value
        out = str(super().convert(value, param, ctx))
        writable(param, out, out)  # refused now, not after the computation
        return out


def writable(param, value: str, folder: str) -> None:
    """Refuse, as the option is read, an output ``folder`` that cannot be made or written (OutputError naming
    the option and its value)."""
    from rjcad.io.outputs import OutputError, check_writable

    try:
        check_writable(folder)
    except OutputError as e:
        name = param.opts[0] if param is not None and param.opts else None
        raise OutputError(f"{name} {value}" if name else value, str(e.reason)) from None


class OutFile(click.Path):
    """An output file option (``--plot``, ``--junit``): a file, its folder made if missing; a folder that cannot
    be made or written is refused when the option is read, before the command computes anything."""

    def __init__(self) -> None:
        super().__init__(dir_okay=False)

    def convert(self, value, param, ctx):
        import os

        from rjcad.io.outputs import OutputError, refuse_special

        out = str(super().convert(value, param, ctx))
        try:
            refuse_special(out)  # a link, a FIFO or a device is never written through nor replaced
        except OutputError as e:
            raise OutputError(
                f"{param.opts[0]} {value}" if param is not None and param.opts else value, e.reason
            ) from None
        writable(param, out, os.path.dirname(out) or ".")
        return out


def out_file(value: str, legacy: tuple[str, ...], name: str) -> tuple[str, str]:
    """``--out``'s (folder, file name in it) for a command that writes one file, ``name`` in the folder: the
    former form ``--out FILE`` (a legacy suffix) keeps its file, with the deprecation note."""
    import os

    if OutDir(legacy).is_legacy(value):
        deprecated(f"--out FILE{legacy[0]}", f"--out DIR (it writes DIR/{name})")
        return os.path.dirname(value) or ".", os.path.basename(value)
    return value, name


def renamed(old: str, new: str, **kw):
    """Decorator: the hidden option ``old``, the former name of ``new`` (same type), taken with the deprecation
    note; the command reads it as ``<old's name>`` and calls ``either`` to merge."""
    kw.setdefault("type", float)
    return click.option(old, old.lstrip("-").replace("-", "_"), hidden=True, default=None, **kw)


def either(new_value, old_value, new: str, old: str):
    """The value of an option given by its new name or its former one (noted); both given is a usage error."""
    if old_value is None:
        return new_value
    if new_value is not None:
        raise click.UsageError(f"give {new} only ({old} is its former name)")
    deprecated(old, new)
    return old_value


def design_options(fields: tuple[Field, ...], config_help: str):
    """Decorator: one click option per field, in order, then ``--config`` (a TOML file with the fields' keys)."""

    def decorate(f):
        f = click.option("--config", type=click.Path(dir_okay=False), help=config_help)(f)
        for field in reversed(fields):
            kind = PROFILE_OPTIONS.get(field.name)
            complete = complete_profiles(kind) if kind else None
            f = click.option(field.flag, type=field.type, help=field.help, shell_complete=complete)(f)
        return f

    return decorate


def print_table(rows: list[tuple[str, str, str]]) -> None:
    """Echo (name, value, unit) rows: names left-aligned, values right-aligned."""
    w0 = max(len(r[0]) for r in rows)
    w1 = max(len(r[1]) for r in rows)
    for name, value, unit in rows:
        click.echo(f"  {name:<{w0}}  {value:>{w1}}  {unit}")


def profile_path(prof) -> str:
    """Where a profile comes from, as printed (``rjcad.materials.shown_file``)."""
    from rjcad.materials import shown_file

    return shown_file("printers" if hasattr(prof, "nozzle_mm") else "materials", prof.file, prof.builtin)


def echo_profiles(*profiles) -> None:
    """Say which file each of the user's profiles (printer or material) came from; nothing for built-in ones."""
    for prof in profiles:
        if not prof.builtin:
            kind = "printer" if hasattr(prof, "nozzle_mm") else "material"
            click.echo(f"{kind} {prof.key}: your profile {shown_path(prof.file)}")


#: ``--allow-outside`` of the commands that read files beside a manifest (its GLB, STLs or 3MF).
allow_outside_option = click.option(
    "--allow-outside",
    is_flag=True,
    help="Read the files beside the manifest even where they resolve outside its folder (default: refused, "
    "symlinks followed).",
)
