"""``rjcad finger-design --object/--cylinders``: a finger for a set of target cylinders
(rjcad.physics.grasp_design), its template written and each target's grasp reported."""

from __future__ import annotations

import json
from typing import Any

import click

from rjcad.errors import ParameterError


def grasp_design(
    objects: tuple[str, ...],
    cylinders: str | None,
    mu: float,
    max_tension: float,
    material: str,
    printer: str,
    out_path: str,
    as_json: bool,
) -> None:
    """Design for the targets, write the template to ``out_path``, print the report (text or one JSON object)."""
    from rjcad.io.config import write_atomic
    from rjcad.physics.grasp_design import Held, Target, design_for_targets, parse_diameters
    from rjcad.physics.objects import Cylinder, parse_object

    targets: list[Target] = []
    for spec in objects:
        obj = parse_object(spec)
        if not isinstance(obj, Cylinder):
            raise ParameterError("--object", spec, "a design target must be a cylinder")
        targets.append(obj)
    if cylinders is not None:
        targets += [Held(d, mu=mu) for d in parse_diameters(cylinders)]
    d = design_for_targets(targets, max_tension_n=max_tension, material=material, printer=printer)
    write_atomic(out_path, d.template(material, printer))
    rep = d.report()
    if as_json:
        click.echo(json.dumps({"template": out_path, **rep}))
    else:
        print_grasp_design(rep, out_path)


def print_grasp_design(rep: dict[str, Any], out_path: str) -> None:
    """The template written, per joint K, range, arm and link, then per target its grasp."""
    click.echo(f"wrote {out_path}")
    for i, k in enumerate(rep["stiffness_nmm_per_rad"]):
        click.echo(
            f"  joint {i + 1}: K {k:.3f} N·mm/rad, preload {rep['preload_deg'][i]:.0f} deg, range "
            f"{rep['rotation_deg'][i]:.0f} deg, arm {rep['tendon_moment_arm_mm'][i]:.2f} mm, "
            f"link {rep['link_length_mm'][i]:g} mm"
        )
    click.echo(f"  base {rep['base_length_mm']:g} mm; worst-case epsilon {rep['worst_epsilon']:.3f}")
    for t in rep["targets"]:
        o = t["object"]
        click.echo(
            f"  {o['diameter_mm']:g} mm at ({o['x_mm']:.1f}, {o['y_mm']:.1f}): links {t['phalanges_in_contact']} "
            f"touch ({', '.join(t['touch_order'])}), enveloping {t['enveloping']}, ejected {t['ejected']}, "
            f"epsilon {t['quality']['epsilon']:.3f}, max tension {t['max_tension_n']:.2f} N"
        )
    s = rep["search"]
    click.echo(
        f"  searched {s['candidates']} fingers, {s['wrap_every_target']} wrap every target, {s['confirmed']} "
        f"confirmed by {s['solver_runs']} closures in {s['solver_seconds']:.1f} s"
    )
