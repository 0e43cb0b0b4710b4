"""What several commands share: design options with their TOML keys, ``--config`` merging, the table printer.

A design option is one ``Field``: its flag, its TOML key, its type and help, and whether it is an
angle (degrees on the command line and in TOML, rad inside). ``spring`` and ``joint`` both start
from ``REQUIREMENT``, the seven options of a spring requirement.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import click

from rjcad import DEG
from rjcad.io.config import load_toml
from rjcad.materials import DEFAULT_MATERIAL, DEFAULT_PRINTER, MATERIALS, PRINTERS, profiles_beside


class Field(NamedTuple):
    """One design option: ``--flag``, its TOML key, its type (float or str), help, and if it is an angle."""

    flag: str
    toml: str
    type: type
    help: str
    degrees: bool = False

    @property
    def name(self) -> str:
        """The option's Python name: ``--width-min`` → ``width_min``."""
        return self.flag[2:].replace("-", "_")

    def internal(self, value):
        """``value`` as ``type`` in rjcad units (degrees → rad)."""
        v = self.type(value)
        return v * DEG if self.degrees else v


#: The spring requirement, in the order ``rjcad spring --help`` shows it.
REQUIREMENT = (
    Field("--stiffness", "stiffness_nmm_per_rad", float, "Joint stiffness, both springs [N·mm/rad]."),
    Field("--rotation", "rotation_deg", float, "Joint rotation range [deg] (default 90).", degrees=True),
    Field("--preload", "preload_deg", float, "Spring preload at rest [deg] (default 90).", degrees=True),
    Field(
        "--material",
        "material",
        str,
        f"A material: built in ({', '.join(MATERIALS)}; default {DEFAULT_MATERIAL}), a name in your profile "
        "folder, or a profile file (.toml); see rjcad profiles.",
    ),
    Field(
        "--printer",
        "printer",
        str,
        f"A printer: built in ({', '.join(PRINTERS)}; default {DEFAULT_PRINTER}), a name in your profile "
        "folder, or a profile file (.toml); see rjcad profiles.",
    ),
    Field("--safety-factor", "safety_factor", float, "Safety factor on yield (default 1.5)."),
    Field(
        "--end",
        "end",
        str,
        "Outer end condition: clamped (default: position and angle held) or pinned (free to turn about its post).",
    ),
)


def requirement(after_printer: tuple[Field, ...] = (), **helps: str) -> tuple[Field, ...]:
    """``REQUIREMENT`` with ``after_printer`` inserted after ``--printer`` and help texts replaced (name → help)."""
    unknown = set(helps) - {f.name for f in REQUIREMENT}
    if unknown:
        raise TypeError(f"requirement(): no option {', '.join(sorted(unknown))}")
    fields = tuple(f._replace(help=helps.get(f.name, f.help)) for f in REQUIREMENT)
    at = [f.name for f in fields].index("printer") + 1
    return fields[:at] + tuple(after_printer) + fields[at:]


def design_options(fields: tuple[Field, ...], config_help: str):
    """Decorator: one click option per field, in order, then ``--config`` (a TOML file with the fields' keys)."""

    def decorate(f):
        f = click.option("--config", type=click.Path(dir_okay=False), help=config_help)(f)
        for field in reversed(fields):
            f = click.option(field.flag, type=field.type, help=field.help)(f)
        return f

    return decorate


def merge_config(options: dict, config: str | None, fields: tuple[Field, ...]) -> dict:
    """defaults < config file < explicit options: {option name: value in rjcad units} of every field given."""
    by_name = {f.name: f for f in fields}
    given = {k: v for k, v in options.items() if v is not None and k in by_name}
    if config:
        toml_types = {f.toml: ((int, float) if f.type is float else f.type) for f in fields}
        by_key = {f.toml: f.name for f in fields}
        data = profiles_beside(load_toml(config, toml_types), Path(config).parent)
        for key, value in data.items():
            given.setdefault(by_key[key], value)
    return {name: by_name[name].internal(v) for name, v in given.items()}


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
