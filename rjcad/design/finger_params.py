"""A finger's design, validated (no CAD kernel): one ``JointParams`` per joint, the base length, and the
template they came from; ``rjcad.cad.finger`` builds it. Kept apart from the builder so that reading and
checking a template (``rjcad finger``'s bad input, ``rjcad simulate finger``) never imports OpenCASCADE."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Any

from rjcad import DEG
from rjcad.design.finger_lengths import DEFAULT_BASE_LENGTH, base_length_min, link_length_min, whole_mm
from rjcad.design.params import JOINT_DEFAULT_END, JointParams
from rjcad.errors import ParameterError, RjcadError
from rjcad.io import templates
from rjcad.io.config import check_key as _typed
from rjcad.io.config import load_toml
from rjcad.materials import profiles_beside

#: The paper's finger, as plain data in rjcad.io.templates (the builder's default).
PAPER_FINGER = templates.PAPER_FINGER
DEFAULT_FINGER = templates.DEFAULT_FINGER

GLOBAL_KEYS = templates.FINGER_KEYS
JOINT_KEYS = templates.FINGER_JOINT_KEYS
MAX_JOINTS = 6


@dataclass(frozen=True)
class FingerParams:
    """Validated finger design: one JointParams per joint, proximal to distal."""

    joints: tuple[JointParams, ...]
    base_length: float = 25.0
    source: str = "built-in paper finger"
    requested: tuple[dict[str, Any], ...] = field(default=(), repr=False)

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "<dict>") -> FingerParams:
        """Check keys and ranges of a finger template (see templates/finger.toml)."""
        from rjcad.physics.objects import objects_from_template

        built, requested = cls.joints_from_dict(data)
        objects_from_template(data)  # checked here, used by the simulation only (the build has no object)
        # a link whose length is not given: 40 mm, or the shortest whole mm that holds its joints if longer
        for i, (p, req) in enumerate(zip(built, requested)):
            if "link_length_mm" not in req:
                need = link_length_min(p, built[i + 1] if i + 1 < len(built) else None)
                if need > p.link_length + 1e-9:
                    built[i] = replace(p, link_length=whole_mm(need))
        # no base length given: the shortest that holds joint 1 (whole mm, at least 25)
        base = (
            float(data["base_length_mm"])
            if "base_length_mm" in data
            else whole_mm(base_length_min(built[0]), DEFAULT_BASE_LENGTH)
        )
        fp = cls(tuple(built), base, source, tuple(requested))
        fp.validate_lengths()
        return fp

    @staticmethod
    def joints_from_dict(
        data: dict[str, Any], profiles: dict[str, Any] | None = None
    ) -> tuple[list[JointParams], list[dict[str, Any]]]:
        """A template's joints, validated, with one eye (or tendon) plane for the whole finger, and each joint's
        table as given; the lengths are checked by :meth:`validate_lengths`. ``profiles``: a ``printer`` and
        ``material`` (profiles, such as a manifest embeds) in the place of the template's names."""
        for k, v in data.items():
            _typed("", k, v, GLOBAL_KEYS)
        defaults = {k: _typed("defaults.", k, v, JOINT_KEYS) for k, v in data.get("defaults", {}).items()}
        joints = data.get("joint", [])
        if not 1 <= len(joints) <= MAX_JOINTS:
            raise ParameterError("joint", len(joints), f"a finger needs 1 to {MAX_JOINTS} [[joint]] tables")
        common: dict[str, Any] = dict(
            material=data.get("material", "absplus-p430"),
            printer=data.get("printer", "generic-0.4"),
            clearance=float(data["clearance_mm"]) if "clearance_mm" in data else None,
            layout=data.get("layout"),
            tendon_diameter=float(data.get("tendon_diameter_mm", 1.0)),
            safety_factor=float(data.get("safety_factor", 1.5)),
            end=data.get("end", JOINT_DEFAULT_END),
        ) | (profiles or {})
        built: list[JointParams] = []
        requested: list[dict[str, Any]] = []
        for i, j in enumerate(joints, start=1):
            where = f"joint[{i}]."
            if not isinstance(j, dict):
                raise ParameterError(f"joint[{i}]", j, "must be a table")
            merged = {**defaults, **{k: _typed(where, k, v, JOINT_KEYS) for k, v in j.items()}}
            if "stiffness_nmm_per_rad" not in merged:
                raise ParameterError(f"{where}stiffness_nmm_per_rad", None, "is required (here or in [defaults])")
            kw: dict[str, Any] = dict(
                stiffness=float(merged["stiffness_nmm_per_rad"]),
                rotation=float(merged.get("rotation_deg", 90)) * DEG,
                preload=float(merged.get("preload_deg", 90)) * DEG,
                link_length=float(merged.get("link_length_mm", 40)),
                tendon_moment_arm=(float(merged["tendon_moment_arm_mm"]) if "tendon_moment_arm_mm" in merged else None),
                arms=int(merged.get("arms", 1)),
            )
            try:
                built.append(JointParams(**kw, **common, standalone=False))
            except ParameterError as e:
                name = {
                    "stiffness": "stiffness_nmm_per_rad",
                    "rotation": "rotation_deg",
                    "preload": "preload_deg",
                    "link_length": "link_length_mm",
                    "tendon_moment_arm": "tendon_moment_arm_mm",
                    "clearance": "clearance_mm",
                    "tendon_diameter": "tendon_diameter_mm",
                }.get(e.parameter, e.parameter)
                prefix = where if name in JOINT_KEYS else ""
                raise ParameterError(f"{prefix}{name}", e.value, e.limit, unit=e.unit) from None
            except RjcadError as e:
                raise RjcadError(
                    f"{where}stiffness_nmm_per_rad = {kw['stiffness']:g}: no printable spring: {e}"
                ) from None
            requested.append(merged)
        # one eye plane for the whole finger, so that the tendon runs straight: a joint with a narrower
        # spring gets thicker cheeks, b_max − b each, and all joints share z_mid and the height
        b_max = max(p.spring.width for p in built)
        built = [replace(p, cheek_thickness=p.cheek_thickness + (b_max - p.spring.width)) for p in built]
        # desktop: each joint's tendon plane is raised to the highest one's (its band and arm grow)
        z_top = max(p.z_mid for p in built)
        built = [replace(p, tendon_lift=z_top - p.z_mid) if p.layout == "desktop" else p for p in built]
        # a link block is as wide as the wider of the joints it joins (rjcad.cad.finger.link_body): each joint's
        # moving block must clear the ground block it turns against at those widths
        half = [p.link_width / 2 for p in built]
        for i, p in enumerate(built):
            wg = max(half[i], half[i - 1]) if i > 0 else half[i]
            wm = max(half[i], half[i + 1]) if i + 1 < len(built) else half[i]
            if (wg, wm) != (half[i], half[i]):
                built[i] = replace(p, ground_half_width=wg, moving_half_width=wm)
        return built, requested

    @classmethod
    def from_toml(cls, path: str | Path, given: dict[str, Any] | None = None) -> FingerParams:
        """The template ``path`` (a profile path in it taken from its folder), ``given`` keys replacing its own."""
        data = profiles_beside(load_toml(path, GLOBAL_KEYS), Path(path).parent)
        return cls.from_dict(data | (given or {}), source=str(path))

    def validate_lengths(self) -> None:
        """Each link must hold its joints' blocks, the tendon slot and the anchor (rjcad.design.finger_lengths)."""
        js = self.joints
        lo = base_length_min(js[0])
        if not lo <= self.base_length <= 150:
            raise ParameterError("base_length_mm", self.base_length, f"must be in [{lo:.1f}, 150] mm", unit="mm")
        for i, p in enumerate(js, start=1):
            need = link_length_min(p, js[i] if i < len(js) else None)
            if p.link_length < need - 1e-9:
                raise ParameterError(
                    f"joint[{i}].link_length_mm",
                    p.link_length,
                    f"must be >= {need:.1f} mm for these joints (their blocks, the slot, the tendon's channel)",
                    unit="mm",
                )
        length, bed = self.base_length + sum(p.link_length for p in js), js[0].printer_spec.bed_length
        if length > bed + 1e-9:
            raise ParameterError(
                "base_length_mm + link_length_mm",
                length,
                f"the finger lies straight on the bed: must be <= {bed:g} mm on {js[0].printer_spec.key}",
                unit="mm",
            )

    @property
    def n(self) -> int:
        return len(self.joints)

    @property
    def body_names(self) -> list[str]:
        return ["base"] + [f"link{i}" for i in range(1, self.n)] + ["distal"]

    @cached_property
    def axis_x(self) -> list[float]:
        """x of each joint axis at rest [mm]."""
        xs = [0.0]
        for p in self.joints[:-1]:
            xs.append(xs[-1] + p.link_length)
        return xs

    @property
    def material(self) -> str:
        return self.joints[0].material
