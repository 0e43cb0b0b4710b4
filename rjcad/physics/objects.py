"""Objects a finger grasps, in its flexion plane: cylinders and boxes, fixed or free, with contact friction.

Frame: the base's, in mm (the straight finger along +x from joint 1 at the origin, flexion about +z, the palm +y).
A box's ``angle`` [rad] turns its width ``w`` (along x at 0) about +z. A free object has a mass [g]; a fixed one
does not move. ``mu`` is the Coulomb coefficient of its contacts with the links and with other objects (a pair
uses the larger of its two). The command line's spec and a template's ``[[object]]`` table give degrees.
"""

from __future__ import annotations

import math
from dataclasses import KW_ONLY, dataclass
from typing import Any

import numpy as np

from rjcad.errors import ParameterError
from rjcad.validate import in_range

#: Largest size and distance from the base [mm], mass [g] and friction coefficient an object may have.
MAX_MM, MAX_MASS_G, MAX_MU = 1e4, 1e6, 5.0


@dataclass(frozen=True)
class GraspObject:
    """What every object has: its centre (x, y) [mm], its turn [rad], friction, and fixed or free with a mass [g]."""

    x: float
    y: float
    _: KW_ONLY
    angle: float = 0.0
    mu: float = 0.0
    free: bool = False
    mass_g: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "y"):
            in_range(f"{self.kind} {name}", getattr(self, name), -MAX_MM, MAX_MM, unit="mm")
        in_range(f"{self.kind} angle", self.angle, -4 * math.pi, 4 * math.pi, deg=True)
        in_range(f"{self.kind} mu", self.mu, 0.0, MAX_MU)
        in_range(f"{self.kind} mass", self.mass_g, 0.0, MAX_MASS_G, unit="g")
        if self.free and self.mass_g <= 0:
            raise ParameterError(f"{self.kind} mass", self.mass_g, "a free object needs a mass > 0", "g")

    kind = "object"

    @property
    def centre(self) -> np.ndarray:
        return np.array([self.x, self.y], dtype=float)

    @property
    def radius(self) -> float:
        """Radius of the smallest circle about the centre that holds the object [mm]."""
        raise NotImplementedError

    def _spec_keys(self) -> dict[str, Any]:
        return {}

    def to_dict(self) -> dict[str, Any]:
        """The template's ``[[object]]`` table (degrees for the angle)."""
        out: dict[str, Any] = {"kind": self.kind, **self._spec_keys(), "x_mm": self.x, "y_mm": self.y}
        if self.angle:
            out["angle_deg"] = math.degrees(self.angle)
        out["mu"] = self.mu
        out["free"] = self.free
        if self.free:
            out["mass_g"] = self.mass_g
        return out


@dataclass(frozen=True)
class Cylinder(GraspObject):
    """A cylinder across the flexion plane: a circle of ``diameter`` [mm]."""

    diameter: float = 0.0
    kind = "cylinder"

    def __post_init__(self) -> None:
        super().__post_init__()
        in_range("cylinder diameter", self.diameter, 0.0, MAX_MM, lo_open=True, unit="mm")

    @property
    def radius(self) -> float:
        return self.diameter / 2.0

    def _spec_keys(self) -> dict[str, Any]:
        return {"diameter_mm": self.diameter}


@dataclass(frozen=True)
class Box(GraspObject):
    """A box across the flexion plane: a rectangle ``w`` × ``h`` [mm] turned by ``angle`` about its centre."""

    w: float = 0.0
    h: float = 0.0
    kind = "box"

    def __post_init__(self) -> None:
        super().__post_init__()
        in_range("box w", self.w, 0.0, MAX_MM, lo_open=True, unit="mm")
        in_range("box h", self.h, 0.0, MAX_MM, lo_open=True, unit="mm")

    @property
    def radius(self) -> float:
        return math.hypot(self.w, self.h) / 2.0

    def corners(self, x: float | None = None, y: float | None = None, angle: float | None = None) -> np.ndarray:
        """The four corners (4, 2) [mm], counter-clockwise, at the pose (x, y, angle) (default: its own)."""
        x = self.x if x is None else x
        y = self.y if y is None else y
        a = self.angle if angle is None else angle
        c, s = math.cos(a), math.sin(a)
        local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float) * [self.w / 2, self.h / 2]
        out: np.ndarray = np.array([x, y]) + local @ np.array([[c, s], [-s, c]])
        return out

    def _spec_keys(self) -> dict[str, Any]:
        return {"w_mm": self.w, "h_mm": self.h}


Object = Cylinder | Box

#: Spec keys per kind: the dimensions (required), then what both take.
_DIMENSIONS = {"cylinder": ("diameter",), "box": ("w", "h")}
_COMMON = ("x", "y", "angle", "mu", "mass")


def parse_object(spec: str) -> Object:
    """An object from the command line's ``KIND:key=value,...`` (mm, degrees, g), e.g.
    ``cylinder:diameter=40,x=60,y=25,mu=0.5,free,mass=20`` or ``box:w=30,h=20,x=50,y=30,angle=15,fixed``."""
    kind, sep, rest = str(spec).partition(":")
    kind = kind.strip().lower()
    if not sep or kind not in _DIMENSIONS:
        raise ParameterError("--object", spec, "must be cylinder:KEY=VALUE,... or box:KEY=VALUE,...")
    values: dict[str, float] = {}
    free: bool | None = None
    for item in (p.strip() for p in rest.split(",")):
        if not item:
            continue
        if item in ("free", "fixed"):
            if free is not None:
                raise ParameterError("--object", spec, "give fixed or free once")
            free = item == "free"
            continue
        key, eq, text = item.partition("=")
        key = key.strip().lower()
        if not eq or key not in _DIMENSIONS[kind] + _COMMON:
            known = ", ".join(_DIMENSIONS[kind] + _COMMON)
            raise ParameterError("--object", spec, f"{item!r} is not KEY=VALUE with KEY one of {known}, fixed, free")
        if key in values:
            raise ParameterError("--object", spec, f"{key} is given twice")
        values[key] = in_range(f"--object {key}", text.strip(), limit="must be a finite number")
    return _make(kind, values, free, "--object")


def object_from_table(table: Any, where: str = "object") -> Object:
    """An object from a template's ``[[object]]`` table: ``kind``, the dimensions in ``*_mm``, ``x_mm``, ``y_mm``,
    and optionally ``angle_deg``, ``mu``, ``free`` and ``mass_g``."""
    if not isinstance(table, dict):
        raise ParameterError(where, table, "must be a table of kind, x_mm, y_mm, ...")
    kind = str(table.get("kind", "")).lower()
    if kind not in _DIMENSIONS:
        raise ParameterError(f"{where}.kind", table.get("kind"), "must be cylinder or box")
    keys = {f"{k}_mm": k for k in _DIMENSIONS[kind] + ("x", "y")} | {"angle_deg": "angle", "mu": "mu"}
    keys |= {"mass_g": "mass"}
    unknown = sorted(set(table) - set(keys) - {"kind", "free"})
    if unknown:
        raise ParameterError(f"{where}.{unknown[0]}", table[unknown[0]], f"is not a key of a {kind}")
    for key in set(keys) & set(table):  # a template's numbers are TOML numbers, as its other keys
        if isinstance(table[key], bool) or not isinstance(table[key], (int, float)):
            raise ParameterError(f"{where}.{key}", table[key], "must be a number")
    values = {short: in_range(f"{where}.{key}", table[key]) for key, short in keys.items() if key in table}
    free = table.get("free")
    if free is not None and not isinstance(free, bool):
        raise ParameterError(f"{where}.free", free, "must be true or false")
    return _make(kind, values, free, where)


def _make(kind: str, values: dict[str, float], free: bool | None, where: str) -> Object:
    missing = [k for k in _DIMENSIONS[kind] + ("x", "y") if k not in values]
    if missing:
        raise ParameterError(where, kind, f"needs {', '.join(missing)}")
    common: dict[str, Any] = {
        "x": values["x"],
        "y": values["y"],
        "angle": math.radians(values.get("angle", 0.0)),
        "mu": values.get("mu", 0.0),
        "free": bool(free),
        "mass_g": values.get("mass", 0.0),
    }
    if not free and "mass" in values:
        raise ParameterError(f"{where} mass", values["mass"], "only a free object has a mass: add free")
    if kind == "cylinder" and "angle" in values:
        raise ParameterError(f"{where} angle", values["angle"], "a cylinder has no angle")
    try:
        if kind == "cylinder":
            return Cylinder(diameter=values["diameter"], **common)
        return Box(w=values["w"], h=values["h"], **common)
    except ParameterError as e:  # a range: named after where the object was given (--object, object[2])
        raise ParameterError(f"{where} {e.parameter}", e.value, e.limit, e.unit) from None


def objects_from_template(data: dict[str, Any], name: str = "") -> list[Object]:
    """A finger template's ``[[object]]`` tables as objects (none: []), each checked by ``object_from_table``."""
    tables = data.get("object", [])
    prefix = f"{name}: " if name else ""
    if not isinstance(tables, list):
        raise ParameterError(f"{prefix}object", tables, "must be [[object]] tables")
    return [object_from_table(t, f"{prefix}object[{i}]") for i, t in enumerate(tables, start=1)]
