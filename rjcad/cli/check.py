"""``rjcad check``: check a mesh for printing; the exit code says if every check passed."""

from __future__ import annotations

import json
from pathlib import Path

import click

from rjcad.io.manifest import CLEARANCE_MM
from rjcad.materials import PRINTERS

#: ``--allowance`` range [mm]: the tessellation allowance on measured gaps and walls (the builder's
#: tolerance is 0.01 mm; the default 0.02 mm).
ALLOWANCE_MM = (0.0, 0.05)


@click.command()
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.option("--manifest", type=click.Path(dir_okay=False), help="The builder's JSON manifest (bodies, joints).")
@click.option(
    "--clearance",
    type=float,
    help="Required gap between bodies [mm], in [{:g}, {:g}] and at least the printer's minimum gap "
    "(default: the manifest's, raised to the printer's minimum gap; or 0.25).".format(*CLEARANCE_MM),
)
@click.option(
    "--allowance",
    type=float,
    default=0.02,
    show_default=True,
    help="Tessellation allowance [mm], in [{:g}, {:g}].".format(*ALLOWANCE_MM),
)
@click.option("--printer", type=str, help=f"One of: {', '.join(PRINTERS)} (default: the manifest's, or generic-0.4).")
@click.option("--bodies", "n_bodies", type=click.IntRange(1, 1000), help="Expected number of bodies.")
@click.option(
    "--slicer",
    type=click.Choice(["prusa"]),
    help="Also slice every body with supports off and read the G-code back (PrusaSlicer 2.5).",
)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def check(mesh, manifest, clearance, allowance, printer, n_bodies, slicer, as_json):
    """Check a mesh for printing: exit 0 all passed, 1 a check failed, 2 bad input."""
    from rjcad.check import format_table, required_clearance, run_checks
    from rjcad.io.manifest import ManifestError
    from rjcad.materials import printer_of
    from rjcad.validate import in_range

    if clearance is not None:
        in_range("--clearance", clearance, *CLEARANCE_MM, unit="mm")
    in_range("--allowance", allowance, *ALLOWANCE_MM, unit="mm")
    man = _manifest(manifest, mesh)
    prn = printer_of(printer, man)
    if clearance is not None:
        prn.check_gap("--clearance", clearance)
    elif man is not None:
        clearance = required_clearance(man, prn)
    try:
        rep = run_checks(
            mesh,
            manifest=man,
            clearance=clearance,
            printer=printer,
            slicer=slicer,
            allowance=allowance,
            bodies=n_bodies,
        )
    except ManifestError as e:  # a key a check needs, missing: name the file
        raise (e.at(manifest) if manifest and e.source == "manifest" else e) from None
    click.echo(json.dumps(rep.to_dict(), indent=2) if as_json else format_table(rep))
    return 0 if rep.passed else 1


def _manifest(path: str | None, mesh: str):
    """The manifest file, read (rjcad.io.untrusted) and checked; an STL's bodies can only be named by its ``bodies``."""
    from rjcad.check import motion_joints
    from rjcad.io.manifest import Manifest, ManifestError

    if not path:
        return None
    man = Manifest.read(path)
    if Path(mesh).suffix.lower() == ".stl" and man.bodies is None and man.joints:
        try:
            moving = motion_joints(man)
        except ManifestError as e:
            raise e.at(path) from None
        if moving:
            raise ManifestError(
                "bodies",
                None,
                "is required with an STL mesh: the motion check names its bodies by their volumes",
                source=path,
            )
    return man
