"""Validated, frozen parameters of one joint module (no CAD kernel: physics reads them too), and the layout derived from them.

Coordinates: the joint axis is +Z through the origin; the ground link runs to
−X, the moving link to +X; positive rotation about +Z is flexion (towards +Y).
The module prints with Z up, springs flat, in this stack (bottom to top):

    spring 1 | gap | cheek 1 | gap | eye | gap | cheek 2 | gap | spring 2

Each spring is printed winding CLOCKWISE outwards (seen from +Z), its outer end ``preload``
clockwise of where the moving link holds it: the user turns that end counter-clockwise (the
flexion sense) by the preload and seats it, and flexion turns it further the same way, so the
joint UNWINDS its springs. The end fitting follows the spring design's ``end``: ``clamped`` (a
rigid key seated in a socket of two tines and a base, which holds the end's position and angle)
or ``pinned`` (a closed ring around a round post, free to turn). Both seat axially: the socket and
the post reach only ``seat_height`` into the spring's layer from the joint's middle, and the user
pushes the key (or ring) out of the spring's plane by ``seat_height + clearance`` to pass them.

All lengths in mm, angles in rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

from rjcad import DEG
from rjcad.design.envelope import WoundEnvelope, wound_envelope
from rjcad.design.layout_desktop import DesktopLayout, clear_of_ground_block
from rjcad.errors import ParameterError
from rjcad.materials import (
    DEFAULT_MATERIAL,
    DEFAULT_PRINTER,
    REFERENCE_NOZZLE_MM,
    Material,
    Printer,
    get_material,
    get_printer,
)
from rjcad.spring import DEFAULT_END, SpringDesign, SpringRequirement
from rjcad.spring.optimise import design_spring
from rjcad.validate import in_range

#: Validated ranges: name → (low, high, unit shown in errors). Angles in rad.
RANGES: dict[str, tuple[float | None, float, str]] = {
    "stiffness": (0.2, 60.0, "N·mm/rad"),
    "rotation": (15 * DEG, 110 * DEG, "deg"),
    "preload": (30 * DEG, 120 * DEG, "deg"),
    "clearance": (0.15, 0.6, "mm"),
    "link_length": (None, 150.0, "mm"),  # lower bound depends on the spring
    "tendon_diameter": (0.5, 2.0, "mm"),
    "tendon_moment_arm": (None, 15.0, "mm"),  # lower bound depends on the pin
    "pin_radius": (1.25, 5.0, "mm"),
    "safety_factor": (1.0, 5.0, ""),
}


#: The joint's default outer end: the spring designer's (clamped: the paper's measured stiffness says its hooks
#: behaved clamped; issue #14).
JOINT_DEFAULT_END = DEFAULT_END
#: Radial length over which a clamped end's key engages the tines of its socket [mm].
KEY_ENGAGEMENT = 3.5
#: Strip length buried in each end fitting (tab at the pin, key or stub outside), so that the free
#: strip between the fittings has the design's length [mm].
STRIP_OVERLAP = 0.3
#: Margin on the wound strip's extent for the rod model's discretisation and sampling [mm].
WOUND_MARGIN = 0.1


LAYOUTS = ("desktop", "stacked")
#: Clearance of the stacked layout (the paper's printer holds it) [mm].
STACKED_CLEARANCE = 0.25


def default_layout(printer: str) -> str:
    """The layout when none is asked for: ``stacked`` (the paper's) on a printer with soluble support, else
    ``desktop`` (support-free)."""
    return "stacked" if get_printer(printer).soluble_support else "desktop"


def default_clearance(material: str, printer: str, layout: str) -> float:
    """The clearance a layout uses when none is given: the print-in-place clearance of the material on the
    printer (``Printer.desktop_clearance``: scaled with the nozzle) on a printer without soluble support in the
    desktop layout, else 0.25 mm [mm]."""
    prn = get_printer(printer)
    if layout == "desktop" and not prn.soluble_support:
        return prn.desktop_clearance(get_material(material))
    return STACKED_CLEARANCE


def _check(name: str, value: object, lo: float | None, hi: float | None, unit: str) -> None:
    """``value`` within [lo, hi] (to 1e-12; shown in degrees when ``unit`` is "deg"), else ParameterError."""
    in_range(name, value, lo, hi, unit=unit, deg=unit == "deg", tol=1e-12, not_a_number="must be a number")


@dataclass(frozen=True)
class JointParams:
    """Inputs of one joint module (validated on construction; angles in rad).

    ``stiffness`` is the joint stiffness, both springs together (N·mm/rad).
    ``tendon_moment_arm`` is the tendon's distance from the joint axis where it
    wraps the eye; ``None`` means 6 mm.
    """

    stiffness: float = 5.2
    rotation: float = 90 * DEG
    preload: float = 90 * DEG
    material: str = DEFAULT_MATERIAL
    printer: str = DEFAULT_PRINTER
    clearance: float | None = None
    link_length: float = 40.0
    tendon_diameter: float = 1.0
    tendon_moment_arm: float | None = None
    pin_radius: float = 2.0
    safety_factor: float = 1.5
    end: str = JOINT_DEFAULT_END
    #: ``desktop`` (support-free: one spring on the bed under nested cones; rjcad.design.layout_desktop) or ``stacked``
    #: (the paper's: two springs beside the knuckle, needs soluble support); None: :func:`default_layout`.
    layout: str | None = None
    # fixed proportions (not user inputs, but kept here so that everything derives from one object)
    cheek_thickness: float = field(default=2.0, repr=False)
    #: desktop: the tendon plane raised by this much, so that a finger's joints share one plane [mm]
    tendon_lift: float = field(default=0.0, repr=False)
    post_radius: float = field(default=1.2, repr=False)
    tendon_line_diameter: float = field(default=0.6, repr=False)
    support_pin_radius: float = field(default=0.9, repr=False)
    #: a joint module printed on its own (two links long, checked against the bed here); False for a joint of a
    #: finger, whose whole length FingerParams checks
    standalone: bool = field(default=True, repr=False)
    #: a finger's link blocks are as wide as the wider of the two joints they join: the half-widths of the
    #: ground (parent) and moving (child) link blocks at this joint [mm]; None: this joint's own (link_width/2)
    ground_half_width: float | None = field(default=None, repr=False)
    moving_half_width: float | None = field(default=None, repr=False)
    #: desktop: the spring's arms, 1 or 2 interleaved arms 180° apart (each half the torque, each with its own key
    #: and socket, the second turned by 180° about the axis: their forces on the hub cancel)
    arms: int = 1

    def __post_init__(self) -> None:
        if self.layout is None:
            object.__setattr__(self, "layout", default_layout(self.printer))
        if self.layout not in LAYOUTS:
            raise ParameterError("layout", self.layout, f"known layouts: {', '.join(LAYOUTS)}")
        if self.clearance is None:
            object.__setattr__(self, "clearance", default_clearance(self.material, self.printer, self.layout))
        if self.arms not in (1, 2) or isinstance(self.arms, bool):
            raise ParameterError("arms", self.arms, "must be 1 or 2 spring arms")
        if self.arms == 2 and self.layout != "desktop":
            raise ParameterError("arms", self.arms, "two spring arms are built in the desktop layout only")
        if self.layout == "desktop" and self.end != "clamped":
            raise ParameterError(
                "end",
                self.end,
                "the desktop layout holds the spring's outer end clamped "
                "(key in a socket); use layout stacked for a pinned end",
            )
        for name, (lo, hi, unit) in RANGES.items():
            value = getattr(self, name)
            if name == "tendon_moment_arm" and value is None:
                continue
            if name == "clearance":  # a wider nozzle needs, and gets, wider clearances (Printer.desktop_clearance)
                hi *= max(1.0, get_printer(self.printer).nozzle_mm / REFERENCE_NOZZLE_MM)
            _check(name, value, lo, hi, unit)
        object.__setattr__(self, "material", get_material(self.material).ref)
        object.__setattr__(self, "printer", get_printer(self.printer).ref)
        self.printer_spec.check_gap("clearance", self.clearance)
        if self.tendon_line_diameter >= self.tendon_diameter:
            raise ParameterError(
                "tendon_diameter",
                self.tendon_diameter,
                f"must be larger than the tendon line ({self.tendon_line_diameter} mm)",
            )
        # geometry-dependent limits (these build the spring design: one optimiser call)
        lo_arm = self.pin_radius + self.clearance_mm + 2 * self.printer_spec.min_wall_mm + self.tendon_line_diameter / 2
        _check("tendon_moment_arm", self.moment_arm, lo_arm, RANGES["tendon_moment_arm"][1], "mm")
        lo_len = max(self.block_start + self.slot_length + 4.0, self.ground_block_start + 8.0)
        _check("link_length", self.link_length, lo_len, RANGES["link_length"][1], "mm")
        if self.standalone:  # the joint lies on the bed, two links long
            half = self.printer_spec.bed_length / 2
            in_range(
                "link_length",
                self.link_length,
                hi=half,
                unit="mm",
                tol=1e-12,
                limit=f"must be <= {half:g} mm on {self.printer_spec.key}: the joint, two links long, must fit its bed",
            )
        tall = self.printer_spec.build_volume_mm[2]
        if self.height > tall + 1e-9:  # a finger's joints are as tall as the joint
            raise ParameterError(
                "printer",
                self.printer_spec.key,
                f"its build height, {tall:g} mm, is under the joint's {self.height:.1f} mm: choose a taller printer",
            )
        in_range(
            "preload",
            self.preload,
            self.min_preload,
            deg=True,
            tol=1e-12,
            limit=f"must be >= {math.degrees(self.min_preload):.1f} deg for this spring: its printed outer "
            "end must clear its socket (or post) by the clearance",
        )
        if self.arms == 2:
            self._check_key_gap()

    def _check_key_gap(self) -> None:
        """Two arms: each arm keeps the coil gap to the other arm's key (this layout's key) over the wind-up, by the
        rod model; else ParameterError naming ``arms``."""
        d = self.spring
        gap = self.key_gap
        if gap < d.requirement.gap_min - 1e-9:
            raise ParameterError(
                "arms",
                self.arms,
                f"the other arm comes {gap:.3f} mm from a key (< {d.requirement.gap_min:g} mm) over the wind-up: "
                "use one arm",
            )

    @property
    def key_gap(self) -> float:
        """Two arms: the smallest gap between an arm and the other arm's key over 0..preload + rotation, by the
        rod model with this layout's key (root 0.25·t inside the end, tip at ``key_tip_radius``) [mm]."""
        from rjcad.spring.verify import rod_check

        d, req = self.spring, self.spring.requirement
        key = (-0.25 * d.thickness, self.key_tip_radius - d.centreline_outer_radius, self.key_width)
        check = rod_check(
            d.inner_radius,
            d.pitch,
            d.turns,
            d.width,
            d.thickness,
            d.youngs_modulus,
            d.end,
            d.sense,
            req.preload,
            req.rotation,
            req.pin_radius,
            arms=2,
            key=key,
        )
        assert check.min_key_gap is not None
        return check.min_key_gap

    # --- printer, spring -------------------------------------------------------
    @property
    def printer_spec(self) -> Printer:
        return get_printer(self.printer)

    @property
    def material_spec(self) -> Material:
        return get_material(self.material)

    @property
    def clearance_mm(self) -> float:
        """The clearance as resolved on construction (``clearance`` is never None after it) [mm]."""
        assert self.clearance is not None  # __post_init__ sets the default
        return self.clearance

    @property
    def gap_xy(self) -> float:
        """Radial (XY) gap between the bodies: the clearance [mm]."""
        return self.clearance_mm

    @property
    def gap_z(self) -> float:
        """Axial (Z) gap between stacked parts: max(clearance, printer's vertical minimum) [mm]."""
        return max(self.clearance_mm, self.printer_spec.min_gap_vertical_mm)

    @property
    def gap_internal(self) -> float:
        """Gap kept inside the ground body (spring to its own parts): printer minimum gap [mm]."""
        return max(self.printer_spec.min_gap_mm, self.clearance_mm)

    @property
    def springs(self) -> int:
        """Springs in the joint: one on the bed (desktop), one each side (stacked)."""
        return 1 if self.layout == "desktop" else 2

    @property
    def coil_gap_min(self) -> float | None:
        """The gap the coils keep over the whole wind-up: the clearance (desktop), else the printer's [mm]."""
        return max(self.clearance_mm, self.printer_spec.min_gap_mm) if self.layout == "desktop" else None

    @cached_property
    def desktop(self) -> DesktopLayout:
        """The desktop layout's dimensions (meaningful when ``layout`` is desktop)."""
        return DesktopLayout.of(self)

    @cached_property
    def spring(self) -> SpringDesign:
        """The spring design: each of the twin springs (K_joint/2 each, stacked) or the one spring (desktop)."""
        # innermost strip edge must clear the pin: r_in − t/2 − r_pin ≥ internal gap
        t_max = 1.2
        r_min = max(3.0, self.pin_radius + self.gap_internal + t_max / 2)
        req = SpringRequirement(
            joint_stiffness=self.stiffness,
            rotation=self.rotation,
            preload=self.preload,
            material=self.material,
            printer=self.printer,
            safety_factor=self.safety_factor,
            end=self.end,
            inner_radius_min=r_min,
            inner_radius_max=max(10.0, r_min),
            springs=self.springs,
            min_gap=self.coil_gap_min,
            arms=self.arms,
        )
        d = design_spring(req)
        if d.inner_radius - d.thickness / 2 - self.pin_radius < self.gap_internal - 1e-9:
            req = SpringRequirement(
                **{**req.__dict__, "inner_radius_min": self.pin_radius + self.gap_internal + d.thickness / 2}
            )
            d = design_spring(req)
        return d

    # --- Z layout --------------------------------------------------------------
    @property
    def spring_width(self) -> float:
        return self.spring.width

    @property
    def eye_thickness(self) -> float:
        """Eye band height: the tendon groove plus a 1 mm flange each side [mm]."""
        return max(4.0, self.tendon_diameter + 3.0)

    @property
    def z_cheek1(self) -> tuple[float, float]:
        z0 = self.spring_width + self.gap_z
        return (z0, z0 + self.cheek_thickness)

    @property
    def z_eye(self) -> tuple[float, float]:
        if self.layout == "desktop":
            return self.desktop.z_band
        z0 = self.z_cheek1[1] + self.gap_z
        return (z0, z0 + self.eye_thickness)

    @property
    def z_cheek2(self) -> tuple[float, float]:
        z0 = self.z_eye[1] + self.gap_z
        return (z0, z0 + self.cheek_thickness)

    @property
    def z_spring1(self) -> tuple[float, float]:
        return (0.0, self.spring_width)

    @property
    def z_spring2(self) -> tuple[float, float]:
        z0 = self.z_cheek2[1] + self.gap_z
        return (z0, z0 + self.spring_width)

    @property
    def height(self) -> float:
        """Total height of the module along the joint axis [mm]."""
        return self.desktop.height if self.layout == "desktop" else self.z_spring2[1]

    @property
    def z_mid(self) -> float:
        """Height of the tendon's plane [mm]."""
        return self.desktop.z_t if self.layout == "desktop" else 0.5 * sum(self.z_eye)

    # --- radial layout ---------------------------------------------------------
    @property
    def moment_arm(self) -> float:
        """Design tendon moment arm r (the tendon centreline's distance from the axis) [mm]."""
        return 6.0 if self.tendon_moment_arm is None else float(self.tendon_moment_arm)

    @property
    def eye_radius(self) -> float:
        """Groove bottom of the tendon path on the eye, r − line diameter/2 [mm]."""
        return self.moment_arm - self.tendon_line_diameter / 2

    @property
    def hook_wall(self) -> float:
        """Wall of the pinned end's ring [mm]."""
        return max(self.spring.thickness, self.printer_spec.min_wall_mm)

    # --- the springs' outer ends (see the module docstring) ----------------------
    @property
    def end_condition(self) -> str:
        """The outer end the spring was designed for, which the builder realises: clamped or pinned."""
        return self.spring.end

    @cached_property
    def wound(self) -> WoundEnvelope:
        """The strip's centreline over the wind-up 0..preload + rotation, ground and moving frames (rod model)."""
        d = self.spring
        if self.arms == 1:
            return wound_envelope(
                d.inner_radius, d.pitch, d.turns, d.thickness, self.preload, self.rotation, self.end_condition
            )
        return wound_envelope(
            d.inner_radius, d.arm_pitch, d.turns, d.thickness, self.preload, self.rotation, self.end_condition, 2
        )

    @property
    def wound_radius(self) -> float:
        """Outer radius of a spring's strip over the whole wind-up, any direction [mm]."""
        d = self.spring
        return max(self.wound.r_max + WOUND_MARGIN, d.centreline_outer_radius) + d.thickness / 2

    @property
    def fitting_clear_radius(self) -> float:
        """Radius the socket (or ring) must stay outside of: the wound strip's surface near the end's ray,
        over ±(socket's half-span + 1 mm) in the moving frame, plus the internal gap [mm]."""
        d = self.spring
        reach = max(map(abs, self.socket_span)) + 1.0
        window = math.atan2(reach, d.outer_radius)
        r = max(self.wound.radius_within(-window, window) + WOUND_MARGIN, d.centreline_outer_radius)
        return r + d.thickness / 2 + self.gap_internal

    @property
    def seat_height(self) -> float:
        """How far the socket (or post) reaches into a spring's layer from the joint's middle, h_s [mm]."""
        if self.layout == "desktop":
            return self.desktop.seat
        b = self.spring.width
        return min(b, max(1.5, 0.5 * b))

    @property
    def key_root_radius(self) -> float:
        """Inner face of the clamped key (or the pinned stub): 0.25·t inside the strip's outer-end centreline [mm]."""
        return self.spring.centreline_outer_radius - 0.25 * self.spring.thickness

    @property
    def key_width(self) -> float:
        """Tangential width of the clamped key, w_k; it lies clockwise of the strip's end ray [mm]."""
        return 2.0 * max(self.spring.thickness, self.printer_spec.min_wall_mm)

    @property
    def tine_width(self) -> float:
        """Thickness of each tine of the clamped end's socket, w_t [mm]."""
        return max(2.0, 2.0 * self.printer_spec.min_wall_mm)

    @property
    def socket_tilt(self) -> float:
        """Tilt α of the socket's tines, counter-clockwise, from ℓ·sin α + w_k·cos α = w_k + 2c [rad].

        The slot is w_k + 2c wide; the spring's moment turns the seated key clockwise in it by α
        (its rotational play, ≈ 2c/ℓ) until it bears on both tines. Tilting the tines by α puts the
        bearing key exactly at its modelled pose: the printed pose turned by the preload.
        """
        w, c, L = self.key_width, self.clearance_mm, KEY_ENGAGEMENT
        h = math.hypot(L, w)
        return math.asin((w + 2 * c) / h) - math.atan2(w, L)

    @property
    def socket_inner_radius(self) -> float:
        """Where the tines begin, R_s0: clear of the wound strip, with the tine's slant [mm]."""
        return self.fitting_clear_radius + self.tine_width * math.sin(self.socket_tilt)

    @property
    def key_tip_radius(self) -> float:
        """Outer end of the clamped key, R_k = R_s0 + ℓ; it bears on the socket's base there [mm]."""
        return self.socket_inner_radius + KEY_ENGAGEMENT

    @property
    def socket_base_depth(self) -> float:
        """Radial depth of the socket's base, which holds the post clear of its faces [mm]."""
        return 2 * self.post_radius + 0.4

    @property
    def socket_span(self) -> tuple[float, float]:
        """(v_lo, v_hi): tangential extent of the socket's base (the ring, pinned) around its post's ray [mm]."""
        if self.end_condition != "clamped":
            hw = self.post_radius + self.clearance_mm + self.hook_wall
            return (-hw, hw)
        a, wt = self.socket_tilt, self.tine_width
        reach = KEY_ENGAGEMENT + self.socket_base_depth / 2
        return (-self.key_width - wt / math.cos(a), reach * math.tan(a) + wt / math.cos(a))

    def socket_corners(self) -> list[tuple[float, float]]:
        """Corners (u, v) of the clamped socket's tines and its base's face, at rest (u along +X) [mm]."""
        a, wt, L = self.socket_tilt, self.tine_width, KEY_ENGAGEMENT
        R0, Rk, depth = self.socket_inner_radius, self.key_tip_radius, self.socket_base_depth
        ca, sa = math.cos(a), math.sin(a)

        def box(u0: float, v0: float, s: tuple[float, float], q: tuple[float, float]) -> list[tuple[float, float]]:
            return [(u0 + si * ca - qi * sa, v0 + si * sa + qi * ca) for si in s for qi in q]

        v_lo, v_hi = self.socket_span
        return (
            box(R0, 0.0, (0.0, (Rk + depth / 2 - R0) / ca), (0.0, wt))
            + box(Rk, -self.key_width, (-L / ca, depth / 2 / ca), (-wt, 0.0))
            + [(Rk, v_lo), (Rk, v_hi)]
        )

    @property
    def min_preload(self) -> float:
        """Smallest preload whose printed key (or ring) clears its socket (or post) by the clearance + 0.05 [rad].

        Clamped: the key lies clockwise of the ray at −preload; a socket corner at radius r and polar
        angle ψ is r·sin(preload + ψ) from that ray. Pinned: ring and post centres 2·R_h·sin(preload/2) apart.
        """
        c = self.clearance_mm + 0.05
        if self.end_condition == "clamped":
            return max(math.asin(min(1.0, c / math.hypot(u, v))) - math.atan2(v, u) for u, v in self.socket_corners())
        reach = 2 * self.post_radius + self.clearance_mm + self.hook_wall + c
        return 2 * math.asin(min(1.0, reach / (2 * self.post_ring_radius)))

    @property
    def post_ring_radius(self) -> float:
        """Radius of the posts, R_h [mm]: behind the key's tip (clamped) or inside the ring (pinned)."""
        rho = self.post_radius
        if self.end_condition == "clamped":
            return self.key_tip_radius + rho + 0.2
        return self.fitting_clear_radius + self.hook_wall + self.clearance_mm + rho

    @property
    def hook_outer_radius(self) -> float:
        """Outermost radius of the end fittings and sockets around the axis [mm]."""
        if self.end_condition == "clamped":
            return math.hypot(self.key_tip_radius + self.socket_base_depth, max(map(abs, self.socket_span)))
        return self.post_ring_radius + self.post_radius + self.clearance_mm + self.hook_wall

    @property
    def fitting_half_width(self) -> float:
        """Largest tangential distance of the printed key or ring from its ray [mm]."""
        if self.end_condition == "clamped":
            return self.key_width
        return self.post_radius + self.clearance_mm + self.hook_wall

    @property
    def fitting_outer_radius(self) -> float:
        """Outer radius of the printed key (clamped) or ring (pinned) [mm]."""
        return self.key_tip_radius if self.end_condition == "clamped" else self.hook_outer_radius

    @property
    def cheek_radius(self) -> float:
        """Cheek disc radius: clears the posts' path by the clearance plus 0.1 mm [mm]."""
        return self.post_ring_radius - self.post_radius - self.clearance_mm - 0.1

    @property
    def cheek_plate_half_width(self) -> float:
        """Half-width of the plates joining each cheek to the fork block [mm].

        Past 90° of flexion the posts sweep over x < 0; the plate stays inside the
        posts' path there: w ≤ (R_h − ρ − c − 0.2)·sin(π − rotation − 2·stop angle − 2°).
        """
        free = math.pi - self.rotation - 2 * self.stop_angle - 2 * DEG
        inner = self.post_ring_radius - self.post_radius - self.clearance_mm - 0.2
        # ≤ 0.7·r_cheek: the plate's side crosses the cheek's circle at ≥ 45°, leaving no thin crescent
        w = 0.7 * self.cheek_radius
        return min(w, inner * math.sin(free)) if free < math.pi / 2 else w

    @property
    def ground_block_start(self) -> float:
        """|x| where the ground link's full-height block begins, X_g [mm].

        It must clear: the wound springs (their leftmost reach over the whole wind-up,
        plus g); the keys or rings in print, at −preload; the posts swept to rotation +
        stop angle and the sockets to the rotation; the eye-band beam of the moving link,
        whose edge y' = R_e passes the block's corner (−X_g, W/2) unless
        X_g·sin θ + (W/2)·cos θ ≥ R_e + c for θ up to the rotation.
        """
        if self.layout == "desktop":
            return self.desktop.X_g
        g, c = self.gap_internal, self.clearance_mm
        R_h, rho = self.post_ring_radius, self.post_radius
        bounds = [
            -self.wound.ground_x_min + self.spring.thickness / 2 + WOUND_MARGIN + g,
            -self.fitting_outer_radius * math.cos(self.preload) + self.fitting_half_width + g,
            -R_h * math.cos(self.rotation + self.stop_angle) + rho + c + 0.3,
            -self.hook_outer_radius * math.cos(self.rotation) + max(map(abs, self.socket_span)) + c + 0.3,
            self.eye_radius + 0.6 + c + 0.3,
        ]
        if self.rotation > math.pi / 2:
            bounds.append(
                (self.eye_radius + c + 0.3 - self.link_width / 2 * math.cos(self.rotation)) / math.sin(self.rotation)
            )
        return max(bounds)

    @property
    def block_start(self) -> float:
        """|x| where the moving link's full-height block begins, X_m [mm].

        Outside the seated keys (or rings) and their sockets and the wound strip, and far enough out that
        the ground block's corner (−X_g, W/2) never enters it: −X_g·cos θ + (W/2)·sin θ ≤ X_m − c − 0.5
        up to the rotation.
        """
        if self.layout == "desktop":
            return self.desktop.X_m
        corner = (
            -self.ground_block_start * math.cos(self.rotation)
            + self.ground_block_half_width * math.sin(self.rotation)
            + self.clearance_mm
            + 0.5
        )
        wound = self.wound.moving_x_max + self.spring.thickness / 2 + WOUND_MARGIN + self.gap_internal
        x_m = max(self.hook_outer_radius + self.clearance_mm + 0.3, corner, wound)
        return clear_of_ground_block(
            x_m,
            self.ground_block_start,
            self.ground_block_half_width,
            self.moving_block_half_width,
            self.rotation,
            self.clearance_mm,
        )

    @property
    def ground_block_half_width(self) -> float:
        """Half-width of the ground (parent) link block at this joint [mm]."""
        return self.link_width / 2 if self.ground_half_width is None else self.ground_half_width

    @property
    def moving_block_half_width(self) -> float:
        """Half-width of the moving (child) link block at this joint [mm]."""
        return self.link_width / 2 if self.moving_half_width is None else self.moving_half_width

    @property
    def link_width(self) -> float:
        """Link width along Y [mm]."""
        return 2.0 * (self.moment_arm + self.tendon_diameter / 2 + 2 * self.support_pin_radius + 1.0)

    @property
    def slot_length(self) -> float:
        return 2 * self.support_pin_radius + 3.0

    @property
    def stop_angle(self) -> float:
        """Angle between the post's centre line and a stop face at clearance, asin((ρ+c)/R_h) [rad]."""
        return math.asin((self.post_radius + self.clearance_mm) / self.post_ring_radius)
