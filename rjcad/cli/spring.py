"""``rjcad spring``: design a joint's spiral springs (twin, or one), print them as a table or JSON, plot them."""

from __future__ import annotations

import json

import click

from rjcad.cli.options import OutFile, design_options, echo_profiles, merge_config, print_table
from rjcad.errors import RjcadError
from rjcad.fields import SPRING_FIELDS, spring_kwargs
from rjcad.spring import SpringDesign, SpringRequirement
from rjcad.spring.design import NOMINAL_KEY_REACH
from rjcad.spring.optimise import design_spring

#: ``rjcad spring``'s options: the requirement, then the optimiser's bounds and the life constraint.
FIELDS = SPRING_FIELDS


def spring_requirement(options: dict, config: str | None) -> SpringRequirement:
    """Merge defaults < config file < explicit options into a SpringRequirement (rotation defaults to 90°)."""
    kwargs = spring_kwargs(merge_config(options, config, FIELDS))
    if "joint_stiffness" not in kwargs:
        raise click.UsageError("missing --stiffness (or stiffness_nmm_per_rad in --config)")
    return SpringRequirement(**kwargs)


@click.command()
@design_options(FIELDS, "TOML file with the same keys (see templates/).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option(
    "--plot",
    "plot",
    type=OutFile(),
    help="Write a PNG: torque against wind-up (rod model vs formula) and the wound shape with its tightest gap.",
)
def spring(config, as_json, plot, **options):
    """Design the spiral springs of one joint (twin, or one with --springs 1; smallest outer radius), verified by
    the rod model."""
    design = design_spring(spring_requirement(options, config))
    if plot:
        from rjcad.io.outputs import OutputError
        from rjcad.spring.plot import write_plot

        try:
            write_plot(design, plot)
        except OutputError as e:
            raise RjcadError(f"--plot {e}") from None
    if as_json:
        click.echo(json.dumps(design.to_dict(), indent=2))
    else:
        echo_profiles(design.requirement.printer_spec, design.requirement.material_spec)
        print_design(design)
        if plot:
            click.echo(f"  plot written to {plot}")


def _contact(d: dict) -> tuple[str, str]:
    if d["first_contact_deg"] is None:
        return "none", f"up to {d['rotation_deg'] + d['preload_deg']:g}° of wind-up"
    return f"{d['first_contact_deg']:.1f}", "° of wind-up"


def _arm_rows(d: dict) -> list[tuple[str, str, str]]:
    """Two arms: the rows of the balance and the key gap (none for one arm)."""
    if d.get("arms", 1) == 1:
        return []
    return [
        ("arms", f"{d['arms']}", f"interleaved, 180° apart; each arm's pitch {d['arm_pitch_mm']:.3f} mm"),
        ("hub force, net", f"{d['hub_force_n']:.2e}", f"N (both arms; one arm's reaction {d['arm_force_n']:.3f} N)"),
        (
            "key gap",
            f"{d['min_key_gap_mm']:.3f}",
            f"mm (an arm to the other's key, {NOMINAL_KEY_REACH:g} mm long; rod model, over the wind-up)",
        ),
    ]


def print_design(design: SpringDesign) -> None:
    """The design as a heading line and a table (degrees, mm, MPa, N·mm); physics from the rod model."""
    d = design.to_dict()
    req = design.requirement
    windup = d["rotation_deg"] + d["preload_deg"]
    share = "one spring" if req.springs == 1 else f"{req.springs} springs of {req.spring_stiffness:g}"
    both = "one spring" if req.springs == 1 else "both springs"
    click.echo(
        f"Spiral spring for a {req.joint_stiffness:g} N·mm/rad joint "
        f"({share}), {d['rotation_deg']:g}° rotation, "
        f"{d['preload_deg']:g}° preload, {req.material_spec.key}, {req.printer_spec.key}, {req.end} outer end, "
        f"loaded unwinding; checked by the rod model"
    )
    print_table(
        [
            ("width b", f"{d['width_mm']:.3f}", "mm"),
            ("thickness t", f"{d['thickness_mm']:.3f}", "mm"),
            ("length L", f"{d['length_mm']:.2f}", "mm"),
            ("inner radius r_in", f"{d['inner_radius_mm']:.3f}", "mm (centreline)"),
            ("pitch p", f"{d['pitch_mm']:.4f}", "mm"),
            ("turns n", f"{d['turns']:.3f}", ""),
            ("outer radius", f"{d['outer_radius_mm']:.3f}", "mm (envelope, hook excluded)"),
            (
                "joint stiffness",
                f"{d['joint_stiffness_nmm_per_rad']:.4f}",
                f"N·mm/rad ({both}, rod model, slope over the rotation)",
            ),
            (
                "formula stiffness",
                f"{d['formula_stiffness_nmm_per_rad']:.4f}",
                f"N·mm/rad ({both}, c·E·b·t³/12L, {req.end})",
            ),
            ("peak stress", f"{d['peak_stress_mpa']:.2f}", f"MPa (rod model, over 0-{windup:g}° of wind-up)"),
            ("allowed stress", f"{d['allowed_stress_mpa']:.2f}", f"MPa (yield / {req.safety_factor:g})"),
            (
                "coil gap, wound",
                f"{d['min_coil_gap_mm']:.3f}",
                f"mm (rod model, smallest over the wind-up, at {d['min_coil_gap_windup_deg']:.0f}°)",
            ),
            ("coil gap, printed", f"{d['print_coil_gap_mm']:.3f}", "mm"),
            ("first contact", *_contact(d)),
            ("pin force", f"{d['pin_force_n']:.3f}", "N (largest reaction on the outer end's post, one spring)"),
            *_arm_rows(d),
            ("preload torque", f"{d['preload_torque_nmm']:.2f}", "N·mm (joint)"),
            ("max torque", f"{d['max_torque_nmm']:.2f}", "N·mm (joint)"),
            (
                "predicted life",
                f"{d['predicted_cycles']:.3g}",
                f"cycles (90 %: {d['predicted_cycles_interval'][0]:.2g}-{d['predicted_cycles_interval'][1]:.2g}; "
                f"backlash {d['backlash_mm']:g} mm; see rjcad life)",
            ),
        ]
    )
