"""``rjcad finger-design``: stiffnesses, preloads and moment arms for a desired free closure, or a finger for a
set of target cylinders (``rjcad.cli.grasp_design``); it writes a finger template."""

from __future__ import annotations

import json

import click

from rjcad.cli.options import OutDir, complete_profiles, out_file
from rjcad.errors import quote
from rjcad.materials import DEFAULT_MATERIAL, DEFAULT_PRINTER
from rjcad.paper import FINGER

#: The template ``finger-design --out DIR`` writes into DIR.
TEMPLATE = "finger.toml"


@click.command("finger-design")
@click.option("--target", help="End angles per joint [deg], e.g. 65,50,50 (a free closure; with --stroke).")
@click.option("--stroke", type=float, help="Tendon displacement at the end [mm] (with --target).")
@click.option(
    "--object",
    "objects",
    multiple=True,
    help="A target cylinder to grasp, e.g. cylinder:diameter=40,x=20,y=25,mu=0.5 (mm; repeatable): design for "
    "grasps instead of a free closure.",
)
@click.option(
    "--cylinders",
    help="Target cylinders at the held position (docs/grasp.md): diameters START:STOP:STEP [mm] "
    "(25:55:10 = 25, 35, 45, 55) or a list (25,40,55).",
)
@click.option("--mu", type=float, default=0.0, show_default=True, help="Contact friction of the --cylinders.")
@click.option(
    "--max-tension", type=float, default=10.0, show_default=True, help="Tendon tension each grasp ends at [N]."
)
@click.option(
    "--sequence", type=click.Choice(["simultaneous", "proximal-first"]), default="simultaneous", show_default=True
)
@click.option(
    "--base-stiffness",
    type=float,
    default=None,
    help=f"Softest joint [N·mm/rad]; default {FINGER.designed_stiffness[0]:g}, "
    "rescaled if a spring would not be printable.",
)
@click.option(
    "--material",
    default=DEFAULT_MATERIAL,
    show_default=True,
    shell_complete=complete_profiles("materials"),
    help="A material profile: a name or a .toml file (see rjcad profiles).",
)
@click.option(
    "--printer",
    default=DEFAULT_PRINTER,
    show_default=True,
    shell_complete=complete_profiles("printers"),
    help="A printer profile: a name or a .toml file (see rjcad profiles).",
)
@click.option(
    "--out",
    "out_dir",
    type=OutDir(legacy=(".toml",)),
    required=True,
    help=f"The folder to write the finger template {TEMPLATE} into (rjcad finger DIR/{TEMPLATE} builds it).",
)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object (the design's report).")
def finger_design(
    target, stroke, objects, cylinders, mu, max_tension, sequence, base_stiffness, material, printer, out_dir, as_json
):
    """Choose stiffnesses, preloads and moment arms for a desired free closure, or stiffnesses, ranges and link
    lengths that grasp target cylinders; write a finger template."""
    from pathlib import Path

    from rjcad.io.config import write_atomic
    from rjcad.physics.inverse import design_finger

    folder, name = out_file(out_dir, (".toml",), TEMPLATE)
    out_path = str(Path(folder) / name)
    if objects or cylinders:
        from rjcad.cli.grasp_design import grasp_design

        if target is not None or stroke is not None:
            raise click.UsageError("give --target/--stroke (a free closure) or --object/--cylinders (grasps)")
        return grasp_design(objects, cylinders, mu, max_tension, material, printer, out_path, as_json)
    if target is None or stroke is None:
        raise click.UsageError("give --target and --stroke (a free closure), or --object/--cylinders (grasps)")

    try:
        angles = [float(v) for v in target.split(",")]
    except ValueError:
        raise click.BadParameter(
            f"{quote(target)} is not a list of angles like 65,50,50", param_hint="--target"
        ) from None
    d = design_finger(angles, stroke, sequence, base_stiffness, material, printer)
    write_atomic(out_path, d.template(material, printer))
    rep = d.report()
    if as_json:
        click.echo(json.dumps(rep))
    else:
        print_finger_design(rep, out_path)


def print_finger_design(rep: dict, out_path: str) -> None:
    """The template written, the design's notes, and per joint: K, preload, arm, end error and onset."""
    click.echo(f"wrote {out_path}")
    for note in rep["notes"]:
        click.echo(f"  note: {note}")
    for i in range(len(rep["stiffness_nmm_per_rad"])):
        click.echo(
            f"  joint {i + 1}: K {rep['stiffness_nmm_per_rad'][i]:.3f} N·mm/rad, preload "
            f"{rep['preload_deg'][i]:.1f} deg, arm {rep['tendon_moment_arm_mm'][i]:.2f} mm, "
            f"end error {rep['end_error_deg'][i]:+.3f} deg, starts at {rep['onset_tendon_mm'][i]:.2f} mm"
        )
