"""``rjcad simulate finger --object``'s printout and plot: per object the touch order, the final angles, tension
and contacts, the verdict; the finger and the objects with an arrow per contact force."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import click
import numpy as np

from rjcad.physics.finger_model import FingerModel
from rjcad.physics.grasp_result import Grasp, arrow_scale
from rjcad.physics.grasp_run import describe, object_touch_order, outline_points

#: Earlier readings drawn faintly behind the final one.
GHOSTS = 3


def grasp_lines(g: Grasp) -> list[str]:
    """The closure's summary lines (see the module)."""
    v = g.verdict()
    lines = []
    for k, obj in enumerate(g.objects, start=1):
        order = object_touch_order(g, k)
        lines.append(f"object {k}: {describe(obj)}; touched by {', '.join(order) if order else 'nothing'}")
    theta = np.degrees(g.theta[-1]) if g.theta else np.zeros(g.n)
    lines.append(
        f"final: θ = ({', '.join(f'{t:.1f}' for t in theta)}) deg, tension {g.tension_n[-1]:.2f} N, "
        f"tendon {g.tendon_mm[-1]:.2f} mm ({len(g.theta)} readings)"
    )
    for c in g.contacts[-1] if g.contacts else []:
        lines.append(
            f"  {c.body} on object {c.object} at ({c.point_mm[0]:.1f}, {c.point_mm[1]:.1f}) mm: "
            f"normal {c.normal_force_n:.3f} N, tangential {c.tangential_force_n:+.3f} N"
        )
    lines.append(
        f"grasp: phalanges in contact {v.phalanges_in_contact or 'none'}, "
        f"enveloping {'yes' if v.enveloping else 'no'}, "
        + (f"ejected at reading {g.ejected_at}" if g.ejected_at is not None else "ejected no")
        + f", ε = {v.epsilon:.4f}"
    )
    lines.append(
        "  ε (Ferrari–Canny): the largest disturbance wrench, any direction, that unit total contact force resists"
    )
    return lines


def echo_grasp(runs: dict[str, Grasp], differences: dict | None = None) -> None:
    """Print each engine's summary (its name first when there are two) and the comparison's main figures."""
    for name, g in runs.items():
        for line in grasp_lines(g):
            click.echo(f"{name}: {line}" if len(runs) > 1 else line)
    if differences is not None:
        d = differences
        click.echo(
            f"differences (mujoco − rjcad): θ ({', '.join(f'{v:+.2f}' for v in d['theta_deg'])}) deg, "
            f"contact sets {'the same' if d['contact_sets']['same'] else 'differ'}"
        )
        for f in d["normal_forces"]:
            click.echo(
                f"  {f['body']} on object {f['object']}: rjcad {f['rjcad_normal_force_n']:.3f} N, "
                f"mujoco {f['mujoco_normal_force_n']:.3f} N"
            )


def draw_grasp(ax, runs: dict[str, Grasp], model: FingerModel, outlines: Sequence[np.ndarray]) -> None:
    """The finger (outlines and axis lines) and the objects at the final reading (faintly: a few earlier ones),
    an arrow per contact force on the object from its point, length ∝ force (the scale in the legend)."""
    from matplotlib.patches import Circle, Polygon

    first = next(iter(runs.values()))
    scale = arrow_scale((c for g in runs.values() for c in g.contacts[-1]), float(sum(model.link_length)))
    for e, (name, g) in enumerate(runs.items()):
        style = "-" if e == 0 else "--"
        picks = sorted({int(i) for i in np.linspace(0, len(g.theta) - 1, GHOSTS + 1)})
        for r in picks:
            final = r == len(g.theta) - 1
            alpha = 1.0 if final else 0.15
            pts = outline_points(model, g.theta[r], outlines)
            axes = outline_points(model, g.theta[r], [np.array([[0.0, 0.0], [L, 0.0]]) for L in model.link_length])
            for i, (p, a) in enumerate(zip(pts, axes)):
                lab = f"{name}: link outlines" if final and i == 0 else None
                ax.plot(p[:, 0], p[:, 1], color=f"C{e}", ls=style, lw=2, alpha=alpha, label=lab)
                ax.plot(a[:, 0], a[:, 1], color="0.4", ls=style, lw=0.8, alpha=alpha, marker="o", ms=3)
            for obj, pose in zip(g.objects, g.poses[r]):
                x, y, ang = pose
                shape = (
                    Circle((x, y), obj.radius)
                    if obj.kind == "cylinder"
                    else Polygon(obj.corners(x, y, ang), closed=True)
                )
                shape.set(fill=final and e == 0, facecolor="0.85", edgecolor=f"C{e}", ls=style, alpha=alpha)
                ax.add_patch(shape)
        for j, c in enumerate(g.contacts[-1]):
            f = c.force
            lab = f"{name}: contact force (1 N = {scale:.3g} mm)" if j == 0 else None
            ax.annotate("", xy=np.add(c.point_mm, f * scale), xytext=c.point_mm,
                        arrowprops=dict(arrowstyle="->", color="C3" if e == 0 else "C4", lw=1.5))  # fmt: skip
            ax.plot([c.point_mm[0], c.point_mm[0] + f[0] * scale], [c.point_mm[1], c.point_mm[1] + f[1] * scale],
                    alpha=0.0)  # fmt: skip
            if lab:
                ax.plot([], [], color="C3" if e == 0 else "C4", label=lab)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x [mm] (the straight finger)")
    ax.set_ylabel("y [mm] (towards the palm)")
    ax.set_title(f"closure on {len(first.objects)} object(s): final reading, {GHOSTS} earlier ones faint")
    ax.legend(fontsize=7, loc="best")


def plot_grasp(path: str, runs: dict[str, Grasp], model: FingerModel, outlines: Sequence[np.ndarray]) -> None:
    """Write ``draw_grasp``'s figure as a PNG."""
    from rjcad.plotting import axes_png

    axes_png(path, lambda ax: draw_grasp(ax, runs, model, outlines))


def simulate_grasp(
    source: str | None,
    objects: list,
    *,
    engine: str,
    compare: bool,
    max_tension_n: float,
    stroke: float | None,
    steps: int,
    mu_t: float,
    gravity: tuple[float, float, float] | None,
    as_json: bool,
    plot: str | None,
    bearing_mu: float | None = None,
) -> None:
    """``rjcad simulate finger --object``: the closure on ``objects`` by one engine or both (``compare``); JSON
    (``Grasp.to_dict``, or ``{"rjcad", "mujoco", "differences"}``), or the summary lines; ``plot``: a PNG;
    ``bearing_mu``: the joints' friction from their bearings (rjcad's engine; its bands under
    ``bearing_friction``)."""
    import json
    from pathlib import Path

    from rjcad.cli.progress import progress_line
    from rjcad.errors import ParameterError
    from rjcad.physics.grasp_run import compare_grasps, grasp_model, grasp_outlines, run_grasp
    from rjcad.progress import report

    if source is not None and Path(source).suffix.lower() == ".xml":
        raise ParameterError("SOURCE", source, "a closure on objects needs a finger template or manifest, not an MJCF")
    engines = ("rjcad", "mujoco") if compare else (engine,)
    if "mujoco" in engines and mu_t > 0:
        raise ParameterError(
            "--mu-t", mu_t, "MuJoCo has no capstan (one tension along a tendon): use 0 with --engine mujoco"
        )
    from rjcad.cli.bearing_out import echo_bands, with_bearing

    model, bands = with_bearing(grasp_model(source, mu_t, gravity), source, bearing_mu)
    outlines = grasp_outlines(source, model)
    runs: dict[str, Grasp] = {}
    with progress_line("simulate finger") as progress:
        for e in engines:
            report(progress, f"closing on {len(objects)} object(s), {'MuJoCo' if e == 'mujoco' else 'rjcad'}")
            runs[e] = run_grasp(
                e, model, objects, max_tension_n=max_tension_n, stroke=stroke, outlines=outlines, steps=steps,
                source=source,
            )  # fmt: skip
        if plot:
            report(progress, "plotting")
            plot_grasp(plot, runs, model, outlines)
    diff = compare_grasps(runs["rjcad"], runs["mujoco"]) if compare else None
    if as_json:
        out: dict[str, Any] = (
            {e: g.to_dict() for e, g in runs.items()} | {"differences": diff} if compare else runs[engine].to_dict()
        )
        if bands:
            out["bearing_friction"] = [b.to_dict() for b in bands]
        click.echo(json.dumps(out))
    else:
        echo_bands(bands)
        echo_grasp(runs, diff)
