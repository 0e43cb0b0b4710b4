"""The design options of ``rjcad spring`` and ``rjcad joint``, shared by the CLI and the Python API (``rjcad.api``).

One ``Field`` per option: its ``--flag``, its TOML key (``--config``), the API's keyword (the TOML key, but
``stiffness`` for ``stiffness_nmm_per_rad``), its type, help, and whether it is an angle (degrees on the command
line, in TOML and in the API; rad inside). No click here: the API imports this module too.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

from rjcad import DEG
from rjcad.errors import ParameterError
from rjcad.materials import DEFAULT_MATERIAL, DEFAULT_PRINTER, MATERIALS, PRINTERS

#: TOML keys whose API keyword is another word.
_KEYWORDS = {"stiffness_nmm_per_rad": "stiffness"}


class Field(NamedTuple):
    """One design option: ``--flag``, its TOML key, its type (float, int or str), help, and if it is an angle."""

    flag: str
    toml: str
    type: type
    help: str
    degrees: bool = False

    @property
    def name(self) -> str:
        """The option's Python name: ``--width-min`` → ``width_min``."""
        return self.flag[2:].replace("-", "_")

    @property
    def keyword(self) -> str:
        """The API's keyword: the TOML key (``rotation_deg``, ``clearance_mm``), ``stiffness`` for the stiffness."""
        return _KEYWORDS.get(self.toml, self.toml)

    def internal(self, value: Any) -> Any:
        """``value`` as ``type`` in rjcad units (degrees → rad)."""
        v = self.type(value)
        return v * DEG if self.degrees else v


#: The spring requirement, in the order ``rjcad spring --help`` shows it.
REQUIREMENT = (
    Field("--stiffness", "stiffness_nmm_per_rad", float, "Joint stiffness, both springs [N·mm/rad]."),
    Field("--rotation", "rotation_deg", float, "Joint rotation range [deg] (default 90).", degrees=True),
    Field("--preload", "preload_deg", float, "Spring preload at rest [deg] (default 90).", degrees=True),
    Field(
        "--material",
        "material",
        str,
        f"A material: built in ({', '.join(MATERIALS)}; default {DEFAULT_MATERIAL}), a name in your profile "
        "folder, or a profile file (.toml); see rjcad profiles.",
    ),
    Field(
        "--printer",
        "printer",
        str,
        f"A printer: built in ({', '.join(PRINTERS)}; default {DEFAULT_PRINTER}), a name in your profile "
        "folder, or a profile file (.toml); see rjcad profiles.",
    ),
    Field("--safety-factor", "safety_factor", float, "Safety factor on yield (default 1.5)."),
    Field(
        "--end",
        "end",
        str,
        "Outer end condition: clamped (default: position and angle held) or pinned (free to turn about its post).",
    ),
)


def requirement(after_printer: tuple[Field, ...] = (), **helps: str) -> tuple[Field, ...]:
    """``REQUIREMENT`` with ``after_printer`` inserted after ``--printer`` and help texts replaced (name → help)."""
    unknown = set(helps) - {f.name for f in REQUIREMENT}
    if unknown:
        raise TypeError(f"requirement(): no option {', '.join(sorted(unknown))}")
    fields = tuple(f._replace(help=helps.get(f.name, f.help)) for f in REQUIREMENT)
    at = [f.name for f in fields].index("printer") + 1
    return fields[:at] + tuple(after_printer) + fields[at:]


#: ``rjcad spring``'s options (``rjcad.api.design_spring``'s keywords): the requirement, then the optimiser's
#: bounds and the life constraint.
SPRING_FIELDS = requirement() + (
    Field(
        "--springs",
        "springs",
        int,
        "Springs sharing the joint stiffness: 2 (default; the stacked layout, the "
        "paper's) or 1 (the desktop layout's one spring on the bed).",
    ),
    Field(
        "--arms",
        "arms",
        int,
        "Arms of each spring: 1 (default) or 2 interleaved arms 180° apart, each half the torque (length, pitch "
        "and turns per arm; the net force on the hub is reported).",
    ),
    Field(
        "--min-gap",
        "min_gap_mm",
        float,
        "Gap the coils keep over the whole wind-up [mm] (default: the printer's "
        "minimum gap; the desktop joint uses its clearance, e.g. 0.40 for ABS).",
    ),
    Field("--width-min", "width_min_mm", float, "Lower bound on spring width b [mm] (default 1)."),
    Field("--width-max", "width_max_mm", float, "Upper bound on spring width b [mm] (default 10)."),
    Field(
        "--inner-radius-min", "inner_radius_min_mm", float, "Lower bound on the inner (pin) radius [mm] (default 3)."
    ),
    Field(
        "--inner-radius-max", "inner_radius_max_mm", float, "Upper bound on the inner (pin) radius [mm] (default 10)."
    ),
    Field("--max-outer-radius", "max_outer_radius_mm", float, "Largest allowed outer radius [mm] (default 20)."),
    Field("--min-turns", "min_turns", float, "Fewest turns of the spiral (default 1)."),
    Field("--min-cycles", "min_cycles", float, "Required life: lower 90 % bound of the predicted cycles."),
    Field("--backlash", "backlash_mm", float, "Pin backlash for the life model [mm] (default 0.25)."),
)
#: Spring options whose SpringRequirement field has another name.
_SPRING_RENAMED = {"stiffness": "joint_stiffness", "max_outer_radius": "outer_radius_max", "min_gap_mm": "min_gap"}

#: ``rjcad joint``'s options (``rjcad.api.build_joint``'s keywords): the spring requirement with the module's
#: geometry after ``--printer``; their names are JointParams' fields.
JOINT_FIELDS = requirement(
    after_printer=(
        Field(
            "--clearance",
            "clearance_mm",
            float,
            "Clearance between the bodies [mm] (default: desktop, the material's print-in-place "
            "clearance, PLA 0.35, ABS 0.40, PETG 0.45; stacked 0.25).",
        ),
        Field(
            "--layout",
            "layout",
            str,
            "desktop (default without soluble support: one spring on the bed under nested 50° "
            "cones, no support) or stacked (the paper's, two springs; default on dimension-elite).",
        ),
        Field(
            "--arms",
            "arms",
            int,
            "Spring arms, desktop layout: 1 (default) or 2 interleaved arms 180° apart, each with its own key and "
            "socket (their forces on the hub cancel; the arms need a far larger spring for the same wind-up).",
        ),
        Field(
            "--link-length",
            "link_length_mm",
            float,
            "Axis to link end, each link [mm] (default 40; at most half the bed's longest side).",
        ),
        Field("--tendon-diameter", "tendon_diameter_mm", float, "Tendon channel diameter [mm] (default 1.0)."),
        Field(
            "--tendon-moment-arm", "tendon_moment_arm_mm", float, "Tendon moment arm about the axis [mm] (default 6)."
        ),
        Field("--pin-radius", "pin_radius_mm", float, "Knuckle pin radius [mm] (default 2)."),
    ),
    stiffness="Joint stiffness, all springs [N·mm/rad] (default 5.2).",
    end="Spring outer end: clamped (default; a key in a socket) or pinned (a ring on a post; stacked only).",
)


def merge_config(
    options: Mapping[str, Any], config: str | os.PathLike[str] | None, fields: tuple[Field, ...]
) -> dict[str, Any]:
    """defaults < config file < explicit options: {option name: value in rjcad units} of every field given."""
    from rjcad.io.config import load_toml
    from rjcad.materials import profiles_beside

    by_name = {f.name: f for f in fields}
    given = {k: v for k, v in options.items() if v is not None and k in by_name}
    if config:
        toml_types = {f.toml: ((int, float) if f.type is float else f.type) for f in fields}
        by_key = {f.toml: f.name for f in fields}
        data = profiles_beside(load_toml(config, toml_types), Path(config).parent)
        for key, value in data.items():
            given.setdefault(by_key[key], value)
    return {name: by_name[name].internal(v) for name, v in given.items()}


_KINDS: dict[type, tuple[type, str]] = {
    float: (numbers.Real, "must be a number"),
    int: (numbers.Integral, "must be an integer"),
    str: (str, "must be a string"),
}


def from_keywords(values: Mapping[str, Any], fields: tuple[Field, ...]) -> dict[str, Any]:
    """The API's keywords (``None``: not given) as {option name: value}, as the CLI's options come; a value of
    the wrong type is a ParameterError naming its keyword (booleans are not numbers)."""
    by_keyword = {f.keyword: f for f in fields}
    out: dict[str, Any] = {}
    for key, value in values.items():
        if key not in by_keyword:
            raise TypeError(f"unexpected keyword argument {key!r}")
        if value is None:
            continue
        f = by_keyword[key]
        kind, text = _KINDS[f.type]
        if isinstance(value, bool) or not isinstance(value, kind):
            raise ParameterError(key, value, text)
        try:
            f.internal(value)
        except (OverflowError, ValueError):  # an integer beyond a float
            raise ParameterError(key, value, text) from None
        out[f.name] = value
    return out


def spring_kwargs(merged: Mapping[str, Any]) -> dict[str, Any]:
    """``merge_config``'s spring options as SpringRequirement's keywords (the rotation defaults to 90°)."""
    kwargs = {_SPRING_RENAMED.get(k, k): v for k, v in merged.items()}
    kwargs.setdefault("rotation", 90.0 * DEG)
    return kwargs
