"""The physics commands: ``rjcad simulate joint|finger``, ``rjcad finger-design``, ``rjcad paper-finger``.

Defaults that are the paper's measured values come from ``rjcad.paper``; degrees here, rad inside.
"""

from __future__ import annotations

import json
import math

import click
from click.core import ParameterSource

from rjcad import DEG
from rjcad.cli.bearing_out import bearing_mu, echo_bands, friction_options, with_bearing
from rjcad.cli.options import OutDir, OutFile, either, renamed
from rjcad.errors import ParameterError
from rjcad.paper import FINGER, JOINT
from rjcad.progress import report


@click.group()
def simulate():
    """Simulate the joint's hysteresis loop or the finger's closure."""


def _plot(path, draw):
    """Write a 7 × 5 in, 100 dpi PNG of one axes that ``draw(ax)`` fills (``rjcad.plotting.axes_png``)."""
    from rjcad.plotting import axes_png

    axes_png(path, draw)


#: ``rjcad simulate joint``'s ranges: (low, high, unit); wide, but finite (the loop's exponentials overflow beyond).
JOINT_LIMITS = {
    "normal_load": (0.0, 1e3, "N"),
    "stiffness": (0.0, 1e4, "N·mm/rad"),
    "preload": (-360.0, 360.0, "deg"),
    "mu_j": (0.0, 100.0, "mm"),
    "gamma_pos": (-1e4, 1e4, "N·mm/rad"),
    "gamma_neg": (-1e4, 1e4, "N·mm/rad"),
    "beta_pos": (1.0, 100.0, ""),
    "beta_neg": (0.01, 1.0, ""),
    "tendon_moment_arm": (0.01, 100.0, "mm"),
}


@simulate.command("joint")
@click.option("--drive", type=click.Choice(["bar", "tendon"]), default="bar", show_default=True)
@click.option("--routed", is_flag=True, help="Tendon slides on its path in the base link (capstan).")
@click.option(
    "--normal-load", type=float, default=JOINT.normal_load, show_default=True, help="Transverse load F_n [N]."
)
@click.option("--stiffness", type=float, default=JOINT.stiffness, show_default=True, help="K_s [N·mm/rad].")
@click.option("--preload", type=float, default=JOINT.preload / DEG, show_default=True, help="θ_0 [deg].")
@click.option("--mu-j", type=float, default=JOINT.mu_j, show_default=True, help="Generalised pin friction μ_j [mm].")
@click.option("--gamma-pos", type=float, default=JOINT.gamma_pos, show_default=True, help="γ⁺ [N·mm/rad].")
@click.option("--gamma-neg", type=float, default=JOINT.gamma_neg, show_default=True, help="γ⁻ [N·mm/rad].")
@click.option("--beta-pos", type=float, default=JOINT.beta_pos, show_default=True, help="β⁺ (pulling, ≥ 1).")
@click.option("--beta-neg", type=float, default=JOINT.beta_neg, show_default=True, help="β⁻ (releasing, ≤ 1).")
@click.option(
    "--tendon-moment-arm",
    type=float,
    default=None,
    help=f"Tendon moment arm r about the joint's axis [mm] (the paper's pulley radius; default {JOINT.pulley_radius:g}).",
)
@renamed("--pulley-radius", "--tendon-moment-arm")
@click.option("--rotation", type=float, required=True, help="Cycle 0 → rotation → 0 [deg].")
@click.option(
    "--friction",
    type=click.Choice(["paper", "bearing"]),
    default="paper",
    show_default=True,
    help="paper: Eq. 3-7 with the options above; bearing: the bearing model of --geometry (docs/bearing.md).",
)
@click.option(
    "--geometry",
    type=click.Choice(["paper", "desktop"]),
    default="paper",
    show_default=True,
    help="With --friction bearing: the paper's joint (stacked, 70° preload) or rjcad's default desktop joint.",
)
@click.option(
    "--mu",
    type=float,
    default=None,
    help="With --friction bearing: μ of the material on itself (default: calibrated on the paper's bar test).",
)
@click.option("--json", "as_json", is_flag=True)
@click.option("--plot", type=OutFile(), help="Write the loop as a PNG.")
def simulate_joint(
    drive,
    routed,
    normal_load,
    stiffness,
    preload,
    mu_j,
    gamma_pos,
    gamma_neg,
    beta_pos,
    beta_neg,
    tendon_moment_arm,
    pulley_radius,
    rotation,
    friction,
    geometry,
    mu,
    as_json,
    plot,
):
    """Hysteresis loop of one joint over a 0 → rotation → 0 cycle (paper Eq. 3-7, or the bearing model)."""
    from rjcad.physics.joint import JointModel, Setup, cycle, tendon_slack
    from rjcad.physics.joint import simulate as run
    from rjcad.validate import in_range

    if friction == "bearing":
        _bearing_loop(drive, geometry, mu, rotation, as_json, plot)
        return
    for name in ("geometry", "mu"):
        if click.get_current_context().get_parameter_source(name) is ParameterSource.COMMANDLINE:
            raise click.BadParameter("only with --friction bearing", param_hint="--" + name)
    arm_flag = "--pulley-radius" if pulley_radius is not None else "--tendon-moment-arm"
    arm = either(tendon_moment_arm, pulley_radius, "--tendon-moment-arm", "--pulley-radius")
    arm = JOINT.pulley_radius if arm is None else arm
    if not 0 < rotation <= 360:
        raise click.BadParameter("must be in (0, 360] deg", param_hint="--rotation")
    given = dict(
        normal_load=normal_load,
        stiffness=stiffness,
        preload=preload,
        mu_j=mu_j,
        gamma_pos=gamma_pos,
        gamma_neg=gamma_neg,
        beta_pos=beta_pos,
        beta_neg=beta_neg,
        tendon_moment_arm=arm,
    )
    for name, (lo, hi, unit) in JOINT_LIMITS.items():
        in_range(
            arm_flag if name == "tendon_moment_arm" else "--" + name.replace("_", "-"), given[name], lo, hi, unit=unit
        )
    m = JointModel(
        stiffness=stiffness,
        preload=preload * DEG,
        mu_j=mu_j,
        gamma_pos=gamma_pos,
        gamma_neg=gamma_neg,
        beta_pos=beta_pos,
        beta_neg=beta_neg,
        pulley_radius=arm,
    )
    setup = Setup(drive, normal_load, routed)
    th, d = cycle(rotation * DEG)
    y = run(m, setup, th, direction=d)
    slack = tendon_slack(m, setup, th, direction=d)
    _report_loop(setup.quantity, th, d, y, slack, as_json, plot)


#: Samples of a --friction bearing cycle (a bearing solve each: 3° steps over 90°).
BEARING_SAMPLES = 61
#: The paper-model options --friction bearing takes from the geometry instead.
PAPER_OPTIONS = (
    "routed",
    "normal_load",
    "stiffness",
    "preload",
    "mu_j",
    "gamma_pos",
    "gamma_neg",
    "beta_pos",
    "beta_neg",
    "tendon_moment_arm",
    "pulley_radius",
)


def _bearing_loop(drive: str, geometry: str, mu: float | None, rotation: float, as_json: bool, plot) -> None:
    """``simulate joint --friction bearing``: the loop with friction from the bearing model (rjcad.physics)."""
    import numpy as np

    from rjcad.design.params import JointParams
    from rjcad.physics import bearing_paper as BP
    from rjcad.physics.bearing import BearingLocked
    from rjcad.physics.joint import Setup, cycle
    from rjcad.validate import in_range

    ctx = click.get_current_context()
    for name in PAPER_OPTIONS:
        if ctx.get_parameter_source(name) is ParameterSource.COMMANDLINE:
            hint = "--" + name.replace("_", "-")
            raise click.BadParameter("not with --friction bearing (the geometry gives it)", param_hint=hint)
    p = BP.paper_joint() if geometry == "paper" else JointParams()
    if not 0 < rotation * DEG <= p.rotation + 1e-9:
        raise click.BadParameter(
            f"must be in (0, {p.rotation / DEG:g}] deg, the joint's range", param_hint="--rotation"
        )
    mu = BP.calibrate() if mu is None else mu
    in_range("--mu", mu, 0.0, 2.0)
    th, d = cycle(rotation * DEG, BEARING_SAMPLES)
    try:
        y = BP.cycle_drive(p, mu, drive, th, d)
    except BearingLocked:
        raise ParameterError("--mu", mu, "locks this joint: the drive's own friction outgrows the drive") from None
    slack = y <= 0.0 if drive == "tendon" else np.zeros(len(y), dtype=bool)
    _report_loop(Setup(drive).quantity, th, d, y, slack, as_json, plot)


def _report_loop(quantity: str, th, d, y, slack, as_json: bool, plot) -> None:
    """The loop's slack warning, plot and printout (JSON or one line)."""
    import numpy as np

    from rjcad.physics.joint import loop_width

    if slack.any():
        _warn_slack(th, d, slack)
    if plot:

        def draw(ax):
            for sgn, lab in ((1, "flexing"), (-1, "extending")):
                k = d == sgn
                ax.plot(np.degrees(th[k]), y[k], label=lab)
            ax.set_xlabel("joint angle θ_j [deg]")
            ax.set_ylabel("torque [N·mm]" if quantity == "torque_nmm" else "tendon force at the actuator [N]")
            ax.legend()

        _plot(plot, draw)
    _print_loop(quantity, th, d, y, slack, loop_width(th, y, d, ~slack), as_json)


def _warn_slack(th, d, slack) -> None:
    """The warning line for a cycle whose tendon goes slack (where, and below which angle while releasing)."""
    rel = slack & (d < 0)
    if rel.sum() == (d < 0).sum():
        where = "the whole release"
    elif rel.any():
        where = f"{int(rel.sum())} of {int((d < 0).sum())} release samples"
    else:
        where = f"{int(slack.sum())} samples"
    below = (
        f" (the required force is negative below {math.degrees(th[rel].max()):.0f}° while releasing)"
        if rel.any()
        else ""
    )
    click.echo(
        f"rjcad: warning: the tendon is slack over {where}{below}: the joint is held by friction "
        "and the model's force there is 0; loop figures use the taut samples only",
        err=True,
    )


def _print_loop(quantity: str, th, d, y, slack, width, as_json: bool) -> None:
    """The cycle as JSON (every sample), or one summary line (range where taut, mean loop width)."""
    import numpy as np

    if as_json:
        out = {
            "theta_deg": [math.degrees(v) for v in th],
            "direction": [int(v) for v in d],
            quantity: y.tolist(),
            "slack": [bool(v) for v in slack],
            "slack_samples": int(slack.sum()),
            "loop_width": width,
        }
        click.echo(json.dumps(out))
        return
    taut = y[~slack] if (~slack).any() else y
    text = (
        f"mean loop width {width:.3f}" + (" (taut samples only)" if slack.any() else "")
        if width is not None
        else "no loop width: the tendon is slack on one branch at every angle"
    )
    click.echo(
        f"{quantity}: {len(th)} samples, from {np.min(taut):.3f} to {np.max(taut):.3f}"
        + (f" where taut ({int(slack.sum())} slack)" if slack.any() else "")
        + f"; {text}"
    )


#: Tendon stroke a finger simulation accepts [mm] (a finger closes within tens of mm) and the
#: tendon friction coefficient (dry polymer on polymer is 0.1–0.5).
MAX_STROKE_MM = 1000.0
MAX_MU_T = 2.0


@simulate.command("finger")
@click.argument("source", required=False, type=click.Path(dir_okay=False))
@click.option("--stroke", type=float, default=FINGER.stroke, show_default=True, help="Tendon displacement [mm].")
@click.option("--steps", type=click.IntRange(10, 100000), default=500, show_default=True)
@click.option("--mu-t", type=float, default=0.0, show_default=True, help="Tendon friction coefficient on its path.")
@click.option("--json", "as_json", is_flag=True)
@click.option("--plot", type=OutFile(), help="Write θ_i(t_d) as a PNG.")
@click.option(
    "--engine",
    type=click.Choice(["rjcad", "mujoco"]),
    default="rjcad",
    show_default=True,
    help="rjcad's solver, or MuJoCo (SOURCE may then also be an MJCF .xml).",
)
@click.option("--compare", is_flag=True, help="Run both engines; overlay them in --plot (the JSON is --engine's).")
@click.option(
    "--gravity",
    default=None,
    help="Gravity relative to the finger, on the links' weights (a manifest's masses), as rjcad mjcf --gravity "
    "[default: off; an MJCF has its own].",
)
@click.option(
    "--object",
    "object_specs",
    multiple=True,
    metavar="SPEC",
    help="An object to close on (repeatable; a template's [[object]] tables too), in the base's frame: "
    "cylinder:diameter=40,x=20,y=25 or box:w=30,h=20,x=..,y=..,angle=DEG; options mu=0.5, fixed or free with "
    "mass=GRAMS. The drive is then the tension ramp (--max-tension), --stroke stops it only if given.",
)
@click.option(
    "--max-tension",
    type=float,
    default=None,
    help="With objects: the tendon's tension is ramped from 0 to this [N] (default 10).",
)
@friction_options
def simulate_finger(
    source, stroke, steps, mu_t, as_json, plot, engine, compare, gravity, object_specs, max_tension, friction, mu
):
    """Finger closure, pull then release: a finger manifest (.json) or template (.toml; default: the paper's).
    With objects (--object, or a template's [[object]] tables): the closure on them as the tension rises."""
    import numpy as np

    from rjcad.cli.progress import progress_line
    from rjcad.validate import in_range

    in_range("--mu-t", mu_t, 0.0, MAX_MU_T)
    mu = _bearing_mu(friction, mu, engine, compare)
    if _grasp(source, object_specs, max_tension, stroke, steps, mu_t, as_json, plot, engine, compare, gravity, mu):
        return
    in_range("--stroke", stroke, 0.0, MAX_STROKE_MM, lo_open=True, unit="mm")
    grav = _finger_gravity(source, gravity)
    runs, bands = {}, []
    with progress_line("simulate finger") as progress:
        for e in ("rjcad", "mujoco") if compare else (engine,):
            what = (
                "MuJoCo: loading the model and running" if e == "mujoco" else "rjcad's solver (compiled on first use)"
            )
            if mu is not None:
                report(progress, "each joint's friction from its bearing")
            report(progress, f"pull and release, {what}")
            runs[e], bands = _finger_run(e, source, stroke, steps, mu_t, grav, mu)
        if plot:
            report(progress, "plotting")
            _plot_closure(plot, runs, compare)
    c = runs[engine]
    if as_json:
        out = c.to_dict()
        if bands:
            out["bearing_friction"] = [b.to_dict() for b in bands]
        click.echo(json.dumps(out))
        return
    echo_bands(bands)
    for name, run in runs.items():
        end = np.degrees(run.theta[steps])
        click.echo(
            f"{name + ': ' if compare else ''}at {stroke:g} mm: θ = ({', '.join(f'{v:.1f}' for v in end)}) "
            f"deg, tension {run.tension[steps]:.2f} N"
        )
    _echo_sag(runs, source, gravity)


def _bearing_mu(friction: str, mu: float | None, engine: str, compare: bool) -> float | None:
    """``simulate finger``'s μ for the bearing's friction (None: --friction none); MuJoCo refused."""
    if friction == "bearing" and (engine == "mujoco" or compare):
        raise click.BadParameter(
            "rjcad's engine only: MuJoCo's joint friction is a constant, the bearing's grows with the tendon's "
            "tension (docs/bearing.md)",
            param_hint="--friction bearing",
        )
    return bearing_mu(friction, mu)


def _grasp(source, object_specs, max_tension, stroke, steps, mu_t, as_json, plot, engine, compare, gravity, mu) -> bool:
    """``simulate finger`` with objects (``--object``, a template's tables): run it and say True; else False."""
    from rjcad.cli.grasp_out import simulate_grasp
    from rjcad.physics.grasp_run import GRASP_STEPS, template_objects
    from rjcad.physics.objects import parse_object

    objects = [*template_objects(source), *(parse_object(s) for s in object_specs)]
    if not objects:
        if max_tension is not None:
            raise click.BadParameter(
                "only with objects (--object, or a template's [[object]] tables)", param_hint="--max-tension"
            )
        return False
    given = click.get_current_context().get_parameter_source
    simulate_grasp(
        source, objects, engine=engine, compare=compare, max_tension_n=10.0 if max_tension is None else max_tension,
        stroke=stroke if given("stroke") is ParameterSource.COMMANDLINE else None,
        steps=steps if given("steps") is ParameterSource.COMMANDLINE else GRASP_STEPS, mu_t=mu_t,
        gravity=_finger_gravity(source, gravity), as_json=as_json, plot=plot, bearing_mu=mu,
    )  # fmt: skip
    return True


def _plot_closure(plot: str, runs: dict, compare: bool) -> None:
    """``simulate finger --plot``: each joint's angle against the tendon, pull and release, per engine."""
    import numpy as np

    def draw(ax):
        for k, (name, run) in enumerate(runs.items()):
            pull = np.array([p == "pull" for p in run.phase])
            for i in range(run.theta.shape[1]):
                tag = f"{name} " if compare else ""
                ax.plot(
                    run.tendon_mm[pull],
                    np.degrees(run.theta[pull, i]),
                    color=f"C{i}",
                    lw=1.6 - 0.7 * k,
                    ls="-" if k == 0 else ":",
                    label=f"{tag}θ{i + 1} pull",
                )
                ax.plot(
                    run.tendon_mm[~pull],
                    np.degrees(run.theta[~pull, i]),
                    color=f"C{i}",
                    lw=1.6 - 0.7 * k,
                    ls="--" if k == 0 else "-.",
                    label=f"{tag}θ{i + 1} release",
                )
        ax.set_xlabel("tendon displacement t_d [mm]")
        ax.set_ylabel("joint angle [deg]")
        ax.legend(fontsize=7, ncol=2 if compare else 1)

    _plot(plot, draw)


def _finger_gravity(source, gravity: str | None) -> tuple[float, float, float] | None:
    """``--gravity`` in the finger frame [m/s²] (None: off); refused with an MJCF, which carries its own."""
    from pathlib import Path

    if gravity is None:
        return None
    if source is not None and Path(source).suffix.lower() == ".xml":
        raise ParameterError("--gravity", gravity, "an MJCF has its own (its base's orientation): leave it out")
    from rjcad.mjcf.export import gravity_of

    g = gravity_of(gravity)
    return g if any(g) else None


def _echo_sag(runs: dict, source, gravity: str | None) -> None:
    """The one-line note (stderr) for each engine whose first reading (t_d = 0: the rest pose, the tendon slack)
    has a joint off its extension stop: the springs cannot hold the finger against its weight."""
    from rjcad.mjcf.sag import sag_note

    where = f"--gravity {gravity}" if gravity is not None else "the MJCF's orientation"
    for name, run in runs.items():
        note = sag_note(run.theta[0], where, "rjcad's statics" if name == "rjcad" else "MuJoCo, settled at ctrl 0")
        if note:
            click.echo(note, err=True)


def _finger_run(engine: str, source, stroke: float, steps: int, mu_t: float, gravity=None, mu: float | None = None):
    """The pull/release of ``source`` by one engine (a ``Closure``), under ``gravity`` [m/s², finger frame], and
    the joints' bearing bands where ``mu`` is given (rjcad's engine only)."""
    from pathlib import Path

    if engine == "mujoco":
        if mu_t > 0:
            raise ParameterError(
                "--mu-t", mu_t, "MuJoCo has no capstan (one tension along a tendon): use 0 with --engine mujoco"
            )
        from rjcad.cli.mjcf import mujoco_model
        from rjcad.mjcf.simulate import raise_warnings, run_stroke

        closure = run_stroke(mujoco_model(source, gravity), stroke, steps)
        raise_warnings(str(source or "the paper's finger"))
        return closure, []
    if source is not None and Path(source).suffix.lower() == ".xml":
        raise ParameterError("SOURCE", source, "an MJCF runs only with --engine mujoco (without --compare)")
    from rjcad.physics.finger import simulate_stroke
    from rjcad.physics.finger_sources import load_finger_model

    model = load_finger_model(source, mu_t=mu_t)
    if gravity is not None:
        from dataclasses import replace

        from rjcad.mjcf.export import G

        model = replace(model, gravity=(gravity[0] / G, gravity[1] / G))
    if mu_t > 0 and not any(model.wrap):
        raise ParameterError(
            "--mu-t",
            mu_t,
            "has nothing to act on: this finger's joints carry no tendon wrap "
            "angle (a template has none); give a finger manifest (.json) that "
            "`rjcad finger` wrote, whose joints carry their measured wraps",
        )
    model, bands = with_bearing(model, source, mu)
    return simulate_stroke(model, stroke, steps=steps), bands


@click.command("paper-finger")
@click.option(
    "--out", "out_dir", type=OutDir(), default="docs", show_default=True, help="The folder to write the page into."
)
@click.option(
    "--manifest",
    type=click.Path(dir_okay=False),
    help="Built finger manifest (out/finger/finger.json) for the design model's moment arms; "
    "default: the joint builder's design arm.",
)
@click.option(
    "--records",
    is_flag=True,
    help="Also write paper-finger-records.md: SYNTHETIC full records of the families that fit the "
    "endpoint, identified blind (about a minute).",
)
def paper_finger(out_dir, manifest, records):
    """Regenerate docs/paper-finger.md: the paper's finger, the design model's error and its explanations."""
    from rjcad.physics.paper_finger import write_doc, wrote

    exps = write_doc(out_dir, manifest)
    click.echo(wrote(out_dir, len(exps)))
    if records:
        from rjcad.identify.finger.paper import write_doc as write_records

        click.echo(f"wrote {write_records(out_dir)}")
