"""The joint a campaign names by its manifest, rebuilt as JointParams, so that identify can compute what its
geometry implies (its bearing friction per unit μ, rjcad.physics.bearing_table).

The manifest of ``rjcad joint`` records the request (stiffness, range, preload, printer, material, clearance,
lengths, layout, arms); the joint rebuilt from it must design the same spring as the manifest records, else the
manifest came from another rjcad (or was edited) and its geometry cannot be trusted here.
"""

from __future__ import annotations

import math
from typing import Any

from rjcad import DEG
from rjcad.design.params import JointParams
from rjcad.errors import ParameterError, RjcadError
from rjcad.io.manifest import Manifest

#: The manifest's top-level request keys → JointParams fields (the joint's entry holds stiffness, range, preload
#: and link length).
REQUEST = {
    "tendon_diameter_mm": "tendon_diameter",
    "tendon_moment_arm_mm_requested": "tendon_moment_arm",
    "pin_radius_mm": "pin_radius",
    "safety_factor": "safety_factor",
    "end": "end",
}
#: The spring's dimensions the rebuilt joint must reproduce (relative tolerance).
SAME_SPRING = ("width_mm", "thickness_mm", "inner_radius_mm", "pitch_mm", "turns")
TOLERANCE = 1e-6


def joint_params(man: Manifest, label: str) -> JointParams:
    """The JointParams of the one joint of ``man`` (a joint manifest); one RjcadError line under ``label``."""
    if man.kind != "joint" or len(man.joints) != 1:
        raise RjcadError(
            f"{label}: needs a joint's manifest (rjcad joint), not a {man.kind} of {len(man.joints)} joints"
        )
    from rjcad.materials import from_manifest

    kw: dict[str, Any] = {}
    for key, name in REQUEST.items():
        if key in man.extra and man.extra[key] is not None:
            kw[name] = man.extra[key]
    entry = man.joints[0]
    for name, value in (
        ("stiffness", entry.requested_stiffness_nmm_per_rad),
        ("rotation", None if entry.rotation_deg is None else entry.rotation_deg * DEG),
        ("preload", None if entry.preload_deg is None else entry.preload_deg * DEG),
        ("link_length", entry.link_length_mm),
    ):
        if value is not None:
            kw[name] = value
    spring = entry.spring or {}
    layout = entry.extra.get("layout")
    kw["layout"] = layout.get("layout") if isinstance(layout, dict) else layout
    kw["clearance"] = man.clearance_mm
    try:
        kw["arms"] = int(spring.get("arms", 1))
        for kind, name in (("printers", "printer"), ("materials", "material")):
            found = from_manifest(kind, getattr(man, name), man.extra)
            if found is not None:
                kw[name] = found
        p = JointParams(**kw)
    except (ParameterError, TypeError, ValueError) as e:
        raise RjcadError(f"{label}: the joint cannot be rebuilt from its manifest: {e}") from None
    built = p.spring
    for key in SAME_SPRING:
        want = spring.get(key)
        got = getattr(built, key.removesuffix("_mm"))
        if not isinstance(want, (int, float)) or not math.isclose(got, want, rel_tol=TOLERANCE):
            raise RjcadError(
                f"{label}: the joint rebuilt from its manifest has a spring {key} of {got:.6g}, the manifest "
                f"records {want!r}: was it written by another rjcad, or edited?"
            )
    return p
