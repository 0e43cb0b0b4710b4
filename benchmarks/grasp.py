"""Grasp benchmark (issue #40): the default finger, as built, closing on fixed cylinders where the docs hold them.

Prints one JSON object. Per diameter (20, 30, 40, 50, 60 mm; --quick: 40 only), the median seconds of rjcad's
contact solver (``rjcad.physics.grasp.close_on``, 40 readings to 10 N, the links' outlines measured on the built
finger) and of the same closure in MuJoCo (``rjcad.mjcf.grasp.close_on_mujoco``), both in this run, and their
ratio. Target: rjcad's solver ≤ 1 s per object (the slowest diameter). Also the largest differences between the
engines' final states (angles [deg], normal forces [N]), frictionless and at μ 0.5. The finger is built once,
untimed (--quick: not built; the template's model and straight pads).
Run: .venv/bin/python benchmarks/grasp.py [--repeats 3] [--diameters 20,40] [--template] [--quick]
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import emit, median_time, parse_args, target

from rjcad.cad.build import build_finger_model
from rjcad.design.finger_params import FingerParams
from rjcad.io.templates import DEFAULT_FINGER
from rjcad.mjcf.grasp import close_on_mujoco
from rjcad.physics.finger_sources import model_from_manifest, model_from_template, outlines_from_manifest
from rjcad.physics.grasp import close_on, held_position
from rjcad.physics.objects import Cylinder


def differences(a, b) -> tuple[float, float]:
    """Largest |Δθ| [deg] and |ΔN| [N] between two grasps' final states (pairs by body and object)."""
    dth = float(np.degrees(np.abs(a.theta[-1] - b.theta[-1])).max())
    fa = {(c.body, c.object): c.normal_force_n for c in a.contacts[-1]}
    fb = {(c.body, c.object): c.normal_force_n for c in b.contacts[-1]}
    dn = max((abs(fa.get(k, 0.0) - fb.get(k, 0.0)) for k in fa.keys() | fb.keys()), default=0.0)
    return dth, dn


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--diameters", default="20,30,40,50,60")
    ap.add_argument("--template", action="store_true", help="the template's model and pads: no build")
    args = parse_args(ap, {"repeats": 1, "diameters": "40", "template": True})
    if args.template:
        model, outlines = model_from_template(DEFAULT_FINGER), None
    else:
        manifest = build_finger_model(FingerParams.from_dict(DEFAULT_FINGER)).manifest.to_json()
        model, outlines = model_from_manifest(manifest), outlines_from_manifest(manifest)
    rows: dict[str, dict[str, float]] = {}
    for d in (float(v) for v in args.diameters.split(",")):
        for mu in (0.0, 0.5):
            o = Cylinder(*held_position(model, d, outlines), diameter=d, mu=mu)
            t_rj, a = median_time(lambda o=o: close_on(model, [o], outlines=outlines), args.repeats)
            t_mj, b = median_time(lambda o=o: close_on_mujoco(model, [o], outlines=outlines), args.repeats)
            dth, dn = differences(a, b)
            rows[f"{d:g}mm_mu{mu:g}"] = {
                "rjcad_s": t_rj,
                "mujoco_s": t_mj,
                "rjcad_over_mujoco": t_rj / t_mj,
                "max_angle_difference_deg": dth,
                "max_normal_force_difference_n": dn,
                "links_in_contact": len(a.verdict().phalanges_in_contact),
            }
    slowest = max(r["rjcad_s"] for r in rows.values())
    emit({
        "per_object": rows,
        "rjcad_slowest_object_s": slowest,
        "targets": {"rjcad_s_per_object": target(slowest, at_most=1.0)},
    })  # fmt: skip


if __name__ == "__main__":
    main()
