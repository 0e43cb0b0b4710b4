"""``rjcad view``: write a built finger's interactive viewer, one self-contained HTML file (``rjcad.view``)."""

from __future__ import annotations

import click

from rjcad.cli.bearing_out import bearing_mu, friction_options
from rjcad.cli.options import OutDir, allow_outside_option, out_file
from rjcad.paper import FINGER
from rjcad.view import DEFAULT_STEPS

#: Tendon stroke the viewer accepts [mm] and the tendon friction coefficient (as ``rjcad simulate finger``).
MAX_STROKE_MM = 1000.0
MAX_MU_T = 2.0
#: ``--out``'s former form: the page's own file name (``--out page.html``).
HTML = (".html", ".htm")


def check_view_options(stroke: float, mu_t: float) -> None:
    """The viewer's physics options in their ranges (one error line naming the option, exit 2)."""
    from rjcad.validate import in_range

    in_range("--stroke", stroke, 0.0, MAX_STROKE_MM, lo_open=True, unit="mm")
    in_range("--mu-t", mu_t, 0.0, MAX_MU_T)


@click.command()
@click.argument("manifest", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_dir",
    type=OutDir(legacy=HTML),
    default=None,
    help="The folder to write <manifest stem>.html into (default: the manifest's folder).",
)
@click.option(
    "--stroke", type=float, default=FINGER.stroke, show_default=True, help="Tendon stroke the slider runs over [mm]."
)
@click.option(
    "--steps",
    type=click.IntRange(10, 100000),
    default=DEFAULT_STEPS,
    show_default=True,
    help="Samples of the closure over the stroke.",
)
@click.option("--mu-t", type=float, default=0.0, show_default=True, help="Tendon friction coefficient on its path.")
@click.option(
    "--object",
    "object_specs",
    multiple=True,
    metavar="SPEC",
    help="An object to close on (repeatable), as in `rjcad simulate finger --object`: the slider then runs over "
    "the closure's readings (the tension ramp, --steps of them, default 60) and the page draws the objects and "
    "the contact forces.",
)
@click.option(
    "--max-tension",
    type=float,
    default=None,
    help="With objects: the tendon's tension is ramped from 0 to this [N] (default 10).",
)
@friction_options
@allow_outside_option
def view(manifest, out_dir, stroke, steps, mu_t, object_specs, max_tension, friction, mu, allow_outside):
    """Write an interactive viewer of a built finger (FINGER.json, its .glb beside it): orbit, and a slider over
    the tendon stroke that closes the finger with the joint angles and tension of `rjcad simulate finger`.
    With objects (--object): the closure on them, the objects and the contact forces along the slider."""
    from pathlib import Path

    from click.core import ParameterSource

    from rjcad.physics.grasp_run import GRASP_STEPS, MAX_TENSION_N
    from rjcad.physics.objects import parse_object
    from rjcad.validate import in_range
    from rjcad.view import write_viewer

    name = Path(manifest).with_suffix(".html").name
    folder, name = out_file(out_dir, HTML, name) if out_dir is not None else (str(Path(manifest).parent), name)
    check_view_options(stroke, mu_t)
    objects = [parse_object(s) for s in object_specs]
    if max_tension is not None and not objects:
        raise click.BadParameter("only with objects (--object)", param_hint="--max-tension")
    if max_tension is not None:
        in_range("--max-tension", max_tension, 0.0, MAX_TENSION_N, lo_open=True, unit="N")
    given = click.get_current_context().get_parameter_source
    if objects and given("steps") is not ParameterSource.COMMANDLINE:
        steps = GRASP_STEPS
    out = Path(folder) / name
    mu = bearing_mu(friction, mu)
    from rjcad.physics.bearing_band import JointLocked

    try:
        write_viewer(
            manifest, out, stroke, steps, mu_t, allow_outside, objects=objects,
            max_tension_n=10.0 if max_tension is None else max_tension,
            grasp_stroke=stroke if given("stroke") is ParameterSource.COMMANDLINE else None, bearing_mu=mu,
        )  # fmt: skip
    except JointLocked as e:
        raise e.parameter_error("--mu", mu) from None
    click.echo(f"viewer written to {out} (open it in a browser; no network needed)")
