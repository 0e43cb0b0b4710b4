"""What several commands share: design options as click options, the table printer.

The design options themselves (``Field``: flag, TOML key, API keyword, type, help, angle or not), the tables of
``rjcad spring`` and ``rjcad joint`` and ``--config`` merging live in ``rjcad.fields``, which the Python API
shares; they are re-exported here.
"""

from __future__ import annotations

import click

from rjcad.fields import REQUIREMENT, Field, merge_config, requirement

__all__ = ["REQUIREMENT", "Field", "design_options", "echo_profiles", "merge_config", "print_table", "requirement"]


def design_options(fields: tuple[Field, ...], config_help: str):
    """Decorator: one click option per field, in order, then ``--config`` (a TOML file with the fields' keys)."""

    def decorate(f):
        f = click.option("--config", type=click.Path(dir_okay=False), help=config_help)(f)
        for field in reversed(fields):
            f = click.option(field.flag, type=field.type, help=field.help)(f)
        return f

    return decorate


def print_table(rows: list[tuple[str, str, str]]) -> None:
    """Echo (name, value, unit) rows: names left-aligned, values right-aligned."""
    w0 = max(len(r[0]) for r in rows)
    w1 = max(len(r[1]) for r in rows)
    for name, value, unit in rows:
        click.echo(f"  {name:<{w0}}  {value:>{w1}}  {unit}")


def echo_profiles(*profiles) -> None:
    """Say which file each of the user's profiles (printer or material) came from; nothing for built-in ones."""
    for prof in profiles:
        if not prof.builtin:
            kind = "printer" if hasattr(prof, "nozzle_mm") else "material"
            click.echo(f"{kind} {prof.key}: your profile {prof.file}")
