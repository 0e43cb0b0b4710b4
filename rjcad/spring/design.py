"""A spring requirement (what the user asks of one joint) and a spring design (one spring of the pair).

A design's physics (stiffness, stresses, coil gap, contact, end force) comes from the full rod
model (:mod:`rjcad.spring.verify`, cached by geometry), wound in the joint's sense ``JOINT_SENSE``
(``unwind``) from the printed shape to preload + rotation; the closed form of
:mod:`rjcad.spring.formulas` is reported beside it. Lengths in mm, angles in rad, stresses in MPa.
A joint has ``springs`` springs in parallel (two in the stacked layout, one in the desktop layout), so a joint
of stiffness K_joint uses springs of K_joint/springs.

A design reports its predicted life through the predictor it was built with
(``life``; the optimiser passes ``rjcad.life.predict_cycles``): this module does not
import ``rjcad.life``, whose Table I stresses come from the spring formulas.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from rjcad.errors import ParameterError
from rjcad.materials import DEFAULT_MATERIAL, DEFAULT_PRINTER, Material, Printer, get_material, get_printer
from rjcad.spring.factors import JOINT_SENSE
from rjcad.spring.formulas import DEFAULT_END, END_CONDITIONS, TWO_PI, outer_radius, stiffness
from rjcad.spring.verify import RodCheck, check_design
from rjcad.validate import in_range

#: Thin-strip validity: the innermost centreline radius is at least this many t.
MIN_RADIUS_TO_THICKNESS = 3.0
#: A strip, not a plate on edge: width b is at least this many t.
MIN_WIDTH_TO_THICKNESS = 2.0
#: Stiffness tolerance the optimiser guarantees (relative).
STIFFNESS_TOLERANCE = 0.005
#: Largest net force of a two-arm spring on its hub, over one arm's reaction.
MAX_HUB_FORCE_RATIO = 0.05
#: The key a two-arm spring is verified with when the layout does not say: radially from 0.25·t inside the end's
#: centreline to this far outside it [mm] (the desktop layout's is shorter; it checks its own).
NOMINAL_KEY_REACH = 6.0
#: What the life keys of :meth:`SpringDesign.to_dict` rest on.
LIFE_NOTE = (
    "rjcad.life: Table I (ABSplus-P430, b = 4.8 mm, Dimension Elite), 90 % interval; "
    "an extrapolation for other materials and printers"
)

#: (stress amplitude [MPa], thickness [mm], backlash [mm]) → (median, lower, upper) cycles, as arrays.
LifePredictor = Callable[..., tuple[Any, Any, Any]]


def check_end(end: str) -> str:
    """``end`` if it is a known end condition, else ParameterError naming the known ones."""
    if end not in END_CONDITIONS:
        raise ParameterError("end", end, f"known end conditions: {', '.join(END_CONDITIONS)}")
    return end


def _angle(name: str, value: object, lo: float, lo_open: bool, limit: str) -> None:
    """An angle in rad within lo..360° (shown in degrees); a non-finite value is shown as given."""
    in_range(name, value, limit=limit)
    in_range(name, value, lo, TWO_PI + 1e-12, lo_open=lo_open, deg=True, limit=limit)


@dataclass(frozen=True)
class SpringRequirement:
    """What the user asks of one joint; validated on construction.

    Angles in rad. ``joint_stiffness`` is the sum of the twin springs (N·mm/rad), the slope of the
    torque over the working range preload → preload + rotation. ``pin_radius`` (optional): the pin
    the inner end is fused to; the strip then keeps the printer's minimum gap to it too.
    """

    joint_stiffness: float
    rotation: float
    preload: float = math.pi / 2
    material: str = DEFAULT_MATERIAL
    printer: str = DEFAULT_PRINTER
    safety_factor: float = 1.5
    end: str = DEFAULT_END
    width_min: float = 1.0
    width_max: float = 10.0
    inner_radius_min: float = 3.0
    inner_radius_max: float = 10.0
    outer_radius_max: float = 20.0
    min_turns: float = 1.0
    min_cycles: float | None = None
    backlash: float = 0.25
    pin_radius: float | None = None
    #: Springs in parallel in the joint: 2 (stacked layout, one each side) or 1 (desktop layout, on the bed).
    springs: int = 2
    #: Smallest gap the coils keep over the whole wind-up [mm]; None: the printer's minimum gap.
    min_gap: float | None = None
    #: Arms of each spring: 1, or 2 interleaved arms 180° apart, each carrying half the spring's torque.
    arms: int = 1

    def __post_init__(self) -> None:
        # lower bounds far below any printable spring (a 1 m strip of 0.4 × 1 mm ABS is 0.01 N·mm/rad), but
        # away from 0: the optimiser divides by them
        in_range(
            "stiffness",
            self.joint_stiffness,
            0.01,
            1e4,
            limit="must be >= 0.01 and <= 10000 N·mm/rad (joint, both springs)",
        )
        _angle("rotation", self.rotation, math.radians(1.0), False, "must be >= 1 and <= 360 deg")
        _angle("preload", self.preload, 0, False, "must be >= 0 and <= 360 deg")
        in_range("safety_factor", self.safety_factor, 1.0, 100.0, limit="must be >= 1 and <= 100")
        for name in ("width_min", "width_max", "inner_radius_min", "inner_radius_max", "outer_radius_max"):
            shown = "max_outer_radius" if name == "outer_radius_max" else name  # as the CLI and TOML spell it
            in_range(shown, getattr(self, name), 0.01, 1000, limit="must be >= 0.01 and <= 1000 mm")
        in_range("width_max", self.width_max, self.width_min, limit=f"must be >= width_min = {self.width_min} mm")
        in_range(
            "inner_radius_max",
            self.inner_radius_max,
            self.inner_radius_min,
            limit=f"must be >= inner_radius_min = {self.inner_radius_min} mm",
        )
        in_range("min_turns", self.min_turns, 0.25, 100, limit="must be >= 0.25 and <= 100")
        if self.min_cycles is not None:
            in_range("min_cycles", self.min_cycles, 1, 1e9, limit="must be >= 1 and <= 1e9 cycles")
        in_range("backlash", self.backlash, 0.05, 1.5, limit="must be >= 0.05 and <= 1.5 mm")
        if self.pin_radius is not None:
            in_range("pin_radius", self.pin_radius, 0, 100, lo_open=True, limit="must be > 0 and <= 100 mm")
        if self.springs not in (1, 2):
            raise ParameterError("springs", self.springs, "must be 1 or 2 springs per joint")
        if self.arms not in (1, 2) or isinstance(self.arms, bool):
            raise ParameterError("arms", self.arms, "must be 1 or 2 spring arms")
        if self.min_gap is not None:
            in_range("min_gap", self.min_gap, 0.05, 2.0, limit="must be >= 0.05 and <= 2 mm")
        check_end(self.end)
        object.__setattr__(self, "material", get_material(self.material).ref)
        object.__setattr__(self, "printer", get_printer(self.printer).ref)

    @property
    def material_spec(self) -> Material:
        return get_material(self.material)

    @property
    def printer_spec(self) -> Printer:
        return get_printer(self.printer)

    @property
    def spring_stiffness(self) -> float:
        """Stiffness of one spring, K_joint/springs [N·mm/rad]."""
        return self.joint_stiffness / self.springs

    @property
    def gap_min(self) -> float:
        """The coil gap kept over the wind-up: ``min_gap``, else the printer's minimum gap [mm]."""
        return self.printer_spec.min_gap_mm if self.min_gap is None else self.min_gap

    @property
    def max_windup(self) -> float:
        """Total wind-up from the printed shape, preload + rotation [rad]."""
        return self.preload + self.rotation

    @property
    def allowed_stress(self) -> float:
        """Yield / safety factor [MPa]."""
        return self.material_spec.yield_strength_mpa / self.safety_factor


@dataclass(frozen=True)
class SpringDesign:
    """One spiral spring of a twin-spring joint. Lengths in mm, angles in rad.

    Its physics is the rod model's (``rod``, computed once per geometry and sense). ``life`` predicts
    cycles from (stress amplitude, thickness, backlash); without it the design has no predicted life.
    """

    width: float
    thickness: float
    length: float
    inner_radius: float
    pitch: float
    turns: float
    requirement: SpringRequirement = field(repr=False)
    life: LifePredictor | None = field(default=None, repr=False, compare=False)
    #: How the joint loads the printed spiral: ``unwind`` (preload and flexion open it), the designer's
    #: constant; ``tighten`` only to judge springs printed the old way.
    sense: str = field(default=JOINT_SENSE, repr=False)

    # --- derived ------------------------------------------------------------
    @property
    def end(self) -> str:
        return self.requirement.end

    @property
    def youngs_modulus(self) -> float:
        """E of the requirement's material [MPa]."""
        return self.requirement.material_spec.youngs_modulus_mpa

    @property
    def arms(self) -> int:
        """Interleaved arms of the spring (1 or 2); ``length`` and ``turns`` are one arm's."""
        return self.requirement.arms

    @property
    def arm_pitch(self) -> float:
        """Pitch of one arm, arms × the coil-to-coil ``pitch`` [mm]."""
        return self.arms * self.pitch

    @property
    def nominal_key(self) -> tuple[float, float, float]:
        """(u0, u1, w) of the key a two-arm spring is verified with [mm] (rjcad.spring.rod.key_box)."""
        w = 2.0 * max(self.thickness, self.requirement.printer_spec.min_wall_mm)
        return (-0.25 * self.thickness, NOMINAL_KEY_REACH, w)

    @property
    def rod(self) -> RodCheck:
        """The rod model wound over 0..preload + rotation (cached by geometry)."""
        return check_design(self)

    @property
    def centreline_outer_radius(self) -> float:
        """r_in + arms·p·n [mm]."""
        return float(outer_radius(self.inner_radius, self.arm_pitch, self.turns))

    @property
    def outer_radius(self) -> float:
        """Encumbrance: outer centreline radius + t/2 [mm] (hook not included)."""
        return self.centreline_outer_radius + self.thickness / 2.0

    @property
    def formula_stiffness(self) -> float:
        """Closed form of one spring, arms·c_end·E·b·t³/(12L) (c_end 1 clamped, 0.8 pinned) [N·mm/rad]."""
        return self.arms * float(stiffness(self.youngs_modulus, self.width, self.thickness, self.length, self.end))

    @property
    def spring_stiffness(self) -> float:
        """One spring, rod model: torque slope over the working range [N·mm/rad]."""
        return self.rod.stiffness

    @property
    def joint_stiffness(self) -> float:
        """All the joint's springs together, springs × one spring's [N·mm/rad]."""
        return self.requirement.springs * self.spring_stiffness

    def stress_at(self, theta: float) -> float:
        """Peak stress at wind-up θ (rad, 0..preload + rotation) from the printed shape, rod model [MPa]."""
        return self.rod.stress_at(theta)

    @property
    def max_stress(self) -> float:
        """Peak stress over the whole wind-up, rod model [MPa]."""
        return self.rod.peak_stress

    @property
    def preload_stress(self) -> float:
        return self.stress_at(self.requirement.preload)

    @property
    def min_coil_gap(self) -> float:
        """Smallest gap between coils over 0..preload + rotation, rod model [mm]."""
        return float(self.rod.coil_gap.min())

    @property
    def min_pin_gap(self) -> float | None:
        """Smallest gap between the strip and the pin (with a pin radius), rod model [mm]."""
        return None if self.rod.pin_gap is None else float(self.rod.pin_gap.min())

    @property
    def min_key_gap(self) -> float | None:
        """Two arms: smallest gap between an arm and the other arm's (nominal) key, rod model [mm]; else None."""
        return self.rod.min_key_gap

    @property
    def first_contact(self) -> float | None:
        """Wind-up at which the coils first touch, rod model [rad]; None: not within the range."""
        return self.rod.first_contact

    @property
    def print_coil_gap(self) -> float:
        """Coil gap as printed (no wind-up), p − t [mm]."""
        return self.pitch - self.thickness

    @property
    def stress_amplitude(self) -> float:
        """Stress amplitude of the working cycle, (σ(preload + rotation) − σ(preload))/2, rod model [MPa]."""
        req = self.requirement
        return (self.stress_at(req.max_windup) - self.stress_at(req.preload)) / 2.0

    def predicted_life(self) -> tuple[float, float, float]:
        """Median cycles and 90 % interval from the life predictor (Table I's model, rjcad.life)."""
        if self.life is None:
            raise ValueError(
                "this spring design has no life predictor: build it with rjcad.spring.optimise "
                "(design_spring or design_from_dict)"
            )
        med, lo, hi = self.life(self.stress_amplitude, self.thickness, self.requirement.backlash)
        return float(med[0]), float(lo[0]), float(hi[0])

    def constraint_report(self) -> dict[str, tuple[float, float, bool]]:
        """Every constraint as name → (value, limit, met), physics from the rod model."""
        req = self.requirement
        pr = req.printer_spec
        steps = self.thickness / pr.thickness_step_mm
        k_err = abs(self.spring_stiffness / req.spring_stiffness - 1.0)
        tol = 1e-9
        extra = {}
        if req.min_cycles is not None:
            lo = self.predicted_life()[1]
            extra["life_lower_cycles"] = (lo, req.min_cycles, lo >= req.min_cycles * (1 - 1e-6))
        if self.arms == 2:
            kg = self.min_key_gap
            assert kg is not None
            extra["key_gap_mm"] = (kg, req.gap_min, kg >= req.gap_min - tol)
            ratio = self.rod.hub_force_ratio
            extra["hub_force_ratio"] = (ratio, MAX_HUB_FORCE_RATIO, ratio <= MAX_HUB_FORCE_RATIO)
        if self.min_pin_gap is not None:
            extra["pin_gap_mm"] = (self.min_pin_gap, req.gap_min, self.min_pin_gap >= req.gap_min - tol)
        b_min = max(req.width_min, MIN_WIDTH_TO_THICKNESS * self.thickness)
        r_min = max(req.inner_radius_min, MIN_RADIUS_TO_THICKNESS * self.thickness)
        return {
            **extra,
            "stiffness_error": (k_err, STIFFNESS_TOLERANCE, k_err <= STIFFNESS_TOLERANCE),
            "stress_mpa": (self.max_stress, req.allowed_stress, self.max_stress <= req.allowed_stress * (1 + tol)),
            "min_wall_mm": (self.thickness, pr.min_wall_mm, self.thickness >= pr.min_wall_mm - tol),
            "thickness_steps": (steps, round(steps), abs(steps - round(steps)) < 1e-6),
            "coil_gap_mm": (self.min_coil_gap, req.gap_min, self.min_coil_gap >= req.gap_min - tol),
            "turns": (self.turns, req.min_turns, self.turns >= req.min_turns - tol),
            "width_min_mm": (self.width, b_min, self.width >= b_min - tol),
            "width_max_mm": (self.width, req.width_max, self.width <= req.width_max + tol),
            "inner_radius_min_mm": (self.inner_radius, r_min, self.inner_radius >= r_min - tol),
            "inner_radius_max_mm": (
                self.inner_radius,
                req.inner_radius_max,
                self.inner_radius <= req.inner_radius_max + tol,
            ),
            "outer_radius_mm": (
                self.outer_radius,
                req.outer_radius_max,
                self.outer_radius <= req.outer_radius_max + tol,
            ),
        }

    def to_dict(self) -> dict[str, Any]:
        """The keys of ``rjcad spring --json``: stiffnesses per joint unless the key says spring."""
        req = self.requirement
        rod = self.rod
        contact = rod.first_contact
        return {
            "width_mm": self.width,
            "thickness_mm": self.thickness,
            "length_mm": self.length,
            "inner_radius_mm": self.inner_radius,
            "pitch_mm": self.pitch,
            "turns": self.turns,
            "outer_radius_mm": self.outer_radius,
            "centreline_outer_radius_mm": self.centreline_outer_radius,
            "spring_stiffness_nmm_per_rad": self.spring_stiffness,
            "joint_stiffness_nmm_per_rad": self.joint_stiffness,
            "rod_stiffness_nmm_per_rad": self.joint_stiffness,
            "formula_stiffness_nmm_per_rad": req.springs * self.formula_stiffness,
            "max_stress_mpa": self.max_stress,
            "peak_stress_mpa": self.max_stress,
            "allowed_stress_mpa": req.allowed_stress,
            "preload_stress_mpa": self.preload_stress,
            "min_coil_gap_mm": self.min_coil_gap,
            "min_coil_gap_windup_deg": math.degrees(rod.min_gap_theta),
            "min_pin_gap_mm": self.min_pin_gap,
            "first_contact_deg": None if contact is None else math.degrees(contact),
            "print_coil_gap_mm": self.print_coil_gap,
            "pin_force_n": rod.pin_force,
            "preload_torque_nmm": req.springs * rod.torque_at(req.preload),
            "max_torque_nmm": req.springs * rod.torque_at(req.max_windup),
            "springs": req.springs,
            "min_gap_mm": req.gap_min,
            "material": req.material_spec.key,
            "printer": req.printer_spec.key,
            "end": req.end,
            "loading_sense": self.sense,
            "verified": True,
            "safety_factor": req.safety_factor,
            "rotation_deg": math.degrees(req.rotation),
            "preload_deg": math.degrees(req.preload),
            "requested_joint_stiffness_nmm_per_rad": req.joint_stiffness,
            "stress_amplitude_mpa": self.stress_amplitude,
            "backlash_mm": req.backlash,
            "min_cycles": req.min_cycles,
            **self._life_keys(),
            **self._arm_keys(),
        }

    def _arm_keys(self) -> dict[str, Any]:
        """Two arms only (one arm's keys are unchanged): the arms, each arm's pitch and the balance."""
        if self.arms == 1:
            return {}
        rod = self.rod
        return {
            "arms": self.arms,
            "arm_pitch_mm": self.arm_pitch,
            "hub_force_n": rod.hub_force,
            "arm_force_n": rod.arm_force,
            "hub_force_ratio": rod.hub_force_ratio,
            "min_key_gap_mm": self.min_key_gap,
        }

    def _life_keys(self) -> dict[str, Any]:
        if self.life is None:
            return {}
        med, lo, hi = self.predicted_life()
        return {"predicted_cycles": med, "predicted_cycles_interval": [lo, hi], "life_model": LIFE_NOTE}
