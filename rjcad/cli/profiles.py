"""``rjcad profiles``: the printer and material profiles rjcad can see, and a printer imported from PrusaSlicer."""

from __future__ import annotations

import re
from typing import Any

import click

from rjcad.cli.options import OutDir


@click.group(invoke_without_command=True)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.pass_context
def profiles(ctx: click.Context, as_json: bool) -> None:
    """List every printer and material profile by name, with the file each comes from (your folder's first)."""
    if ctx.invoked_subcommand is not None:
        return
    import json

    from rjcad.materials import MATERIALS, PRINTERS, Material, Printer, everything, user_dir

    rows: dict[str, list[dict[str, Any]]] = {}
    listed = {kind: everything(kind) for kind in ("printers", "materials")}
    for kind in ("printers", "materials"):
        rows[kind] = []
        for prof in listed[kind]:
            shadowed = not prof.builtin and prof.key in (PRINTERS if kind == "printers" else MATERIALS)
            row: dict[str, Any] = {
                "name": prof.key,
                "title": prof.name,
                "from": "built-in" if prof.builtin else "yours",
            }
            if shadowed:
                row["from"] = "yours, over the built-in"
            row["file"] = prof.file
            if isinstance(prof, Printer):
                row.update(
                    nozzle_mm=prof.nozzle_mm,
                    layer_mm=prof.layer_height_mm,
                    bed_mm=list(prof.build_volume_mm),
                    min_wall_mm=prof.min_wall_mm,
                    min_gap_mm=prof.min_gap_mm,
                    soluble_support=prof.soluble_support,
                )
            elif isinstance(prof, Material):
                row.update(youngs_modulus_mpa=prof.youngs_modulus_mpa, yield_mpa=prof.yield_strength_mpa)
            rows[kind].append(row)
    folder = user_dir()
    if as_json:
        click.echo(json.dumps({"user_dir": str(folder), **rows}, indent=2))
        return
    from rjcad.cli.options import profile_path
    from rjcad.io.untrusted import shown_path

    mine = shown_path(folder)
    click.echo(f"your profiles: {mine}/printers/*.toml and {mine}/materials/*.toml (a name there wins)")
    for kind in ("printers", "materials"):
        click.echo(f"{kind}:")
        width = max(len(r["name"]) for r in rows[kind])
        for r, prof in zip(rows[kind], listed[kind], strict=True):
            what = (
                f"{r['nozzle_mm']:g} mm nozzle, {r['layer_mm']:g} mm layers, bed "
                f"{' × '.join(f'{v:g}' for v in r['bed_mm'])} mm"
                if kind == "printers"
                else f"E {r['youngs_modulus_mpa']:g} MPa, yield {r['yield_mpa']:g} MPa"
            )
            click.echo(f"  {r['name']:<{width}}  {r['from']:<9}  {what}  ({profile_path(prof)})")


@profiles.command("show")
@click.argument("name")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def show(name: str, as_json: bool) -> None:
    """Print one printer or material profile (a name or a .toml file): its values and the printability limits
    derived from it."""
    import json

    from rjcad.cli.options import print_table, profile_path
    from rjcad.materials import Material, Printer, everything

    prof = _find_either(name)
    kind = "printer" if isinstance(prof, Printer) else "material"
    if as_json:
        click.echo(
            json.dumps(
                {"kind": kind, "key": prof.key, "builtin": prof.builtin, "file": prof.file, **prof.to_profile()},
                indent=2,
            )
        )
        return
    click.echo(f"{kind} {prof.key}: {prof.name} ({'built-in' if prof.builtin else 'yours'}, {profile_path(prof)})")
    rows: list[tuple[str, str, str]] = []
    if isinstance(prof, Printer):

        def derived(key: str, rule: str) -> str:
            return "set in the file" if key in prof.overrides else f"derived: {rule}"

        rows = [
            ("nozzle", f"{prof.nozzle_mm:g}", "mm"),
            ("layer", f"{prof.layer_height_mm:g}", f"mm (first layer {prof.first_layer_mm:g} mm)"),
            ("bed", " × ".join(f"{v:g}" for v in prof.build_volume_mm), "mm"),
            ("soluble support", "yes" if prof.soluble_support else "no", ""),
            ("road width w", f"{prof.extrusion_width_mm:g}", f"mm ({derived('extrusion_width_mm', 'the nozzle')})"),
            ("thinnest wall", f"{prof.min_wall_mm:g}", f"mm ({derived('min_wall_mm', '2·w')})"),
            ("spring thickness step", f"{prof.thickness_step_mm:g}", f"mm ({derived('thickness_step_mm', 'w')})"),
            ("gap side by side", f"{prof.min_gap_mm:g}", f"mm ({derived('min_gap_mm', '5/8 · nozzle')})"),
            (
                "gap across a Z step",
                f"{prof.min_gap_vertical_mm:g}",
                f"mm ({derived('min_gap_vertical_mm', '2 · layer')})",
            ),
        ]
        print_table(rows)
        mats = [m for m in everything("materials") if isinstance(m, Material)]
        click.echo(
            "clearance between bodies (desktop layout) by material: "
            + ", ".join(f"{m.key} {prof.desktop_clearance(m):.3f}" for m in mats)
            + " mm"
        )
    else:
        assert isinstance(prof, Material)
        rows = [
            ("Young's modulus E", f"{prof.youngs_modulus_mpa:g}", "MPa"),
            ("yield", f"{prof.yield_strength_mpa:g}", "MPa"),
            ("density", f"{prof.density_g_cm3:g}", "g/cm³"),
            ("clearance", f"{prof.desktop_clearance_mm:g}", "mm (at a 0.4 mm nozzle; scaled with the nozzle)"),
        ]
        print_table(rows)
    if prof.source:
        click.echo(f"source: {prof.source}")


def _find_either(name: str):
    """The printer or material profile ``name``: a name (printers first), or a .toml file (its kind by its keys)."""
    from pathlib import Path

    from rjcad.errors import ParameterError
    from rjcad.io.untrusted import read_toml
    from rjcad.materials import find

    if name.lower().endswith(".toml") or "/" in name:
        path = Path(name).expanduser()
        material = path.is_file() and "youngs_modulus_mpa" in read_toml(str(path), name=name)
        return find("materials" if material else "printers", name)
    for kind in ("printers", "materials"):
        try:
            return find(kind, name)
        except ParameterError:
            continue
    raise ParameterError(
        "profile", name, "no printer or material of that name (rjcad profiles lists them), nor a .toml file"
    )


@profiles.command("import-prusaslicer")
@click.argument("printer_name")
@click.option(
    "--out",
    "out_dir",
    type=OutDir(legacy=(".toml",)),
    required=True,
    help="The folder to write the printer profile into, as <printer name>.toml in lower case, words joined by "
    "'-' (your profile folder's printers/ makes it usable by that name).",
)
@click.option(
    "--profiles-dir",
    type=click.Path(file_okay=False),
    help="PrusaSlicer's vendor profiles folder (default: the installed PrusaSlicer's).",
)
def import_prusaslicer(printer_name: str, out_dir: str, profiles_dir: str | None) -> None:
    """Write a printer profile from one of PrusaSlicer's bundled printers (its nozzle, bed, height, layers)."""
    from pathlib import Path

    from rjcad.cli.options import out_file
    from rjcad.io.config import write_atomic
    from rjcad.io.prusaslicer import printer_toml, read_printer
    from rjcad.io.untrusted import parse_toml
    from rjcad.materials import Printer, normalise

    folder, name = out_file(out_dir, (".toml",), "<printer name>.toml")
    printer = read_printer(printer_name, profiles_dir)
    if name == "<printer name>.toml":
        name = profile_file_name(printer["name"])
    out = str(Path(folder) / name)
    key = normalise(Path(out).stem)
    text = printer_toml(printer, key)
    Printer.from_profile(parse_toml(text, out), key, file=out)  # the profile rjcad will read: checked now
    write_atomic(out, text)
    click.echo(
        f"printer profile written to {out}: {printer['name']} ({printer['nozzle_mm']:g} mm nozzle, "
        f"{printer['layer_mm']:g} mm layers, bed {' × '.join(f'{v:g}' for v in printer['bed_mm'])} mm)"
    )


def profile_file_name(printer_name: str) -> str:
    """The file ``import-prusaslicer --out DIR`` writes: the printer's name in lower case, every run of other
    characters than letters and digits one '-' ("Original Prusa MK4 0.4 nozzle" → original-prusa-mk4-0-4-nozzle.toml)."""
    return (re.sub(r"[^a-z0-9]+", "-", printer_name.lower()).strip("-") or "printer") + ".toml"
