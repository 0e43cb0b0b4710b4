"""``rjcad check``: check meshes for printing; the exit code says if every check passed."""

from __future__ import annotations

import json
import os
import time
from datetime import datetime
from pathlib import Path

import click

from rjcad.cli.options import OutFile, complete_profiles
from rjcad.io.manifest import CLEARANCE_MM
from rjcad.materials import PRINTERS

#: ``--allowance`` range [mm]: the tessellation allowance on measured gaps and walls (the builder's
#: tolerance is 0.01 mm; the default 0.02 mm).
ALLOWANCE_MM = (0.0, 0.05)


@click.command()
@click.argument("meshes", metavar="MESH...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option(
    "--manifest", type=click.Path(dir_okay=False), help="The builder's JSON manifest (bodies, joints); one MESH only."
)
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
@click.option(
    "--printer",
    type=str,
    shell_complete=complete_profiles("printers"),
    help=f"One of: {', '.join(PRINTERS)} (default: the manifest's, or generic-0.4).",
)
@click.option("--bodies", "n_bodies", type=click.IntRange(1, 1000), help="Expected number of bodies.")
@click.option(
    "--slicer",
    type=click.Choice(["prusa"]),
    help="Also slice every body with supports off and read the G-code back (PrusaSlicer 2.5).",
)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option(
    "--junit",
    type=OutFile(),
    help="Also write JUnit XML for CI (a test suite per mesh, a case per check), whenever the checks ran.",
)
def check(meshes, manifest, clearance, allowance, printer, n_bodies, slicer, as_json, junit):
    """Check meshes for printing: exit 0 all passed, 1 a check failed, 2 bad input."""
    from rjcad.check import required_clearance, run_checks
    from rjcad.check.junit import Run, junit_xml
    from rjcad.check.load import mesh_file
    from rjcad.cli.progress import progress_line
    from rjcad.errors import BadInput, ParameterError
    from rjcad.io.config import write_atomic
    from rjcad.io.manifest import ManifestError
    from rjcad.materials import printer_of
    from rjcad.validate import in_range

    if clearance is not None:
        in_range("--clearance", clearance, *CLEARANCE_MM, unit="mm")
    in_range("--allowance", allowance, *ALLOWANCE_MM, unit="mm")
    if manifest and len(meshes) > 1:
        raise ParameterError("--manifest", manifest, f"describes one mesh: give one MESH with it ({len(meshes)} given)")
    for mesh in meshes:  # every file there before the first is checked
        mesh_file(mesh)
    if junit:
        _junit_not_a_mesh(junit, meshes)
    man = _manifest(manifest, meshes[0])
    prn = printer_of(printer, man)
    if clearance is not None:
        prn.check_gap("--clearance", clearance)
    elif man is not None:
        clearance = required_clearance(man, prn)
    runs = []
    for mesh in meshes:
        started, t0 = datetime.now(), time.perf_counter()
        title = f"check {Path(mesh).name}" if len(meshes) > 1 else "check"
        try:
            with progress_line(title) as progress:
                rep = run_checks(
                    mesh,
                    manifest=man,
                    clearance=clearance,
                    printer=printer,
                    slicer=slicer,
                    allowance=allowance,
                    bodies=n_bodies,
                    progress=progress,
                )
        except ManifestError as e:  # a key a check needs, missing: name the file
            raise (e.at(manifest) if manifest and e.source == "manifest" else e) from None
        except BadInput as e:  # among several meshes, say which
            if len(meshes) > 1 and not str(e).startswith(str(mesh)):
                raise BadInput(f"{mesh}: {e}") from None
            raise
        runs.append(Run(mesh, rep, time.perf_counter() - t0, started))
    if junit:
        write_atomic(junit, junit_xml(runs))
    click.echo(_output(runs, as_json))
    return 0 if all(r.report.passed for r in runs) else 1


def _junit_not_a_mesh(junit: str, meshes) -> None:
    """Refuse, before any check runs, a ``--junit`` file that is a mesh to check (``OutFile`` refused an unwritable
    one as the option was read)."""
    from rjcad.errors import ParameterError

    target = Path(os.path.abspath(junit))
    if any(target == Path(os.path.abspath(m)) for m in meshes):
        raise ParameterError("--junit", junit, "is a mesh to check: name another file")


def _output(runs, as_json: bool) -> str:
    """The table (or JSON) of one mesh as it always was; of several, each mesh's under its path, then a verdict."""
    from rjcad.check import format_table

    if len(runs) == 1:
        rep = runs[0].report
        return json.dumps(rep.to_dict(), indent=2) if as_json else format_table(rep)
    failed = [r.mesh for r in runs if not r.report.passed]
    if as_json:
        meshes = [{"mesh": r.mesh, **r.report.to_dict()} for r in runs]
        return json.dumps({"passed": not failed, "meshes": meshes}, indent=2)
    tables = [f"{r.mesh}\n{format_table(r.report)}" for r in runs]
    verdict = (
        f"FAILED: {len(failed)} of {len(runs)} meshes ({', '.join(failed)})"
        if failed
        else f"PASSED: all {len(runs)} meshes"
    )
    return "\n\n".join([*tables, verdict])


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
