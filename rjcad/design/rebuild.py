"""A joint's or a finger's design rebuilt from the manifest rjcad wrote for it, so that what its geometry implies
(its bearing's friction, rjcad.physics.bearing_band and bearing_table) can be computed without the CAD kernel.

A manifest records the request (stiffness, range, preload, printer, material, clearance, lengths, layout, arms,
the tendon's arm); the design rebuilt from it must have the springs the manifest records, else the manifest came
from another rjcad (or was edited) and its geometry cannot be trusted.
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
#: A finger manifest's top-level keys that are template keys as they stand.
FINGER_REQUEST = ("tendon_diameter_mm", "safety_factor", "end")
#: The spring's dimensions the rebuilt joint must reproduce (relative tolerance).
SAME_SPRING = ("width_mm", "thickness_mm", "inner_radius_mm", "pitch_mm", "turns")
TOLERANCE = 1e-6


def _profiles(man: Manifest) -> dict[str, Any]:
    """The printer and material a manifest names (its embedded profiles first)."""
    from rjcad.materials import from_manifest

    out = {}
    for kind, name in (("printers", "printer"), ("materials", "material")):
        found = from_manifest(kind, getattr(man, name), man.extra)
        if found is not None:
            out[name] = found
    return out


def _layout(entry: Any) -> Any:
    layout = entry.extra.get("layout")
    return layout.get("layout") if isinstance(layout, dict) else layout


def _check_spring(p: JointParams, spring: dict[str, Any], label: str) -> None:
    built = p.spring
    for key in SAME_SPRING:
        want = spring.get(key)
        got = getattr(built, key.removesuffix("_mm"))
        if not isinstance(want, (int, float)) or not math.isclose(got, want, rel_tol=TOLERANCE):
            raise RjcadError(
                f"{label}: the joint rebuilt from its manifest has a spring {key} of {got:.6g}, the manifest "
                f"records {want!r}: was it written by another rjcad, or edited?"
            )


def joint_params(man: Manifest, label: str) -> JointParams:
    """The JointParams of the one joint of ``man`` (a joint manifest); one RjcadError line under ``label``."""
    if man.kind != "joint" or len(man.joints) != 1:
        raise RjcadError(
            f"{label}: needs a joint's manifest (rjcad joint), not a {man.kind} of {len(man.joints)} joints"
        )
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
    kw["layout"] = _layout(entry)
    kw["clearance"] = man.clearance_mm
    try:
        kw["arms"] = int(spring.get("arms", 1))
        p = JointParams(**kw, **_profiles(man))
    except (ParameterError, TypeError, ValueError) as e:
        raise RjcadError(f"{label}: the joint cannot be rebuilt from its manifest: {e}") from None
    _check_spring(p, spring, label)
    return p


def designs(man: Manifest, label: str) -> tuple[JointParams, ...]:
    """Each joint's JointParams of a joint's or a finger's manifest, proximal first (``joint_params``,
    ``finger_joints``)."""
    return (joint_params(man, label),) if man.kind == "joint" else finger_joints(man, label)


def _finger_joint(j: Any) -> dict[str, Any]:
    """A finger manifest's joint entry as its template table (the measured tendon arm as the requested one, to
    the micrometre; a key the entry lacks is left out, so the template's check names it)."""
    arm = j.tendon_moment_arm_mm
    table = {
        "stiffness_nmm_per_rad": j.requested_stiffness_nmm_per_rad,
        "rotation_deg": j.rotation_deg,
        "preload_deg": j.preload_deg,
        "link_length_mm": j.link_length_mm,
        "tendon_moment_arm_mm": None if arm is None else round(float(arm), 6),
        "arms": int((j.spring or {}).get("arms", 1)),
    }
    return {k: v for k, v in table.items() if v is not None}


def finger_joints(man: Manifest, label: str) -> tuple[JointParams, ...]:
    """Each joint's JointParams of ``man`` (a finger manifest), proximal first, as ``rjcad finger`` designed them
    (the finger's shared eye plane and widths included); one RjcadError line under ``label``."""
    from rjcad.design.finger_params import FingerParams

    if man.kind != "finger" or not man.joints:
        raise RjcadError(f"{label}: needs a finger's manifest (rjcad finger), not a {man.kind}")
    data: dict[str, Any] = {k: man.extra[k] for k in FINGER_REQUEST if man.extra.get(k) is not None}
    if man.clearance_mm is not None:
        data["clearance_mm"] = man.clearance_mm
    layouts = {_layout(j) for j in man.joints}
    try:
        if len(layouts) != 1:
            raise ValueError(f"its joints have different layouts {sorted(map(str, layouts))}")
        data["layout"] = layouts.pop()
        data["joint"] = [_finger_joint(j) for j in man.joints]
        built, _ = FingerParams.joints_from_dict(data, _profiles(man))
    except (ParameterError, RjcadError, TypeError, ValueError) as e:
        raise RjcadError(f"{label}: the finger cannot be rebuilt from its manifest: {e}") from None
    for i, (p, j) in enumerate(zip(built, man.joints), start=1):
        _check_spring(p, j.spring or {}, f"{label}: joint {i}")
    return tuple(built)
