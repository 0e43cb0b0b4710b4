"""``rjcad joint`` and ``rjcad finger``: build the solids, write meshes, preview and manifest, print a summary."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from rjcad.cli.options import OutDir, complete_profiles, design_options, echo_profiles, print_table
from rjcad.fields import JOINT_FIELDS
from rjcad.progress import report

if TYPE_CHECKING:
    from rjcad.io.manifest import Manifest

#: ``rjcad joint``'s options (``rjcad.api.build_joint``'s keywords): the spring requirement with the module's
#: geometry after ``--printer``.
FIELDS = JOINT_FIELDS


def _outputs(out_dir: str, stem: str, no_png: bool, html: bool = False) -> str:
    return f"{out_dir}/{stem}.{{stl,3mf,step,glb{'' if no_png else ',png'},json{',html' if html else ''}}}"


def _springs(n: int, arms: int = 1) -> str:
    what = "one spring" if n == 1 else f"{n} springs"
    return f"N·mm/rad ({what}{', two arms' if arms == 2 else ''})"


def _bodies(m: Manifest | dict[str, Any]) -> tuple[str, str, str]:
    return ("bodies", ", ".join(f"{b['name']} {b['mass_g']:.1f} g" for b in m["bodies"]), "")


@click.command()
@design_options(FIELDS, "TOML design (see templates/joint.toml).")
@click.option("--out", "out_dir", type=OutDir(), default="out/joint", show_default=True, help="Output directory.")
@click.option("--no-png", is_flag=True, help="Skip the preview image.")
def joint(config, out_dir, no_png, **options):
    """Build the one-piece joint module: STL, 3MF, STEP, GLB, PNG preview and JSON manifest."""
    import contextlib

    import rjcad.cli
    from rjcad.cad import process
    from rjcad.cli.progress import progress_line

    # the rjcad program builds in a forked process that imports OCP while this one designs the spring
    cad = process.CadProcess() if rjcad.cli.PROGRAM and process.usable() else None
    with cad or contextlib.nullcontext(), progress_line("joint") as progress:  # the line's thread after the fork
        from rjcad.api import joint_params

        report(progress, "designing the spring")
        params = joint_params(config=config, **{f.keyword: options[f.name] for f in FIELDS})
        from rjcad.cad.build import write_joint

        b = write_joint(params, out_dir, png=not no_png, cad=cad, progress=progress)
    click.echo(f"joint written to {_outputs(out_dir, 'joint', no_png)}")
    echo_profiles(params.printer_spec, params.material_spec)
    print_joint(b.manifest)


def print_joint(m: Manifest | dict[str, Any]) -> None:
    """Summary table of a joint manifest: stiffness, spring, measured arm, wrap and gap, bearing, bodies, triangles;
    the bearing's note (``echo_lock_note``)."""
    print_table(
        [
            (
                "joint stiffness",
                f"{m['joint_stiffness_nmm_per_rad']:.3f}",
                _springs(m["spring"].get("springs", 2), m["spring"].get("arms", 1)),
            ),
            (
                "spring b × t × L",
                f"{m['spring']['width_mm']:.2f} × {m['spring']['thickness_mm']:.2f} × {m['spring']['length_mm']:.1f}",
                "mm",
            ),
            ("spring outer radius", f"{m['spring']['outer_radius_mm']:.2f}", "mm"),
            ("tendon moment arm", f"{m['tendon_moment_arm_mm']:.3f}", "mm (measured)"),
            ("tendon wrap angle", f"{m['tendon_wrap_angle_rad']:.3f}", "rad in the ground channel (measured)"),
            ("min gap between bodies", f"{m['measured_min_gap_mm']:.3f}", "mm (on the mesh)"),
            _locks(m["joints"]),
            _bodies(m),
            ("triangles", f"{m['mesh']['triangles']}", ""),
        ]
    )
    echo_lock_note(m["joints"])


@click.command()
@click.argument("template", required=False, type=click.Path(dir_okay=False))
@click.option("--out", "out_dir", type=OutDir(), default="out/finger", show_default=True, help="Output directory.")
@click.option("--no-png", is_flag=True, help="Skip the preview image.")
@click.option(
    "--printer",
    shell_complete=complete_profiles("printers"),
    help="Printer profile, instead of the template's: a name or a .toml file (see rjcad profiles).",
)
@click.option(
    "--material",
    shell_complete=complete_profiles("materials"),
    help="Material profile, instead of the template's: a name or a .toml file (see rjcad profiles).",
)
@click.option("--html", is_flag=True, help="Also write finger.html, the interactive viewer (see rjcad view).")
@click.option(
    "--mjcf",
    is_flag=True,
    help="Also write the MuJoCo model (SI units) into mjcf/: finger.xml, scene.xml and meshes/ (see rjcad mjcf).",
)
@click.option(
    "--gravity",
    default="horizontal-palm-down",
    show_default=True,
    help="With --mjcf: gravity relative to the finger (see rjcad mjcf --help).",
)
def finger(template, out_dir, no_png, printer, material, html, mjcf, gravity):
    """Build a finger of chained joint modules (default: the paper's joints on a desktop printer,
    templates/finger.toml)."""
    from rjcad.api import finger_params
    from rjcad.cli.progress import progress_line
    from rjcad.view import finger_page, vendored_three

    with progress_line("finger") as progress:
        report(progress, "designing the springs")
        fp = finger_params(template or None, printer=printer, material=material)
        grav = None
        if mjcf:
            from rjcad.mjcf.export import gravity_of

            grav = gravity_of(gravity)
        if html:
            vendored_three()  # a missing three.js is said before the build
        from rjcad.cad.build import MJCF_DIR, write_finger

        more = None
        if html:  # the template's [[object]] tables, if any, closed on in the page
            import functools

            from rjcad.physics.grasp_run import template_objects

            more = functools.partial(finger_page, objects=template_objects(template) if template else [])
        b = write_finger(fp, out_dir, png=not no_png, more=more, mjcf=mjcf, gravity=grav, progress=progress)
    m = b.manifest
    click.echo(
        f"finger written to {_outputs(out_dir, 'finger', no_png, html)} "
        f"({fp.n} joints, {len(m['bodies'])} bodies, {m['mesh']['triangles']} triangles)"
        + (f"; MuJoCo: {out_dir}/{MJCF_DIR}/finger.xml (open scene.xml beside it)" if mjcf else "")
    )
    echo_profiles(fp.joints[0].printer_spec, fp.joints[0].material_spec)
    print_finger(m)
    if mjcf:
        from rjcad.cli.mjcf import echo_sag_of_manifest

        echo_sag_of_manifest(m, gravity)


def print_finger(m: Manifest | dict[str, Any]) -> None:
    """Summary table of a finger manifest: each joint's K, arm and wrap, the tendon length, the bearings, the
    bodies; the bearing's note (``echo_lock_note``)."""
    rows = [
        (
            f"joint {i + 1} ({j['parent']} → {j['child']})",
            f"K {j['joint_stiffness_nmm_per_rad']:.2f}  r {j['tendon_moment_arm_mm']:.2f}  "
            f"wrap {j['tendon_wrap_angle_rad']:.3f}",
            "N·mm/rad, mm, rad",
        )
        for i, j in enumerate(m["joints"])
    ]
    rows.append(("tendon length at rest", f"{m['tendon_length_mm']:.1f}", "mm"))
    rows.append(_locks(m["joints"]))
    rows.append(_bodies(m))
    print_table(rows)
    echo_lock_note(m["joints"])


def echo_lock_note(joints) -> None:
    """A note (stderr) when a joint's bearing locks above a μ that dry plastic on itself can have."""
    from rjcad.physics.bearing_paper import PLAUSIBLE_MU

    locks = [(i, (j.get("bearing") or {}).get("locks_above_mu")) for i, j in enumerate(joints, start=1)]
    inside = [(i, v) for i, v in locks if v is not None and v < PLAUSIBLE_MU[1]]
    if not inside:
        return
    if len(joints) == 1:
        which = f"this joint locks above μ {inside[0][1]:.2f}"
    elif len(inside) == 1:
        which = f"joint {inside[0][0]} locks above μ {inside[0][1]:.2f}"
    else:
        which = f"joints {', '.join(str(i) for i, _ in inside)} lock above μ {', '.join(f'{v:.2f}' for _, v in inside)}"
    click.echo(
        f"rjcad: note: the bearing model says {which}, inside dry plastic's {PLAUSIBLE_MU[0]:g}–{PLAUSIBLE_MU[1]:g}: "
        f"in a material that grips itself the tendon may not turn {'it' if len(inside) == 1 else 'them'} "
        "(docs/bearing.md)",
        err=True,
    )


def _locks(joints) -> tuple[str, str, str]:
    """The row of each joint's ``bearing.locks_above_mu``: the μ above which its tendon cannot turn it."""
    values = [(j.get("bearing") or {}).get("locks_above_mu") for j in joints]
    shown = "  ".join("never" if v is None else f"{v:.2f}" for v in values)
    return ("bearing locks above μ", shown, "(bearing model, docs/bearing.md)")
