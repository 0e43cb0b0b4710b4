"""``rjcad check``: check a mesh for printing; the exit code says if every check passed."""

from __future__ import annotations

import json

import click

from rjcad.materials import PRINTERS


@click.command()
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.option("--manifest", type=click.Path(dir_okay=False), help="The builder's JSON manifest (bodies, joints).")
@click.option("--clearance", type=float, help="Required gap between bodies [mm] (default: the manifest's, or 0.25).")
@click.option("--allowance", type=float, default=0.02, show_default=True, help="Tessellation allowance [mm].")
@click.option("--printer", type=str, help=f"One of: {', '.join(PRINTERS)} (default: the manifest's, or generic-0.4).")
@click.option("--bodies", "n_bodies", type=click.IntRange(1, 1000), help="Expected number of bodies.")
@click.option("--slicer", type=click.Choice(["prusa"]),
              help="Also slice every body with supports off and read the G-code back (PrusaSlicer 2.5).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def check(mesh, manifest, clearance, allowance, printer, n_bodies, slicer, as_json):
    """Check a mesh for printing: exit 0 all passed, 1 a check failed, 2 bad input."""
    from rjcad.check import format_table, run_checks

    rep = run_checks(mesh, manifest=manifest, clearance=clearance, printer=printer, slicer=slicer,
                     allowance=allowance, bodies=n_bodies)
    click.echo(json.dumps(rep.to_dict(), indent=2) if as_json else format_table(rep))
    return 0 if rep.passed else 1
