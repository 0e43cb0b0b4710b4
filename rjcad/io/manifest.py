"""The build manifest: what a builder made (bodies, joints, inputs), as one typed object and its JSON.

A joint module is a finger with one joint: ``Manifest.joints`` always holds the joints, proximal
first. Builders (``rjcad.cad.build``) make a ``Manifest`` and write ``to_json()``; ``rjcad.check``
and ``rjcad.physics`` read files through ``Manifest.from_json``.

Schema versions:

* 0 (no ``schema_version`` key; rjcad before the manifest type): a joint's keys flat at the top
  (``moving_body``, ``axis_point_mm``, ``rotation_deg`` …), or a finger's ``joints`` list;
* 1: the same keys and order, plus ``schema_version`` first and, for a joint, its one entry in
  ``joints`` last (the flat keys stay, mirrored from that entry). A finger's manifest may also hold (since
  #40; optional, so the version stays 1 and files without them still load) each joint's child body's palmar
  outline ``joints[i].palmar_outline_mm`` (link frame: origin at the joint's axis, x along the link, y towards
  the palm) and the base's ``base_palmar_outline_mm`` (finger frame): ``[[x, y], ...]`` [mm], x increasing.

Keys the readers do not need (``spring`` at the top, ``frame``, ``gaps_mm``, ``mesh``, ``print`` …)
round-trip through ``extra``. ``None`` in a typed field means the key is absent. Lengths in mm,
angles in the unit their key names. A typed number must be finite and within ``LIMITS`` (a clearance in
``CLEARANCE_MM``, a rotation in (0, 360] deg, a volume > 0 …); an axis direction must not be zero. A file is
read through ``Manifest.read`` (rjcad.io.untrusted): every error names the file and the key.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Self, TypeVar

from rjcad.errors import ParameterError, quote
from rjcad.io.untrusted import read_json
from rjcad.validate import default_limit

#: Version written by ``Manifest.to_json``; ``from_json`` also reads 0 (no version key).
SCHEMA_VERSION = 1

#: A JSON object as read or written.
JSONObject = dict[str, Any]

#: A joint manifest's top-level keys mirrored from its one joint entry: top-level key → entry field.
JOINT_FLAT_KEYS = {
    "stiffness_nmm_per_rad": "requested_stiffness_nmm_per_rad",
    "rotation_deg": "rotation_deg",
    "preload_deg": "preload_deg",
    "link_length_mm": "link_length_mm",
    "spring": "spring",
    "joint_stiffness_nmm_per_rad": "joint_stiffness_nmm_per_rad",
    "moving_body": "child",
    "axis_point_mm": "axis_point_mm",
    "axis_dir": "axis_dir",
    "tendon_moment_arm_mm": "tendon_moment_arm_mm",
    "tendon_wrap_angle_rad": "tendon_wrap_angle_rad",
}

#: Top-level key order of each kind (keys not listed follow, in their own order; a joint's ``joints`` last).
KEY_ORDER = {
    "joint": (
        "stiffness_nmm_per_rad",
        "rotation_deg",
        "preload_deg",
        "material",
        "printer",
        "clearance_mm",
        "link_length_mm",
        "tendon_diameter_mm",
        "tendon_moment_arm_mm_requested",
        "pin_radius_mm",
        "safety_factor",
        "end",
        "spring",
        "joint_stiffness_nmm_per_rad",
        "bodies",
        "moving_body",
        "axis_point_mm",
        "axis_dir",
        "tendon_moment_arm_mm",
        "tendon_wrap_angle_rad",
        "gaps_mm",
        "measured_min_gap_mm",
        "spring_strip_volume_mm3",
        "frame",
        "mesh",
        "print",
    ),
    "finger": (
        "template",
        "n_joints",
        "material",
        "printer",
        "clearance_mm",
        "tendon_diameter_mm",
        "safety_factor",
        "end",
        "base_length_mm",
        "base_palmar_outline_mm",
        "joints",
        "bodies",
        "tendon_length_mm",
        "tendon_path_mm",
        "gaps_mm",
        "mesh",
        "frame",
    ),
}


#: Clearances a manifest may state, and ``rjcad check --clearance`` may ask for [mm]: below 0.1 mm no FDM
#: printer keeps two bodies apart (and the motion sweep, whose step is half the clearance, would need
#: thousands of poses); above 5 mm the gap is no print-in-place clearance.
CLEARANCE_MM = (0.1, 5.0)

#: Range of a typed number: field → (low, high, low open, unit). Absent: any finite number.
LIMITS: dict[str, tuple[float, float | None, bool, str]] = {
    "clearance_mm": (*CLEARANCE_MM, False, "mm"),
    "volume_mm3": (0.0, None, True, "mm³"),
    "mass_g": (0.0, None, False, "g"),
    "rotation_deg": (0.0, 360.0, True, "deg"),
    "preload_deg": (-360.0, 360.0, False, "deg"),
    "joint_stiffness_nmm_per_rad": (0.0, None, True, "N·mm/rad"),
    "requested_stiffness_nmm_per_rad": (0.0, None, True, "N·mm/rad"),
    "link_length_mm": (0.0, None, True, "mm"),
    "tendon_moment_arm_mm": (0.0, None, True, "mm"),
    "tendon_wrap_angle_rad": (0.0, None, False, "rad"),
    "height_mm": (0.0, None, True, "mm"),
}


#: The manifest's typed top-level keys and their kinds (``_KINDS``).
_TOP_TYPED = (
    ("material", "str"),
    ("printer", "str"),
    ("clearance_mm", "float"),
    ("base_palmar_outline_mm", "list[list[float]]"),
)


class ManifestError(ParameterError):
    """A manifest key is missing, has the wrong type or is out of range: ``<source>: <key path> <problem>``
    (``source`` is the file, or "manifest" for an object given in memory)."""

    def __init__(self, key: str, value: Any, problem: str, source: str = "manifest") -> None:
        super().__init__(key, value, problem)
        self.problem, self.source = problem, source
        self.args = (f"{source}: {quote(key, 120, repr_=False)} {problem}",)

    def at(self, source: str | os.PathLike[str]) -> ManifestError:
        """The same error, naming the file ``source``."""
        return ManifestError(self.parameter, self.value, self.problem, str(source))


# --------------------------------------------------------------------------
# typed values: a field's annotation says what its JSON value must be
# --------------------------------------------------------------------------


def _is_number(v: object) -> bool:
    """A finite int or float (not a bool)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _vector(v: object) -> bool:
    return isinstance(v, (list, tuple)) and len(v) == 3 and all(_is_number(x) for x in v)


def _polyline(v: object) -> bool:
    """At least two [x, y] points of finite numbers, x increasing (an outline ordered along its link)."""
    if not isinstance(v, (list, tuple)) or len(v) < 2:
        return False
    if not all(isinstance(p, (list, tuple)) and len(p) == 2 and all(_is_number(c) for c in p) for p in v):
        return False
    return all(a[0] < b[0] for a, b in itertools.pairwise(v))


#: annotation (without "| None") → (test, what the error says it must be). The annotations are read as
#: strings (``from __future__ import annotations`` above): a field's type is its JSON schema.
_KINDS: dict[str, tuple[Callable[[Any], bool], str]] = {
    "str": (lambda v: isinstance(v, str), "must be a string"),
    "float": (_is_number, "must be a finite number"),
    "list[float]": (_vector, "must be a list of 3 numbers"),
    "dict[str, Any]": (lambda v: isinstance(v, dict), "must be an object"),
    "list[list[float]]": (_polyline, "must be a list of at least 2 [x, y] points, x increasing"),
}


def _typed_fields(cls: type[Any]) -> list[tuple[str, str, bool]]:
    """(name, kind, required) of a dataclass's JSON fields, in order (``extra`` excluded)."""
    out = []
    for f in dataclasses.fields(cls):
        if f.name != "extra":
            assert isinstance(f.type, str)  # the annotations are strings (see _KINDS)
            kind = f.type.replace(" | None", "")
            out.append((f.name, kind, kind == f.type))
    return out


def _check(kind: str, value: Any, path: str) -> Any:
    """``value`` if it is of ``kind`` and within the LIMITS of its field (the last part of ``path``)."""
    test, must = _KINDS[kind]
    if value is None:
        return None
    if not test(value):
        raise ManifestError(path, value, f"{must}, not {quote(value)}")
    name = path.rsplit(".", 1)[-1]
    if name in LIMITS:
        lo, hi, lo_open, unit = LIMITS[name]
        if (value <= lo if lo_open else value < lo) or (hi is not None and value > hi):
            raise ManifestError(path, value, f"{default_limit(lo, hi, unit, lo_open=lo_open)}, not {quote(value)}")
    if name == "axis_dir" and math.hypot(*value) < 1e-9:
        raise ManifestError(path, value, f"must be a non-zero direction, not {quote(value)}")
    if kind == "list[list[float]]":
        return [[float(c) for c in p] for p in value]
    return list(value) if kind == "list[float]" else value


_E = TypeVar("_E", bound="_Entry")


def _read(cls: type[_E], data: Any, path: str) -> _E:
    """``cls`` from a JSON object: typed fields checked, other keys into ``extra``."""
    if not isinstance(data, dict):
        raise ManifestError(path.rstrip("."), data, f"must be an object, not {quote(data)}")
    values: JSONObject = {}
    extra: JSONObject = {}
    kinds = {name: (kind, req) for name, kind, req in _typed_fields(cls)}
    for key, v in data.items():
        if key in kinds:
            values[key] = _check(kinds[key][0], v, path + key)
        else:
            extra[key] = v
    for name, (_, required) in kinds.items():
        if required and values.get(name) is None:
            raise ManifestError(path + name, None, "is required")
    return cls(**values, extra=extra)


def _write(obj: _Entry) -> JSONObject:
    """JSON object of a typed entry: its set fields in order, then ``extra``."""
    out = {name: getattr(obj, name) for name, _, _ in _typed_fields(type(obj)) if getattr(obj, name) is not None}
    out.update(obj.extra)
    return out


# --------------------------------------------------------------------------
# the entries and the manifest
# --------------------------------------------------------------------------


class _Entry:
    """A typed JSON object: ``to_json`` writes its set fields then ``extra``; ``from_json`` checks types."""

    _PATH = ""
    extra: JSONObject

    if TYPE_CHECKING:  # each entry is a dataclass, built from its fields by keyword

        def __init__(self, **values: Any) -> None: ...

    def to_json(self) -> JSONObject:
        return _write(self)

    @classmethod
    def from_json(cls, data: Any, path: str | None = None) -> Self:
        return _read(cls, data, cls._PATH if path is None else path)


@dataclass
class BodyEntry(_Entry):
    """One printed body: its name (as in the 3MF and STEP), volume [mm³], mass [g] and centre of mass at rest
    (finger or joint coordinates) [mm]."""

    name: str
    volume_mm3: float | None = None
    mass_g: float | None = None
    com_mm: list[float] | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    _PATH = "body."


@dataclass
class JointEntry(_Entry):
    """One joint: parent and child bodies, the axis at rest (point, direction), the spring and its angles,
    and the tendon's measured moment arm and wrap angle (in the channel that feeds the joint); in a finger, the
    child body's palmar outline."""

    parent: str | None = None
    child: str | None = None
    axis_point_mm: list[float] | None = None
    axis_dir: list[float] | None = None
    joint_stiffness_nmm_per_rad: float | None = None
    requested_stiffness_nmm_per_rad: float | None = None
    spring: dict[str, Any] | None = None
    preload_deg: float | None = None
    rotation_deg: float | None = None
    link_length_mm: float | None = None
    z_mid_mm: float | None = None
    height_mm: float | None = None
    tendon_moment_arm_mm: float | None = None
    tendon_wrap_angle_rad: float | None = None
    #: the child body's palmar outline in the flexion plane, in the link's frame (rjcad.cad.outline) [mm]
    palmar_outline_mm: list[list[float]] | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    _PATH = "joint."


@dataclass
class Manifest:
    """A built joint (``kind`` "joint": one joint, its child the moving body) or finger ("finger")."""

    kind: str
    joints: list[JointEntry]
    bodies: list[BodyEntry] | None = None
    material: str | None = None
    printer: str | None = None
    clearance_mm: float | None = None
    #: a finger's base's palmar outline in the flexion plane, in the finger's frame [mm]
    base_palmar_outline_mm: list[list[float]] | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    #: the schema version it was read from (0: a joint's keys were flat at the top)
    read_version: int = field(default=SCHEMA_VERSION, compare=False, repr=False)

    def __post_init__(self) -> None:
        if self.kind not in KEY_ORDER:
            raise ValueError(f"Manifest.kind must be one of {sorted(KEY_ORDER)}, not {self.kind!r}")

    # --- writing ---------------------------------------------------------------
    def to_json(self) -> JSONObject:
        """The JSON object: ``schema_version`` first, then the keys in ``KEY_ORDER``, then any others."""
        values = {k: getattr(self, k) for k, _ in _TOP_TYPED if getattr(self, k) is not None}
        values.update(self.extra)
        if self.bodies is not None:
            values["bodies"] = [b.to_json() for b in self.bodies]
        joints = [j.to_json() for j in self.joints]
        if self.kind == "joint":
            if self.joints:
                entry = joints[0]
                values.update({k: entry[f] for k, f in JOINT_FLAT_KEYS.items() if f in entry})
        else:
            values["joints"] = joints
        out: JSONObject = {"schema_version": SCHEMA_VERSION}
        out.update({k: values.pop(k) for k in KEY_ORDER[self.kind] if k in values})
        out.update(values)
        if self.kind == "joint":
            out["joints"] = joints
        return out

    # --- reading ---------------------------------------------------------------
    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> Manifest:
        """The manifest in the JSON file ``path`` (rjcad.io.untrusted); one error line naming the file (and key)."""
        return cls.from_json(read_json(path), source=path)

    @classmethod
    def from_json(cls, data: Any, source: str | os.PathLike[str] | None = None) -> Manifest:
        """The manifest of a JSON object of version 1 or 0; one ``ManifestError`` line naming a bad key (and
        ``source``, the file it came from, if given)."""
        try:
            return cls._from_json(data)
        except ManifestError as e:
            raise (e.at(source) if source is not None else e) from None

    @classmethod
    def _from_json(cls, data: Any) -> Manifest:
        if not isinstance(data, dict):
            raise ManifestError(
                "manifest",
                type(data).__name__,
                f"must be a JSON object, not {_JSON_TYPES.get(type(data), type(data).__name__)}",
            )
        version = data.get("schema_version", 0)
        if not _is_number(version) or version not in (0, SCHEMA_VERSION):
            raise ManifestError(
                "schema_version",
                version,
                f"is {quote(version)}: this rjcad reads versions 0 to "
                f"{SCHEMA_VERSION} (was the file written by a newer rjcad?)",
            )
        version = int(version)
        if version and "joints" not in data:
            raise ManifestError("joints", None, f"is required (schema_version {version})")
        kind = "joint" if "moving_body" in data or "joints" not in data else "finger"
        rest = {k: v for k, v in data.items() if k not in ("schema_version", "joints", "bodies")}
        typed = {k: _check(kind_, rest.pop(k, None), k) for k, kind_ in _TOP_TYPED}
        bodies = _bodies(data.get("bodies"))
        if kind == "joint" and "joints" not in data:
            joints = [_flat_joint(rest, bodies)]
        else:
            joints = _joint_list(data["joints"])
            if kind == "joint":
                _drop_mirrored(rest, joints)
        return cls(kind, joints, bodies, **typed, extra=rest, read_version=version)

    @classmethod
    def coerce(cls, manifest: Any) -> Manifest:
        """``manifest`` itself if it is a Manifest, else ``from_json(manifest)``."""
        return manifest if isinstance(manifest, cls) else cls.from_json(manifest)

    def key_path(self, i: int, name: str) -> str:
        """Where field ``name`` of joint ``i`` (0-based) is in the file: ``joints[i+1].name``, or the flat key."""
        if self.kind == "joint" and self.read_version == 0:
            return next((k for k, f in JOINT_FLAT_KEYS.items() if f == name), name)
        return f"joints[{i + 1}].{name}"

    # --- the JSON view, read-only (for printers and callers that want a key) --------------
    def __getitem__(self, key: str) -> Any:
        return self.to_json()[key]

    def __contains__(self, key: str) -> bool:
        return key in self.to_json()

    def get(self, key: str, default: Any = None) -> Any:
        return self.to_json().get(key, default)


_JSON_TYPES = {
    list: "an array",
    str: "a string",
    int: "a number",
    float: "a number",
    bool: "a boolean",
    type(None): "null",
}


def _bodies(data: Any) -> list[BodyEntry] | None:
    if data is None:
        return None
    if not isinstance(data, list):
        raise ManifestError("bodies", data, "must be a list of bodies")
    return [BodyEntry.from_json(b, f"bodies[{i}].") for i, b in enumerate(data, 1)]


def _joint_list(data: Any) -> list[JointEntry]:
    if not isinstance(data, list):
        raise ManifestError("joints", data, "must be a list of joints, proximal first")
    return [JointEntry.from_json(j, f"joints[{i}].") for i, j in enumerate(data, 1)]


def _flat_joint(rest: JSONObject, bodies: list[BodyEntry] | None) -> JointEntry:
    """Version 0 joint: the entry from the flat keys (consumed from ``rest``); its parent the other body."""
    kinds = {name: kind for name, kind, _ in _typed_fields(JointEntry)}
    values = {f: _check(kinds[f], rest.pop(k), k) for k, f in JOINT_FLAT_KEYS.items() if k in rest}
    child = values.get("child")
    if child is not None and bodies:
        values["parent"] = next((b.name for b in bodies if b.name != child), None)
    return JointEntry(**values)


def _drop_mirrored(rest: JSONObject, joints: list[JointEntry]) -> None:
    """Version 1 joint: the flat keys must agree with its one entry (which they mirror); drop them."""
    if len(joints) != 1:
        raise ManifestError("joints", len(joints), "must hold exactly one joint in a joint manifest (moving_body)")
    entry = joints[0].to_json()
    for k, f in JOINT_FLAT_KEYS.items():
        if k in rest:
            v = rest.pop(k)
            if entry.get(f) != v:
                raise ManifestError(k, v, f"= {quote(v)} disagrees with joints[1].{f} = {quote(entry.get(f))}")
