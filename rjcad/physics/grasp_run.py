"""A closure on objects from what the command line, the viewer and the API are given: a finger source (a
manifest, a template, or None for the paper's finger), the template's ``[[object]]`` tables and the objects
given besides, run by rjcad's solver or by MuJoCo; and the two engines' final states compared."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from rjcad.errors import ParameterError
from rjcad.physics.finger_model import FingerModel
from rjcad.physics.grasp import STEPS
from rjcad.physics.grasp_result import Grasp
from rjcad.physics.objects import Object, objects_from_template

#: Readings of a closure on objects (the tension ramp) unless told (rjcad.physics.grasp.STEPS), and the largest
#: tension accepted [N].
GRASP_STEPS = STEPS
MAX_TENSION_N = 1e3
ENGINES = ("rjcad", "mujoco")


def _is_manifest(source: str | Path | None) -> bool:
    return source is not None and Path(source).suffix.lower() == ".json"


def template_objects(source: str | Path | None) -> list[Object]:
    """The ``[[object]]`` tables of a finger template (TOML) as objects; none for a manifest or the default."""
    if source is None or _is_manifest(source) or Path(source).suffix.lower() == ".xml":
        return []
    from rjcad.io.untrusted import read_toml

    return objects_from_template(read_toml(Path(source)), Path(source).name)


def grasp_model(
    source: str | Path | None, mu_t: float = 0.0, gravity: tuple[float, float, float] | None = None
) -> FingerModel:
    """The finger model of ``source`` with ``gravity`` [m/s², finger frame] on its links' weights (None: off)."""
    from rjcad.physics.finger_sources import load_finger_model

    model = load_finger_model(None if source is None else str(source), mu_t=mu_t)
    if gravity is None:
        return model
    from rjcad.mjcf.export import G

    return replace(model, gravity=(gravity[0] / G, gravity[1] / G))


def grasp_outlines(source: str | Path | None, model: FingerModel) -> list[np.ndarray]:
    """Each link's palmar outline in its own frame [mm]: the manifest's (measured on the solids) where it has
    them, else the template's simplified pads (``rjcad.physics.grasp.template_outlines``)."""
    from rjcad.physics.grasp import template_outlines

    if not _is_manifest(source):
        return template_outlines(model)

    return grasp_outlines_of(_manifest_json(source), model)


def _manifest_json(source: str | Path | None) -> dict[str, Any]:
    from rjcad.io.manifest import Manifest

    out: dict[str, Any] = Manifest.read(str(source)).to_json()
    return out


def base_outline_of(manifest: dict[str, Any]) -> np.ndarray | None:
    """The base's palmar outline of a manifest's JSON object (the base's frame, mm), or None: it supports free
    objects in rjcad's solver."""
    from rjcad.physics.finger_sources import base_outline_from_manifest

    return base_outline_from_manifest(manifest)


def grasp_outlines_of(manifest: dict[str, Any], model: FingerModel) -> list[np.ndarray]:
    """The outlines of a manifest's JSON object (``rjcad.physics.finger_sources.outlines_from_manifest``), or
    the template's pads where it has none."""
    from rjcad.physics.finger_sources import outlines_from_manifest
    from rjcad.physics.grasp import link_outlines

    return link_outlines(model, outlines_from_manifest(manifest))


def run_grasp(
    engine: str,
    model: FingerModel,
    objects: Sequence[Object],
    *,
    max_tension_n: float = 10.0,
    stroke: float | None = None,
    outlines: Sequence[np.ndarray] | None = None,
    steps: int = GRASP_STEPS,
    source: str | Path | None = None,
    base_outline: np.ndarray | None = None,
) -> Grasp:
    """The closure of ``model`` on ``objects`` by ``engine`` ("rjcad" or "mujoco"), the tension ramped from 0 to
    ``max_tension_n`` [N] in ``steps`` readings, stopped early at ``stroke`` [mm] of tendon travel if given."""
    from rjcad.validate import in_range

    if engine not in ENGINES:
        raise ParameterError("engine", engine, "must be rjcad or mujoco")
    if not objects:
        raise ParameterError("objects", [], "a grasp needs at least one object")
    in_range("--max-tension", max_tension_n, 0.0, MAX_TENSION_N, lo_open=True, unit="N")
    if stroke is not None:
        in_range("--stroke", stroke, 0.0, 1000.0, lo_open=True, unit="mm")
    kw: dict[str, Any] = dict(max_tension_n=float(max_tension_n), stroke=stroke, outlines=outlines, steps=steps)
    if engine == "rjcad":
        from rjcad.physics.grasp import close_on

        if base_outline is None and _is_manifest(source):
            base_outline = base_outline_of(_manifest_json(source))
        return close_on(model, list(objects), base_outline=base_outline, **kw)
    from rjcad.mjcf.grasp import close_on_mujoco

    out: Grasp = close_on_mujoco(model, list(objects), source=None if source is None else str(source), **kw)
    return out


def _forces(g: Grasp) -> dict[tuple[str, int], float]:
    """The final reading's normal force [N] per (body, object) pair, summed over that pair's contacts."""
    out: dict[tuple[str, int], float] = {}
    for c in g.contacts[-1] if g.contacts else []:
        if c.normal_force_n > 0:
            out[c.body, c.object] = out.get((c.body, c.object), 0.0) + float(c.normal_force_n)
    return out


def compare_grasps(a: Grasp, b: Grasp) -> dict[str, Any]:
    """The final states of two engines' closures (``a`` rjcad's, ``b`` MuJoCo's) side by side: each joint's
    angle difference b − a [deg], the contact sets (body, object) and each pair's normal force by both [N]
    (0 where an engine has no such contact)."""
    ta = np.degrees(a.theta[-1]) if a.theta else np.zeros(a.n)
    tb = np.degrees(b.theta[-1]) if b.theta else np.zeros(b.n)
    d_theta = (tb - ta).tolist()
    fa, fb = _forces(a), _forces(b)
    pairs = sorted(set(fa) | set(fb), key=lambda p: (p[1], p[0]))
    names = {a.engine: fa, b.engine: fb}
    forces = [
        {"body": body, "object": obj}
        | {f"{e}_normal_force_n": f.get((body, obj), 0.0) for e, f in names.items()}
        | {"difference_n": fb.get((body, obj), 0.0) - fa.get((body, obj), 0.0)}
        for body, obj in pairs
    ]
    return {
        "theta_deg": d_theta,
        "max_abs_theta_deg": max((abs(v) for v in d_theta), default=0.0),
        "contact_sets": {e: [f"{b}/object{o}" for b, o in sorted(f)] for e, f in names.items()}
        | {"same": set(fa) == set(fb)},
        "normal_forces": forces,
        "phalanges_in_contact": {
            a.engine: a.verdict().phalanges_in_contact,
            b.engine: b.verdict().phalanges_in_contact,
        },
        "ejected": {a.engine: a.ejected_at is not None, b.engine: b.ejected_at is not None},
    }


def link_frames(model: FingerModel, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each link's axis point (N + 1, 2: the tip last) and direction (N, 2) in the base's frame [mm] at the
    angles ``theta`` [rad]: link i along the sum of θ_1…θ_i."""
    phi = np.cumsum(np.asarray(theta, dtype=float))
    d = np.column_stack([np.cos(phi), np.sin(phi)])
    L = np.asarray(model.link_length, dtype=float)
    axes = np.vstack([[0.0, 0.0], np.cumsum(d * L[:, None], axis=0)])
    return axes, d


def outline_points(model: FingerModel, theta: np.ndarray, outlines: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each link's outline in the base's frame [mm] at the angles ``theta``: a + x d + y n (n = d turned +90°)."""
    axes, d = link_frames(model, theta)
    out = []
    for i, line in enumerate(outlines):
        p = np.asarray(line, dtype=float)
        n = np.array([-d[i, 1], d[i, 0]])
        out.append(axes[i] + p[:, :1] * d[i] + p[:, 1:2] * n)
    return out


def object_touch_order(g: Grasp, k: int) -> list[str]:
    """The bodies in the order they first pressed object ``k`` (1-based)."""
    order: list[str] = []
    for cs in g.contacts:
        for c in cs:
            if c.object == k and c.normal_force_n > 0 and c.body not in order:
                order.append(c.body)
    return order


def describe(obj: Object) -> str:
    """One object in words: kind, size, centre [mm], turn [deg], fixed or free, μ."""
    size = f"{obj.diameter:g} mm" if obj.kind == "cylinder" else f"{obj.w:g} × {obj.h:g} mm"  # type: ignore[union-attr]
    turn = f", turned {math.degrees(obj.angle):g}°" if obj.angle else ""
    held = f"free, {obj.mass_g:g} g" if obj.free else "fixed"
    return f"{obj.kind} {size} at ({obj.x:g}, {obj.y:g}) mm{turn}, {held}, μ {obj.mu:g}"
