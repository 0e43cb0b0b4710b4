"""Command line: parse, call, print. Degrees here, radians inside.

Every user-facing error is one line on stderr and exit code 2; ``--debug``
adds the traceback.
"""

from __future__ import annotations

import json
import math
import sys
import traceback

import click

from rjcad import spring as sp
from rjcad.spring.optimise import design_spring
from rjcad.config import load_toml
from rjcad.errors import RjcadError
from rjcad.materials import MATERIALS, PRINTERS


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks on errors.")
@click.version_option(package_name="rjcad")
def cli(debug: bool) -> None:
    """Design, build and check 3D-printable elastic joints for robotic fingers."""


# Spring requirement: CLI option → (SpringRequirement field, TOML key, type, to-internal).
_SPRING_FIELDS = {
    "stiffness": ("joint_stiffness", "stiffness_nmm_per_rad", float, float),
    "rotation": ("rotation", "rotation_deg", float, math.radians),
    "preload": ("preload", "preload_deg", float, math.radians),
    "material": ("material", "material", str, str),
    "printer": ("printer", "printer", str, str),
    "safety_factor": ("safety_factor", "safety_factor", float, float),
    "end": ("end", "end", str, str),
    "width_min": ("width_min", "width_min_mm", float, float),
    "width_max": ("width_max", "width_max_mm", float, float),
    "inner_radius_min": ("inner_radius_min", "inner_radius_min_mm", float, float),
    "inner_radius_max": ("inner_radius_max", "inner_radius_max_mm", float, float),
    "max_outer_radius": ("outer_radius_max", "max_outer_radius_mm", float, float),
    "min_turns": ("min_turns", "min_turns", float, float),
    "min_cycles": ("min_cycles", "min_cycles", float, float),
    "backlash": ("backlash", "backlash_mm", float, float),
}


def _merge_config(options: dict, config: str | None, fields: dict) -> dict:
    """defaults < config file < explicit options; ``fields``: option → (kwarg, TOML key, type, convert)."""
    given = {k: v for k, v in options.items() if v is not None and k in fields}
    if config:
        toml_types = {key: ((int, float) if typ is float else typ) for _, key, typ, _ in fields.values()}
        by_key = {key: opt for opt, (_, key, _, _) in fields.items()}
        for key, value in load_toml(config, toml_types).items():
            given.setdefault(by_key[key], value)
    return {fields[opt][0]: fields[opt][3](fields[opt][2](v)) for opt, v in given.items()}


def _requirement(options: dict, config: str | None) -> sp.SpringRequirement:
    """Merge defaults < config file < explicit options into a SpringRequirement."""
    kwargs = _merge_config(options, config, _SPRING_FIELDS)
    if "joint_stiffness" not in kwargs:
        raise click.UsageError("missing --stiffness (or stiffness_nmm_per_rad in --config)")
    kwargs.setdefault("rotation", math.radians(90.0))
    return sp.SpringRequirement(**kwargs)


def _print_table(rows: list[tuple[str, str, str]]) -> None:
    w0 = max(len(r[0]) for r in rows)
    w1 = max(len(r[1]) for r in rows)
    for name, value, unit in rows:
        click.echo(f"  {name:<{w0}}  {value:>{w1}}  {unit}")


@cli.command()
@click.option("--stiffness", type=float, help="Joint stiffness, both springs [N·mm/rad].")
@click.option("--rotation", type=float, help="Joint rotation range [deg] (default 90).")
@click.option("--preload", type=float, help="Spring preload at rest [deg] (default 90).")
@click.option("--material", type=str, help=f"One of: {', '.join(MATERIALS)} (default absplus-p430).")
@click.option("--printer", type=str, help=f"One of: {', '.join(PRINTERS)} (default generic-0.4).")
@click.option("--safety-factor", type=float, help="Safety factor on yield (default 1.5).")
@click.option("--end", type=str, help="Outer end condition: pinned (default, a hook on a pin) or clamped.")
@click.option("--width-min", type=float, help="Lower bound on spring width b [mm] (default 1).")
@click.option("--width-max", type=float, help="Upper bound on spring width b [mm] (default 10).")
@click.option("--inner-radius-min", type=float, help="Lower bound on the inner (pin) radius [mm] (default 3).")
@click.option("--inner-radius-max", type=float, help="Upper bound on the inner (pin) radius [mm] (default 10).")
@click.option("--max-outer-radius", type=float, help="Largest allowed outer radius [mm] (default 20).")
@click.option("--min-turns", type=float, help="Fewest turns of the spiral (default 1).")
@click.option("--min-cycles", type=float, help="Required life: lower 90 % bound of the predicted cycles.")
@click.option("--backlash", type=float, help="Pin backlash for the life model [mm] (default 0.25).")
@click.option("--config", type=click.Path(dir_okay=False), help="TOML file with the same keys (see templates/).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def spring(config, as_json, **options):
    """Design the twin spiral springs of one joint (smallest outer radius)."""
    design = design_spring(_requirement(options, config))
    d = design.to_dict()
    if as_json:
        click.echo(json.dumps(d, indent=2))
        return
    req = design.requirement
    click.echo(f"Spiral spring for a {req.joint_stiffness:g} N·mm/rad joint "
               f"(two springs of {req.spring_stiffness:g}), {d['rotation_deg']:g}° rotation, "
               f"{d['preload_deg']:g}° preload, {req.material}, {req.printer}, {req.end} outer end")
    _print_table([
        ("width b", f"{d['width_mm']:.3f}", "mm"),
        ("thickness t", f"{d['thickness_mm']:.3f}", "mm"),
        ("length L", f"{d['length_mm']:.2f}", "mm"),
        ("inner radius r_in", f"{d['inner_radius_mm']:.3f}", "mm (centreline)"),
        ("pitch p", f"{d['pitch_mm']:.4f}", "mm"),
        ("turns n", f"{d['turns']:.3f}", ""),
        ("outer radius", f"{d['outer_radius_mm']:.3f}", "mm (envelope, hook excluded)"),
        ("spring stiffness", f"{d['spring_stiffness_nmm_per_rad']:.4f}", "N·mm/rad (one spring)"),
        ("joint stiffness", f"{d['joint_stiffness_nmm_per_rad']:.4f}", "N·mm/rad (both)"),
        ("peak stress", f"{d['max_stress_mpa']:.2f}", f"MPa at {d['rotation_deg'] + d['preload_deg']:g}° wind-up"),
        ("allowed stress", f"{d['allowed_stress_mpa']:.2f}", f"MPa (yield / {req.safety_factor:g})"),
        ("coil gap, wound", f"{d['min_coil_gap_mm']:.3f}", "mm at maximum wind-up"),
        ("coil gap, printed", f"{d['print_coil_gap_mm']:.3f}", "mm"),
        ("preload torque", f"{d['preload_torque_nmm']:.2f}", "N·mm (joint)"),
        ("max torque", f"{d['max_torque_nmm']:.2f}", "N·mm (joint)"),
        ("predicted life", f"{d['predicted_cycles']:.3g}",
         f"cycles (90 %: {d['predicted_cycles_interval'][0]:.2g}-{d['predicted_cycles_interval'][1]:.2g}; "
         f"backlash {d['backlash_mm']:g} mm; see rjcad life)"),
    ])


_JOINT_FIELDS = {
    "stiffness": ("stiffness", "stiffness_nmm_per_rad", float, float),
    "rotation": ("rotation", "rotation_deg", float, math.radians),
    "preload": ("preload", "preload_deg", float, math.radians),
    "material": ("material", "material", str, str),
    "printer": ("printer", "printer", str, str),
    "clearance": ("clearance", "clearance_mm", float, float),
    "link_length": ("link_length", "link_length_mm", float, float),
    "tendon_diameter": ("tendon_diameter", "tendon_diameter_mm", float, float),
    "tendon_moment_arm": ("tendon_moment_arm", "tendon_moment_arm_mm", float, float),
    "pin_radius": ("pin_radius", "pin_radius_mm", float, float),
    "safety_factor": ("safety_factor", "safety_factor", float, float),
    "end": ("end", "end", str, str),
}


@cli.command()
@click.option("--stiffness", type=float, help="Joint stiffness, both springs [N·mm/rad] (default 5.2).")
@click.option("--rotation", type=float, help="Joint rotation range [deg] (default 90).")
@click.option("--preload", type=float, help="Spring preload at rest [deg] (default 90).")
@click.option("--material", type=str, help=f"One of: {', '.join(MATERIALS)} (default absplus-p430).")
@click.option("--printer", type=str, help=f"One of: {', '.join(PRINTERS)} (default generic-0.4).")
@click.option("--clearance", type=float, help="Clearance between the bodies [mm] (default 0.25).")
@click.option("--link-length", type=float, help="Axis to link end, each link [mm] (default 40).")
@click.option("--tendon-diameter", type=float, help="Tendon channel diameter [mm] (default 1.0).")
@click.option("--tendon-moment-arm", type=float, help="Tendon moment arm about the axis [mm] (default 6).")
@click.option("--pin-radius", type=float, help="Knuckle pin radius [mm] (default 2).")
@click.option("--safety-factor", type=float, help="Safety factor on yield (default 1.5).")
@click.option("--end", type=str, help="Spring outer end: pinned (default) or clamped.")
@click.option("--config", type=click.Path(dir_okay=False), help="TOML design (see templates/joint.toml).")
@click.option("--out", "out_dir", type=click.Path(file_okay=False), default="out/joint", show_default=True,
              help="Output directory.")
@click.option("--no-png", is_flag=True, help="Skip the preview image.")
def joint(config, out_dir, no_png, **options):
    """Build the one-piece joint module: STL, 3MF, STEP, PNG preview and JSON manifest."""
    from rjcad.cad.build import write_joint
    from rjcad.params import JointParams

    params = JointParams(**_merge_config(options, config, _JOINT_FIELDS))
    b = write_joint(params, out_dir, png=not no_png)
    m = b.manifest
    click.echo(f"joint written to {out_dir}/joint.{{stl,3mf,step{'' if no_png else ',png'},json}}")
    _print_table([
        ("joint stiffness", f"{m['joint_stiffness_nmm_per_rad']:.3f}", "N·mm/rad (both springs)"),
        ("spring b × t × L", f"{m['spring']['width_mm']:.2f} × {m['spring']['thickness_mm']:.2f} × "
                             f"{m['spring']['length_mm']:.1f}", "mm"),
        ("spring outer radius", f"{m['spring']['outer_radius_mm']:.2f}", "mm"),
        ("tendon moment arm", f"{m['tendon_moment_arm_mm']:.3f}", "mm (measured)"),
        ("tendon wrap angle", f"{m['tendon_wrap_angle_rad']:.3f}", "rad in the ground channel (measured)"),
        ("min gap between bodies", f"{m['measured_min_gap_mm']:.3f}", "mm (on the mesh)"),
        ("bodies", ", ".join(f"{b_['name']} {b_['mass_g']:.1f} g" for b_ in m["bodies"]), ""),
        ("triangles", f"{m['mesh']['triangles']}", ""),
    ])


@cli.command()
@click.argument("template", required=False, type=click.Path(dir_okay=False))
@click.option("--out", "out_dir", type=click.Path(file_okay=False), default="out/finger", show_default=True,
              help="Output directory.")
@click.option("--no-png", is_flag=True, help="Skip the preview image.")
def finger(template, out_dir, no_png):
    """Build a finger of chained joint modules (default: the paper's finger, templates/finger.toml)."""
    from rjcad.cad.build import write_finger
    from rjcad.cad.finger import PAPER_FINGER, FingerParams

    fp = FingerParams.from_toml(template) if template else FingerParams.from_dict(PAPER_FINGER, "built-in paper finger")
    b = write_finger(fp, out_dir, png=not no_png)
    m = b.manifest
    click.echo(f"finger written to {out_dir}/finger.{{stl,3mf,step{'' if no_png else ',png'},json}} "
               f"({fp.n} joints, {len(m['bodies'])} bodies, {m['mesh']['triangles']} triangles)")
    rows = [(f"joint {i + 1} ({j['parent']} → {j['child']})",
             f"K {j['joint_stiffness_nmm_per_rad']:.2f}  r {j['tendon_moment_arm_mm']:.2f}  "
             f"wrap {j['tendon_wrap_angle_rad']:.3f}",
             "N·mm/rad, mm, rad") for i, j in enumerate(m["joints"])]
    rows.append(("tendon length at rest", f"{m['tendon_length_mm']:.1f}", "mm"))
    rows.append(("bodies", ", ".join(f"{b_['name']} {b_['mass_g']:.1f} g" for b_ in m["bodies"]), ""))
    _print_table(rows)


@cli.command()
@click.argument("sweep_file", type=click.Path(dir_okay=False))
@click.option("--out", "out_dir", type=click.Path(file_okay=False), default="out/sweep", show_default=True)
@click.option("--workers", type=click.IntRange(0, 256),
              help="Local worker processes (default: the cores; 0 runs in this process).")
@click.option("--scheduler", help="Dask distributed scheduler address, e.g. tcp://host:8786.")
@click.option("--build", is_flag=True, help="Build and check the joint of every feasible design.")
@click.option("--keep-meshes", is_flag=True, help="With --build: keep each design's STL in OUT/meshes.")
@click.option("--resume", is_flag=True, help="Skip designs already in OUT/results.csv.")
def sweep(sweep_file, out_dir, workers, scheduler, build, keep_meshes, resume):
    """Sweep design parameters (analytic by default; --build for CAD + checks)."""
    from rjcad.sweep import SweepSpec, run_sweep

    spec = SweepSpec.from_toml(sweep_file)
    res = run_sweep(spec, out_dir, build=build, workers=workers, scheduler=scheduler, resume=resume,
                    keep_meshes=keep_meshes)
    status: dict[str, int] = {}
    for r in res.rows:
        status[r.get("status", "")] = status.get(r.get("status", ""), 0) + 1
    click.echo(f"sweep: {len(res.rows)} designs ({res.computed} computed, {res.skipped} resumed) in "
               f"{res.seconds:.2f} s; " + ", ".join(f"{k}: {v}" for k, v in sorted(status.items())))
    click.echo(f"wrote {out_dir}/results.csv, pareto.png, summary.md")


@cli.command()
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.option("--manifest", type=click.Path(dir_okay=False), help="The builder's JSON manifest (bodies, joints).")
@click.option("--clearance", type=float, help="Required gap between bodies [mm] (default: the manifest's, or 0.25).")
@click.option("--allowance", type=float, default=0.02, show_default=True, help="Tessellation allowance [mm].")
@click.option("--printer", type=str, help=f"One of: {', '.join(PRINTERS)} (default: the manifest's, or generic-0.4).")
@click.option("--bodies", "n_bodies", type=click.IntRange(1, 1000), help="Expected number of bodies.")
@click.option("--slicer", type=click.Choice(["prusa"]), help="Also slice with this slicer.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def check(mesh, manifest, clearance, allowance, printer, n_bodies, slicer, as_json):
    """Check a mesh for printing: exit 0 all passed, 1 a check failed, 2 bad input."""
    from rjcad.check import format_table, run_checks

    rep = run_checks(mesh, manifest=manifest, clearance=clearance, printer=printer, slicer=slicer,
                     allowance=allowance, bodies=n_bodies)
    click.echo(json.dumps(rep.to_dict(), indent=2) if as_json else format_table(rep))
    return 0 if rep.passed else 1


@cli.group()
def simulate():
    """Simulate the joint's hysteresis loop or the finger's closure."""


def _plot(path, draw):
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rjcad.config import write_atomic

    fig, ax = plt.subplots(figsize=(7, 5))
    draw(ax)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    write_atomic(path, buf.getvalue())


@simulate.command("joint")
@click.option("--drive", type=click.Choice(["bar", "tendon"]), default="bar", show_default=True)
@click.option("--routed", is_flag=True, help="Tendon slides on its path in the base link (capstan).")
@click.option("--normal-load", type=float, default=1.5, show_default=True, help="Transverse load F_n [N].")
@click.option("--stiffness", type=float, default=5.19, show_default=True, help="K_s [N·mm/rad].")
@click.option("--preload", type=float, default=70.0, show_default=True, help="θ_0 [deg].")
@click.option("--mu-j", type=float, default=6.92, show_default=True, help="Generalised pin friction μ_j [mm].")
@click.option("--gamma-pos", type=float, default=1.89, show_default=True, help="γ⁺ [N·mm/rad].")
@click.option("--gamma-neg", type=float, default=3.15, show_default=True, help="γ⁻ [N·mm/rad].")
@click.option("--beta-pos", type=float, default=1.24, show_default=True, help="β⁺ (pulling, ≥ 1).")
@click.option("--beta-neg", type=float, default=0.67, show_default=True, help="β⁻ (releasing, ≤ 1).")
@click.option("--pulley-radius", type=float, default=6.0, show_default=True, help="Tendon moment arm r [mm].")
@click.option("--rotation", type=float, required=True, help="Cycle 0 → rotation → 0 [deg].")
@click.option("--json", "as_json", is_flag=True)
@click.option("--plot", type=click.Path(dir_okay=False), help="Write the loop as a PNG.")
def simulate_joint(drive, routed, normal_load, stiffness, preload, mu_j, gamma_pos, gamma_neg, beta_pos, beta_neg,
                   pulley_radius, rotation, as_json, plot):
    """Hysteresis loop of one joint over a 0 → rotation → 0 cycle (paper Eq. 3-7)."""
    import numpy as np

    from rjcad.physics.joint import JointModel, Setup, cycle, simulate as run

    if not 0 < rotation <= 360:
        raise click.BadParameter("must be in (0, 360] deg", param_hint="--rotation")
    m = JointModel(stiffness=stiffness, preload=math.radians(preload), mu_j=mu_j, gamma_pos=gamma_pos,
                   gamma_neg=gamma_neg, beta_pos=beta_pos, beta_neg=beta_neg, pulley_radius=pulley_radius)
    setup = Setup(drive, normal_load, routed)
    th, d = cycle(math.radians(rotation))
    y = run(m, setup, th, direction=d)
    out = {"theta_deg": [math.degrees(v) for v in th], "direction": [int(v) for v in d], setup.quantity: y.tolist()}
    if plot:
        def draw(ax):
            for sgn, lab in ((1, "flexing"), (-1, "extending")):
                k = d == sgn
                ax.plot(np.degrees(th[k]), y[k], label=lab)
            ax.set_xlabel("joint angle θ_j [deg]")
            ax.set_ylabel("torque [N·mm]" if drive == "bar" else "tendon force at the actuator [N]")
            ax.legend()
        _plot(plot, draw)
    if as_json:
        click.echo(json.dumps(out))
    else:
        click.echo(f"{setup.quantity}: {len(th)} samples, from {np.min(y):.3f} to {np.max(y):.3f}; "
                   f"mean loop width {np.mean(y[d > 0]) - np.mean(y[d < 0]):.3f}")


@simulate.command("finger")
@click.argument("source", required=False, type=click.Path(dir_okay=False))
@click.option("--stroke", type=float, default=25.0, show_default=True, help="Tendon displacement [mm].")
@click.option("--steps", type=click.IntRange(10, 100000), default=500, show_default=True)
@click.option("--mu-t", type=float, default=0.0, show_default=True, help="Tendon friction coefficient on its path.")
@click.option("--json", "as_json", is_flag=True)
@click.option("--plot", type=click.Path(dir_okay=False), help="Write θ_i(t_d) as a PNG.")
def simulate_finger(source, stroke, steps, mu_t, as_json, plot):
    """Finger closure, pull then release: a finger manifest (.json) or template (.toml; default: the paper's)."""
    import numpy as np

    from rjcad.physics.finger import load_finger_model, simulate_stroke

    if stroke <= 0:
        raise click.BadParameter("must be > 0 mm", param_hint="--stroke")
    model = load_finger_model(source, mu_t=mu_t)
    c = simulate_stroke(model, stroke, steps=steps)
    if plot:
        def draw(ax):
            pull = np.array([p == "pull" for p in c.phase])
            for i in range(model.n):
                ax.plot(c.tendon_mm[pull], np.degrees(c.theta[pull, i]), color=f"C{i}", label=f"θ{i + 1} pull")
                ax.plot(c.tendon_mm[~pull], np.degrees(c.theta[~pull, i]), "--", color=f"C{i}", label=f"θ{i + 1} release")
            ax.set_xlabel("tendon displacement t_d [mm]")
            ax.set_ylabel("joint angle [deg]")
            ax.legend(fontsize=8)
        _plot(plot, draw)
    if as_json:
        click.echo(json.dumps(c.to_dict()))
    else:
        end = np.degrees(c.theta[steps])
        click.echo(f"at {stroke:g} mm: θ = ({', '.join(f'{v:.1f}' for v in end)}) deg, tension {c.tension[steps]:.2f} N")


@cli.command("finger-design")
@click.option("--target", required=True, help="End angles per joint [deg], e.g. 65,50,50.")
@click.option("--stroke", type=float, required=True, help="Tendon displacement at the end [mm].")
@click.option("--sequence", type=click.Choice(["simultaneous", "proximal-first"]), default="simultaneous",
              show_default=True)
@click.option("--base-stiffness", type=float, default=None,
              help="Softest joint [N·mm/rad]; default 5.2, rescaled if a spring would not be printable.")
@click.option("--material", default="absplus-p430", show_default=True)
@click.option("--printer", default="generic-0.4", show_default=True)
@click.option("--out", "out_path", type=click.Path(dir_okay=False), required=True, help="Finger template to write.")
@click.option("--json", "as_json", is_flag=True)
def finger_design(target, stroke, sequence, base_stiffness, material, printer, out_path, as_json):
    """Choose stiffnesses, preloads and moment arms for a desired free closure; write a finger template."""
    from rjcad.config import write_atomic
    from rjcad.physics.inverse import design_finger

    try:
        angles = [float(v) for v in target.split(",")]
    except ValueError:
        raise click.BadParameter(f"{target!r} is not a list of angles like 65,50,50", param_hint="--target") from None
    d = design_finger(angles, stroke, sequence, base_stiffness, material, printer)
    write_atomic(out_path, d.template(material, printer))
    rep = d.report()
    if as_json:
        click.echo(json.dumps(rep))
        return
    click.echo(f"wrote {out_path}")
    for note in rep["notes"]:
        click.echo(f"  note: {note}")
    for i in range(len(angles)):
        click.echo(f"  joint {i + 1}: K {rep['stiffness_nmm_per_rad'][i]:.3f} N·mm/rad, preload "
                   f"{rep['preload_deg'][i]:.1f} deg, arm {rep['tendon_moment_arm_mm'][i]:.2f} mm, "
                   f"end error {rep['end_error_deg'][i]:+.3f} deg, starts at {rep['onset_tendon_mm'][i]:.2f} mm")


@cli.command("paper-finger")
@click.option("--out", "out_dir", type=click.Path(file_okay=False), default="docs", show_default=True)
@click.option("--manifest", type=click.Path(dir_okay=False),
              help="Built finger manifest (out/finger/finger.json) for the design model's moment arms; "
                   "default: the joint builder's design arm.")
def paper_finger(out_dir, manifest):
    """Regenerate docs/paper-finger.md: the paper's finger, the design model's error and its explanations."""
    from rjcad.physics.paper_finger import write_doc

    exps = write_doc(out_dir, manifest)
    click.echo(f"wrote {out_dir}/paper-finger.md and paper-finger.png ({len(exps)} explanations fitted)")


@cli.command()
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--plot", type=click.Path(dir_okay=False), help="Write the models against the data as a PNG.")
@click.option("--doc", "doc_dir", type=click.Path(file_okay=False),
              help="Regenerate DOC_DIR/life.md and life.png (every number computed).")
@click.option("--sims", type=click.IntRange(10, 100000), default=200, show_default=True,
              help="Bootstrap tables per model for --doc.")
def life(as_json, plot, doc_dir, sims):
    """Spring life from the paper's Table I: the stress-only law, what it gets wrong, and the extension."""
    from rjcad import life as lf

    c = lf.critique()
    d = c.to_dict()
    if plot:
        lf.write_plot(c, plot)
    if doc_dir:
        lf.write_doc(c, doc_dir, n_sim=sims)
    if as_json:
        click.echo(json.dumps(d, indent=2))
        return
    b, e = d["baseline"], d["extended"]

    def law(v):
        return ", ".join(f"{k} = {x:.3g}" for k, x in v["params"].items()) + \
            ("" if v["stress_term"] else " (no stress term)")

    click.echo(f"stress-only law:  {law(b)}; LOO RMSE {b['loo_rmse_log10']:.3f} log10, AICc {b['aicc']:.2f}")
    for name, v in d["candidates"].items():
        click.echo(f"+ {name:<13} {law(v)}; LOO RMSE {v['loo_rmse_log10']:.3f}, ΔAICc {v['delta_aicc']:+.2f}")
    chosen = ", ".join(e["effects"]) or "none (the stress-only law stays)"
    click.echo(f"chosen: {chosen}; gain {d['gain']:.2f}x (LOO {b['loo_rmse_log10']:.3f} -> "
               f"{e['loo_rmse_log10']:.3f}); Akaike weights "
               + ", ".join(f"{k} {v:.2f}" for k, v in d["akaike_weights"].items()))
    _print_table([(f"row {r['row']}", f"σa {r['stress_amp_mpa']:5.2f} MPa  observed {r['observed_cycles']:7.2g}"
                   f"{'+' if r['censored'] else ' '}  stress-only {r['baseline_cycles']:7.2g} "
                   f"(res {r['baseline_residual_log10']:+.2f}, LOO {r['baseline_loo_error_log10']:+.2f})  extended "
                   f"{r['extended_cycles']:7.2g} (res {r['extended_residual_log10']:+.2f}, "
                   f"LOO {r['extended_loo_error_log10']:+.2f})", "") for r in d["rows"]])


def _key_values(text: str, option: str) -> dict[str, float]:
    """'a=1,b=2' → {'a': 1.0, 'b': 2.0}; click.BadParameter on bad syntax."""
    out = {}
    for item in (s.strip() for s in text.split(",")):
        if not item:
            continue
        key, eq, value = item.partition("=")
        try:
            if not eq or not key.strip():
                raise ValueError
            out[key.strip()] = float(value)
        except ValueError:
            raise click.BadParameter(f"{item!r} is not NAME=NUMBER", param_hint=option) from None
    return out


@cli.command()
@click.option("--effects", default="", help="Comma-separated catalogue effects in the true model (none: the null case).")
@click.option("--param", "params", multiple=True, help="NAME=VALUE (JSON name, e.g. mu_j_mm=5); repeatable.")
@click.option("--noise", default="", help="Noise σ per column, e.g. torque_nmm=0.1,tendon_force_n=0.02,theta_deg=0.1.")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed (same seed, same files).")
@click.option("--samples", type=int, default=3000, show_default=True, help="Samples per experiment (>= 100).")
@click.option("--rotation", type=float, default=90.0, show_default=True, help="Joint rotation from rest [deg].")
@click.option("--paper", is_flag=True, help="The paper's campaign: its design and measured parameters, F_n 1.5 N in A-C.")
@click.option("--out", "out_dir", type=click.Path(file_okay=False), required=True, help="Campaign directory.")
def bench(effects, params, noise, seed, samples, rotation, paper, out_dir):
    """Write a SYNTHETIC campaign (experiments A-E of the paper) simulated from the joint model, with noise."""
    from pathlib import Path

    from rjcad.identify.bench import PAPER_PRESET, write_campaign

    overrides = {}
    for p in params:
        overrides.update(_key_values(p, "--param"))
    chosen = [e.strip() for e in effects.split(",") if e.strip()]
    design = None
    if paper:
        if chosen:
            raise click.BadParameter("give either --paper or --effects", param_hint="--effects")
        chosen, design = list(PAPER_PRESET["effects"]), PAPER_PRESET["design"]
        overrides = {**PAPER_PRESET["params"], **overrides}
    truth = write_campaign(out_dir, chosen, overrides, design=design, seed=seed, noise=_key_values(noise, "--noise"),
                           samples=samples, rotation_deg=rotation)
    out = Path(out_dir)
    click.echo(f"wrote {out / 'campaign.toml'}")
    for e in truth["experiments"]:
        click.echo(f"wrote {out / e['file']} ({samples} samples, {e['quantity']})")
    click.echo(f"wrote {out / 'truth.json'}")
    click.echo(f"wrote {out / 'README.md'}")


@cli.command()
@click.argument("campaign", type=click.Path(dir_okay=False))
@click.option("--json", "json_out", type=click.Path(dir_okay=False), help="Write the result as JSON ('-': stdout).")
@click.option("--report", "report_dir", type=click.Path(file_okay=False), help="Write report.md and PNG plots here.")
def identify(campaign, json_out, report_dir):
    """What the design simulation gets wrong in measured data, which effects cause it, and the gain."""
    from rjcad.config import write_json
    from rjcad.identify.data import load_campaign
    from rjcad.identify.result import to_json
    from rjcad.identify.select import identify as run

    camp = load_campaign(campaign)
    ident = run(camp)
    js = to_json(ident)
    if json_out == "-":
        click.echo(json.dumps(js, indent=2))
    else:
        _identify_summary(js)
    if json_out and json_out != "-":
        write_json(json_out, js)
        click.echo(f"wrote {json_out}")
    if report_dir:
        from rjcad.identify.report import write_report

        for path in write_report(ident, js, report_dir):
            click.echo(f"wrote {path}")


def _identify_summary(js: dict) -> None:
    for note in js["notes"]:
        click.echo(f"note: {note}")
    found = ", ".join(js["effects"]) or "nothing beyond the design simulation"
    click.echo(f"found: {found}  (gain {js['gain']:.3g}x in RMSE, geometric mean over experiments)")
    for s in js["steps"]:
        ho = "n/a" if s["heldout_rmse"] is None else f"{s['heldout_rmse']:.3g}"
        click.echo(f"  {s['action']} {s['effect']}: dBIC {s['delta_bic']:+.4g}, held-out RMSE {ho} x noise "
                   f"- {s['cause']}")
    for name, value in js["params"].items():
        ci = js["param_ci95"].get(name)
        click.echo(f"  {name} = {value:.4g}" + (f"  [{ci[0]:.4g}, {ci[1]:.4g}]" if ci else "  (design)"))
    for name, why in js["not_identifiable_why"].items():
        click.echo(f"  not identifiable: {name} ({why})")
    for e in js["experiments"]:
        click.echo(f"  {e['file']}: RMSE {e['rmse_design']:.4g} -> {e['rmse_final']:.4g} {e['quantity']} "
                   f"(noise {e['noise']:.3g}, {e['samples_masked_at_reversals']} samples at reversals masked)")


# ---- new commands go above this line (one block per command) ----


def main(argv: list[str] | None = None) -> None:
    """Console entry point: run the CLI, turn user errors into one line and exit 2."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args
    args = [a for a in args if a != "--debug"]  # accepted anywhere on the line
    try:
        rv = cli.main(args=args, prog_name="rjcad", standalone_mode=False)
    except RjcadError as e:
        if debug:
            traceback.print_exc()
        click.echo(f"rjcad: error: {e}", err=True)
        sys.exit(2)
    except click.exceptions.Abort:
        click.echo("rjcad: aborted", err=True)
        sys.exit(130)
    except getattr(click.exceptions, "NoArgsIsHelpError", ()) as e:
        click.echo(e.format_message())
        sys.exit(0)
    except click.ClickException as e:
        if debug:
            traceback.print_exc()
        ctx = getattr(e, "ctx", None)
        where = f" (see '{ctx.command_path} --help')" if ctx is not None and ctx.info_name != "rjcad" else ""
        click.echo(f"rjcad: error: {e.format_message()}{where}", err=True)
        sys.exit(2)
    sys.exit(rv if isinstance(rv, int) else 0)


if __name__ == "__main__":  # pragma: no cover
    main()
