"""The support-free desktop layout of one joint module: every dimension, derived from the joint's parameters.

Everything prints from the bed up, with no surface over another body and no flat overhang:

- one spring (the whole joint stiffness) lies on the bed, winding COUNTER-CLOCKWISE outwards; its inner
  end is fused to the moving **hub** (radius r_h) that rises from the bed through the spring's middle;
  its outer end is a key, printed ``preload`` counter-clockwise of its socket, which two tines and a base
  hold on the inside of the ground **cup**; the user lifts the key out of the bed plane by the seat
  height + clearance, turns it clockwise by the preload (this unwinds the spiral; flexion unwinds it
  further) and lets it drop between the tines;
- the cup's wall (R_ci..R_co) rises from the bed and carries a **roof**, a cone rising inwards at
  ``CONE_ANGLE`` from the wall's top to a bore around the hub;
- under the roof the hub carries a **flare**, a cone rising outwards whose top runs parallel to the
  roof's underside at the clearance (measured along the cone's normal): it holds the moving body down;
  the bore (R_bore = R_band + c) lies FLARE_OVERLAP inside the flare's rim;
- above the roof the hub is the **band** with the tendon's V-groove, and an **arm** (|y| ≤ w_a)
  whose underside runs parallel to the roof's top at the clearance, down to the moving link's block:
  it holds the moving body up and carries it;
- two **lugs** on the roof (extension, flexion) stop the arm's sides; they end below the tendon;
- a full-height **web** joins the cup to the ground link's block at −X.

Cone surfaces face down at CONE_ANGLE from horizontal (steeper than 45°): nothing is a flat overhang.
Frame as the stacked layout: axis +Z, ground link −X, moving link +X, flexion positive about +Z.
Lengths in mm, angles in rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

#: Angle of every conical surface from horizontal [rad]: steeper than the overhang check's 45°, so that each
#: 0.2 mm layer steps out by 0.17 mm, inside the road under it (the slicer check's rule) with margin.
CONE_ANGLE = math.radians(50.0)
T = math.tan(CONE_ANGLE)
SEC = 1.0 / math.cos(CONE_ANGLE)


def clear_of_ground_block(x_m: float, x_g: float, wg: float, wm: float, theta: float, c: float) -> float:
    """The moving block's start x_m [mm], raised if needed so that its corner (x_m, wm), turned by up to ``theta``
    [rad], never enters the ground block (x <= -x_g, |y| <= wg) within c + 0.5 mm: once the corner is past the
    block's face (x_m·cos θ − wm·sin θ < −x_g + c + 0.5) it must stay above it, x_m·sin θ + wm·cos θ ≥ wg + c + 0.5."""
    margin = c + 0.5
    if math.sin(theta) > 1e-9 and x_m * math.cos(theta) - wm * math.sin(theta) < -x_g + margin:
        return max(x_m, (wg + margin - wm * math.cos(theta)) / math.sin(theta))
    return x_m


#: Roof thickness, normal to the cone, at least [mm]; thicker on a printer whose walls must be (``roof``).
ROOF_NORMAL = 1.2
#: The roof is at least this much thicker than the printer's thinnest wall, so that its faceted cone still
#: measures a wall (at 0.4 mm nozzles: 0.8 + 0.3 < ROOF_NORMAL) [mm].
ROOF_WALL_MARGIN = 0.3
#: Flat land at the roof's bore, so that the roof's top does not end in a knife edge [mm].
ROOF_LAND = 0.8
#: How far the flare reaches under the roof's bore edge [mm].
FLARE_OVERLAP = 0.8
#: Added to the clearance between facing cones and at the bore: two tessellated curved faces facing each
#: other can each come a chord's sagitta closer than modelled [mm].
FACET_MARGIN = 0.05
#: Width of a stop lug, and its least length along its ray [mm].
LUG_WIDTH = 2.0
#: A stop lug starts this far outside the roof's bore, and its outer corner ends this far inside the cup's
#: outer radius [mm].
LUG_INSET = 0.5, 0.1
#: Ray of the seated key's socket on the ground cup [rad] (towards the ground link).
SOCKET_RAY = math.pi


class _Strip(Protocol):
    @property
    def width(self) -> float: ...


class _Walls(Protocol):
    @property
    def min_wall_mm(self) -> float: ...


class JointLike(Protocol):
    """What the layout reads of a joint's parameters: JointParams, described here (importing it is a cycle)."""

    @property
    def spring(self) -> _Strip: ...
    @property
    def printer_spec(self) -> _Walls: ...
    @property
    def clearance_mm(self) -> float: ...
    @property
    def pin_radius(self) -> float: ...
    @property
    def tendon_diameter(self) -> float: ...
    @property
    def tendon_line_diameter(self) -> float: ...
    @property
    def eye_radius(self) -> float: ...
    @property
    def moment_arm(self) -> float: ...
    @property
    def key_tip_radius(self) -> float: ...
    @property
    def key_width(self) -> float: ...
    @property
    def wound_radius(self) -> float: ...
    @property
    def gap_internal(self) -> float: ...
    @property
    def gap_z(self) -> float: ...
    @property
    def link_width(self) -> float: ...
    @property
    def ground_block_half_width(self) -> float: ...
    @property
    def moving_block_half_width(self) -> float: ...
    @property
    def rotation(self) -> float: ...


@dataclass(frozen=True)
class DesktopLayout:
    """The desktop layout's dimensions (see the module docstring); build with :meth:`of`."""

    c: float  # clearance, normal to every pair of facing surfaces
    b: float  # spring width (height on the bed)
    r_h: float  # hub radius through the spring
    seat: float  # tine height (from the bed); the key lifts by seat + c
    R_ci: float  # cup inner radius
    R_co: float  # cup outer radius
    R_band: float  # band radius (tendon groove's rim), also the hub's radius in the roof's bore
    R_bore: float  # roof's bore radius
    R_flare: float  # flare's outer radius
    z_w0: float  # roof underside at the cup wall
    z_t: float  # tendon centreline height
    z_band: tuple[float, float]  # tendon band (groove zone)
    height: float  # module height H
    w_arm: float  # arm half-width
    X_m: float  # moving block start
    X_g: float  # ground block start
    w_web: float  # web half-width
    groove_half: float  # groove's flat bottom half-height
    groove_depth: float
    roof: float = ROOF_NORMAL  # roof thickness normal to the cone: max(ROOF_NORMAL, min wall + ROOF_WALL_MARGIN)

    @classmethod
    def of(cls, p: JointLike) -> DesktopLayout:
        """Derive the layout from a joint's parameters ``p`` (a :class:`rjcad.design.params.JointParams`)."""
        d = p.spring
        c, b = p.clearance_mm, d.width
        cz = (c + FACET_MARGIN) * SEC
        seat = min(b, max(1.5, min(2.0, 0.3 * b)))
        r_h = p.pin_radius
        groove_half = p.tendon_line_diameter / 2 + 0.1
        R_band = p.eye_radius + p.tendon_line_diameter + 0.5
        depth = R_band - p.eye_radius
        R_bore = R_band + c + FACET_MARGIN
        R_f = R_bore + FLARE_OVERLAP
        w_arm = min(4.5, p.moment_arm - p.tendon_diameter / 2 - 0.4)
        wall = 2.0 * p.printer_spec.min_wall_mm
        roof = max(ROOF_NORMAL, p.printer_spec.min_wall_mm + ROOF_WALL_MARGIN)
        # the cup holds the key and the wound spring, clears the flare's rim, and its roof holds the stop lugs
        # (LUG_WIDTH square at least, beside the arm at the clearance; see lug_span)
        lug_corner = math.hypot(R_bore + LUG_INSET[0] + LUG_WIDTH, w_arm + c + LUG_WIDTH) + LUG_INSET[1]
        R_ci = max(
            math.hypot(p.key_tip_radius, p.key_width) + c + 0.1,
            p.wound_radius + p.gap_internal,
            R_f + c + FACET_MARGIN,
            lug_corner - wall,
        )
        R_co = R_ci + wall
        # roof underside z_ru(r) = z_w0 + (R_ci − r)·T; flare top = z_ru − cz; the flare leaves the hub
        # (r_h) at b + gap_z: z_w0 + (R_ci − R_f)·T − cz − (R_f − r_h)·T ≥ b + gap_z
        gz = p.gap_z
        z_w0 = max(
            b + seat + c + 0.2,  # the lifted key passes under the roof
            b + cz + gz + 2 * T * R_f - (R_ci + r_h) * T,
        )  # the flare clears the spring
        roof_top_bore = z_w0 + (R_ci - R_bore) * T + roof * SEC
        flank = depth * T
        # the arm's cone at the band's radius (raised by tendon_lift: a finger's joints share one tendon plane)
        z_step = roof_top_bore + cz + (R_bore - R_band) * T + getattr(p, "tendon_lift", 0.0)
        z_t = z_step + flank + groove_half + 0.3
        half = groove_half + flank + 0.3
        height = z_t + half + 1.0
        W = p.link_width
        theta_m = p.rotation + math.radians(5.0)
        X_g = R_co + 1.0
        wg, wm = p.ground_block_half_width, p.moving_block_half_width
        X_m = max(R_co + c + 0.6, -X_g * math.cos(theta_m) + wg * math.sin(theta_m) + c + 0.5)
        X_m = clear_of_ground_block(X_m, X_g, wg, wm, theta_m, c)
        # the web ends in the plane x = −(R_ci + 0.3), inside the wall at its corners, and stays clear of
        # the tendon (y = r): no knife edge, no channel through it
        w_web = min(W / 2, math.sqrt((R_co - 0.4) ** 2 - (R_ci + 0.3) ** 2), p.moment_arm - p.tendon_diameter / 2 - 0.6)
        if theta_m > math.pi / 2:
            w_web = min(w_web, (X_m - c - 0.3 + (R_co - 0.5) * math.cos(theta_m)) / math.sin(theta_m))
        return cls(
            c=c,
            b=b,
            r_h=r_h,
            seat=seat,
            R_ci=R_ci,
            R_co=R_co,
            R_band=R_band,
            R_bore=R_bore,
            R_flare=R_f,
            z_w0=z_w0,
            z_t=z_t,
            z_band=(z_step, z_t + half),
            height=height,
            w_arm=w_arm,
            X_m=X_m,
            X_g=X_g,
            w_web=w_web,
            groove_half=groove_half,
            groove_depth=depth,
            roof=roof,
        )

    # --- cone surfaces, z of r -------------------------------------------------
    @property
    def cz(self) -> float:
        """Vertical offset between parallel cones a normal clearance c (+ FACET_MARGIN) apart, c/cos α [mm]."""
        return (self.c + FACET_MARGIN) * SEC

    def roof_under(self, r: float) -> float:
        """Roof underside, rising inwards from the wall's top [mm]."""
        return self.z_w0 + (self.R_ci - r) * T

    def roof_top(self, r: float) -> float:
        return self.roof_under(r) + self.roof * SEC

    def arm_under(self, r: float) -> float:
        """The arm's underside: the roof's top plus the clearance, continued outwards [mm]."""
        return self.roof_top(r) + self.cz

    def flare_top(self, r: float) -> float:
        return self.roof_under(r) - self.cz

    @property
    def flare_bottom(self) -> float:
        """Height where the flare leaves the hub (r = r_h) [mm]."""
        return self.flare_top(self.R_flare) - (self.R_flare - self.r_h) * T

    @property
    def lug_span(self) -> tuple[float, float, float]:
        """(x0, x1, y0) of a stop lug along its ray: from LUG_INSET[0] outside the bore to where its outer corner
        (y0 + LUG_WIDTH off the ray) comes LUG_INSET[1] inside the cup's outer radius; its inner side y0 is the
        arm's side plus the clearance [mm]."""
        y0 = self.w_arm + self.c
        x1 = math.sqrt((self.R_co - LUG_INSET[1]) ** 2 - (y0 + LUG_WIDTH) ** 2)
        return self.R_bore + LUG_INSET[0], x1, y0

    @property
    def lug_top(self) -> float:
        """Stop lugs end below the tendon [mm]."""
        return self.z_t - self.groove_half - 0.7

    def summary(self) -> dict[str, Any]:
        """Manifest keys of the layout [mm, deg]."""
        return {
            "layout": "desktop",
            "cone_angle_deg": math.degrees(CONE_ANGLE),
            "clearance_normal_mm": self.c,
            "hub_radius_mm": self.r_h,
            "cup_inner_radius_mm": self.R_ci,
            "cup_outer_radius_mm": self.R_co,
            "band_radius_mm": self.R_band,
            "bore_radius_mm": self.R_bore,
            "flare_radius_mm": self.R_flare,
            "roof_wall_z_mm": self.z_w0,
            "tendon_z_mm": self.z_t,
            "height_mm": self.height,
            "arm_half_width_mm": self.w_arm,
            "seat_height_mm": self.seat,
            "socket_ray_deg": math.degrees(SOCKET_RAY),
        }
