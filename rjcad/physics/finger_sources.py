"""A finger model from what describes a built or planned finger: its manifest (measured arms, wraps, masses and
centres of mass), a finger template's physics keys, or a file of either (re-exported by
``rjcad.physics.finger``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from rjcad import DEG
from rjcad.errors import ParameterError
from rjcad.physics.finger_model import FingerModel

if TYPE_CHECKING:
    from rjcad.design.params import JointParams


def model_from_manifest(
    manifest: Any,
    mu_t: float = 0.0,
    friction: Sequence[float] | None = None,
    gamma: Sequence[float] | None = None,
    gravity: tuple[float, float] | None = None,
    gamma_pos: Sequence[float] | None = None,
    gamma_neg: Sequence[float] | None = None,
) -> FingerModel:
    """A finger model from a finger (or joint) manifest (a ``Manifest`` or its JSON object): stiffness,
    preload, range, measured arms and wraps, and each joint's child body's mass."""
    from rjcad.io.manifest import Manifest

    man = Manifest.coerce(manifest)
    joints = man.joints
    if not joints:
        raise ParameterError("joints", [], "must be a non-empty list of joints, proximal first")

    def num(key: str, default: float | None = None) -> tuple[float, ...]:
        out = []
        for i, j in enumerate(joints):
            v = getattr(j, key)
            if v is None:
                if default is None:
                    raise ParameterError(man.key_path(i, key), None, "is required in a finger manifest")
                v = default
            out.append(float(v))
        return tuple(out)

    masses = {b.name: b.mass_g for b in man.bodies or [] if b.mass_g is not None}
    coms = {b.name: b.com_mm for b in man.bodies or [] if b.com_mm is not None}
    link_com: tuple[tuple[float, float], ...] = ()
    measured = [
        (coms[j.child], j.axis_point_mm)
        for j in joints
        if j.child is not None and j.child in coms and j.axis_point_mm is not None
    ]
    if len(measured) == len(joints):  # measured: relative to the axis
        link_com = tuple((c[0] - a[0], c[1] - a[1]) for c, a in measured)
    return FingerModel(
        stiffness=num("joint_stiffness_nmm_per_rad"),
        preload=tuple(x * DEG for x in num("preload_deg")),
        rotation=tuple(x * DEG for x in num("rotation_deg")),
        moment_arm=num("tendon_moment_arm_mm"),
        wrap=num("tendon_wrap_angle_rad", 0.0),
        mu_t=mu_t,
        friction=tuple(friction) if friction is not None else (),
        gamma=tuple(gamma) if gamma is not None else (),
        gamma_pos=tuple(gamma_pos) if gamma_pos is not None else (),
        gamma_neg=tuple(gamma_neg) if gamma_neg is not None else (),
        link_length=num("link_length_mm", 40.0),
        link_mass=tuple(float(masses.get(j.child, 0.0)) if j.child is not None else 0.0 for j in joints),
        gravity=gravity,
        link_com=link_com,
    )


def outlines_from_manifest(manifest: Any) -> list[np.ndarray] | None:
    """Each link's palmar outline (joint i's child body, proximal first) from a finger manifest (a ``Manifest``
    or its JSON object): arrays of rows (x, y) in the link's frame (origin at axis i, x along the link, y
    towards the palm) [mm]; None if any joint lacks ``palmar_outline_mm`` (a manifest written before #40)."""
    from rjcad.io.manifest import Manifest

    joints = Manifest.coerce(manifest).joints
    if not joints or any(j.palmar_outline_mm is None for j in joints):
        return None
    return [np.array(j.palmar_outline_mm, dtype=float) for j in joints]


def base_outline_from_manifest(manifest: Any) -> np.ndarray | None:
    """The base's palmar outline (rows x, y in the finger's frame, mm) from a finger manifest, or None when it
    has none (a joint's manifest, or one written before #40): usable as a palm."""
    from rjcad.io.manifest import Manifest

    outline = Manifest.coerce(manifest).base_palmar_outline_mm
    return None if outline is None else np.array(outline, dtype=float)


def model_from_template(data: dict[str, Any], default_arm: float = 6.0) -> FingerModel:
    """A finger model from a finger template's physics keys; the purely geometric keys are ignored.

    Per joint (``[[joint]]`` over ``[defaults]``): stiffness_nmm_per_rad (required), preload_deg (90),
    rotation_deg (90), tendon_moment_arm_mm (``default_arm`` = 6 mm, the joint builder's default),
    link_length_mm (40). No wrap angle in a template: 0 (frictionless path).
    """
    defaults = data.get("defaults", {})
    joints = data.get("joint", [])
    if not isinstance(defaults, dict):
        raise ParameterError("defaults", defaults, "must be a table")
    if not isinstance(joints, list) or not joints:
        raise ParameterError("joint", joints, "a finger template needs at least one [[joint]] table")
    ks, pre, rot, arm, lengths = [], [], [], [], []
    for i, j in enumerate(joints, start=1):
        if not isinstance(j, dict):
            raise ParameterError(f"joint[{i}]", j, "must be a table")
        merged = {**defaults, **j}
        ks.append(_number(merged, i, "stiffness_nmm_per_rad"))
        pre.append(_number(merged, i, "preload_deg", 90) * DEG)
        rot.append(_number(merged, i, "rotation_deg", 90) * DEG)
        arm.append(_number(merged, i, "tendon_moment_arm_mm", default_arm))
        lengths.append(_number(merged, i, "link_length_mm", 40))
    return FingerModel(tuple(ks), tuple(pre), tuple(rot), tuple(arm), link_length=tuple(lengths))


def check_template_keys(data: dict[str, Any], name: str) -> None:
    """Every key of a finger template known and of its type, as the builder requires (ParameterError)."""
    from rjcad.io.config import check_key
    from rjcad.io.templates import FINGER_JOINT_KEYS, FINGER_KEYS
    from rjcad.physics.objects import objects_from_template

    for key, value in data.items():
        check_key(f"{name}: ", key, value, FINGER_KEYS)
    tables = [("defaults.", data.get("defaults", {}))]
    tables += [(f"joint[{i}].", j) for i, j in enumerate(data.get("joint", []), start=1) if isinstance(j, dict)]
    for where, table in tables:
        for key, value in table.items():
            check_key(f"{name}: {where}", key, value, FINGER_JOINT_KEYS)
    objects_from_template(data, name)


def load_finger_model(source: str | None, mu_t: float = 0.0) -> FingerModel:
    """A finger model from a manifest (.json), a template (.toml), or the paper's finger (None)."""
    from pathlib import Path

    from rjcad.io.manifest import Manifest
    from rjcad.io.untrusted import read_toml

    if source is None:
        from rjcad.io.templates import PAPER_FINGER

        return model_from_template(PAPER_FINGER)
    if Path(source).suffix.lower() == ".json":
        return model_from_manifest(Manifest.read(source), mu_t=mu_t)
    data = read_toml(source)
    check_template_keys(data, Path(source).name)
    m = model_from_template(data)
    return m if mu_t == 0 else replace(m, mu_t=mu_t)


def _number(table: dict[str, Any], i: int, key: str, default: float | None = None) -> float:
    """``table[key]`` (joint ``i``'s, or the defaults') as a float; one error line if missing or not a number."""
    v = table.get(key, default)
    if v is None:
        raise ParameterError(f"joint[{i}].{key}", None, "is required (here or in [defaults])")
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParameterError(f"joint[{i}].{key}", v, "must be a number")
    return float(v)


def load_finger_designs(source: str | None) -> tuple[JointParams, ...]:
    """Each joint's design (JointParams, proximal first) of a finger manifest or a joint manifest (.json: rebuilt,
    ``rjcad.design.rebuild``), a finger template (.toml) or the paper's finger (None)."""
    from pathlib import Path

    from rjcad.design.finger_params import FingerParams
    from rjcad.design.rebuild import designs
    from rjcad.io.manifest import Manifest
    from rjcad.io.untrusted import read_toml
    from rjcad.materials import profiles_beside

    if source is None:
        from rjcad.io.templates import PAPER_FINGER

        return FingerParams.from_dict(PAPER_FINGER).joints
    path = Path(source)
    if path.suffix.lower() == ".json":
        return designs(Manifest.read(source), path.name)
    data = read_toml(source)
    check_template_keys(data, path.name)
    return FingerParams.from_dict(profiles_beside(data, path.parent), str(source)).joints
