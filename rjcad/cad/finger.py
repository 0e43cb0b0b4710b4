"""A single-tendon finger: N joint modules chained, each link one printed body.

Link i (between joints i and i+1) is the moving side of joint i fused with the
ground side (fork) of joint i+1, placed at x = Σ link lengths. Each body is
fused once from a fixed number of parts, so the build cost grows linearly
with N (never one growing union of the whole finger).

Body names: ``base``, ``link1`` … ``link{N-1}``, ``distal``. Joint i's axis is
+Z through (x_i, 0, 0), x_1 = 0, x_{i+1} = x_i + L_i; L_N runs to the fingertip.
"""

from __future__ import annotations

import math

from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import cadquery as cq

from rjcad.cad.joint import (
    Z,
    _fuse,
    _one_solid,
    ground_channel_points,
    ground_side,
    ground_side_cuts,
    link_block,
    moving_channel_start,
    moving_side,
    moving_side_cuts,
    support_pin,
    tube_path,
)
from rjcad.cad.parts import CHANNEL_ROOF
from rjcad.finger_lengths import (CHANNEL_RUNS, DEFAULT_BASE_LENGTH, base_length_min, channel_shift, link_length_min,
                                  whole_mm)
from rjcad.params import JOINT_DEFAULT_END, JointParams
from rjcad.config import check_key as _typed
from rjcad.config import load_toml
from rjcad.errors import ParameterError, RjcadError
from rjcad import templates
from rjcad.units import DEG

#: The paper's finger, as plain data in rjcad.templates (the builder's default).
PAPER_FINGER = templates.PAPER_FINGER
DEFAULT_FINGER = templates.DEFAULT_FINGER

GLOBAL_KEYS = templates.FINGER_KEYS
JOINT_KEYS = templates.FINGER_JOINT_KEYS
MAX_JOINTS = 6
M3_CLEARANCE_DIAMETER = 3.4


@dataclass(frozen=True)
class FingerParams:
    """Validated finger design: one JointParams per joint, proximal to distal."""

    joints: tuple[JointParams, ...]
    base_length: float = 25.0
    source: str = "built-in paper finger"
    requested: tuple[dict, ...] = field(default=(), repr=False)

    @classmethod
    def from_dict(cls, data: dict, source: str = "<dict>") -> "FingerParams":
        """Check keys and ranges of a finger template (see templates/finger.toml)."""
        built, requested = cls.joints_from_dict(data)
        # no base length given: the shortest that holds joint 1 (whole mm, at least 25)
        base = (float(data["base_length_mm"]) if "base_length_mm" in data
                else whole_mm(base_length_min(built[0]), DEFAULT_BASE_LENGTH))
        fp = cls(tuple(built), base, source, tuple(requested))
        fp.validate_lengths()
        return fp

    @staticmethod
    def joints_from_dict(data: dict) -> tuple[list[JointParams], list[dict]]:
        """A template's joints, validated, with one eye (or tendon) plane for the whole finger, and each joint's
        table as given; the lengths are checked by :meth:`validate_lengths`."""
        for k, v in data.items():
            _typed("", k, v, GLOBAL_KEYS)
        defaults = {k: _typed("defaults.", k, v, JOINT_KEYS) for k, v in data.get("defaults", {}).items()}
        joints = data.get("joint", [])
        if not 1 <= len(joints) <= MAX_JOINTS:
            raise ParameterError("joint", len(joints), f"a finger needs 1 to {MAX_JOINTS} [[joint]] tables")
        common = dict(
            material=data.get("material", "absplus-p430"), printer=data.get("printer", "generic-0.4"),
            clearance=float(data["clearance_mm"]) if "clearance_mm" in data else None, layout=data.get("layout"),
            tendon_diameter=float(data.get("tendon_diameter_mm", 1.0)),
            safety_factor=float(data.get("safety_factor", 1.5)), end=data.get("end", JOINT_DEFAULT_END),
        )
        built, requested = [], []
        for i, j in enumerate(joints, start=1):
            where = f"joint[{i}]."
            if not isinstance(j, dict):
                raise ParameterError(f"joint[{i}]", j, "must be a table")
            merged = {**defaults, **{k: _typed(where, k, v, JOINT_KEYS) for k, v in j.items()}}
            if "stiffness_nmm_per_rad" not in merged:
                raise ParameterError(f"{where}stiffness_nmm_per_rad", None, "is required (here or in [defaults])")
            kw = dict(
                stiffness=float(merged["stiffness_nmm_per_rad"]),
                rotation=float(merged.get("rotation_deg", 90)) * DEG,
                preload=float(merged.get("preload_deg", 90)) * DEG,
                link_length=float(merged.get("link_length_mm", 40)),
                tendon_moment_arm=(float(merged["tendon_moment_arm_mm"])
                                   if "tendon_moment_arm_mm" in merged else None),
            )
            try:
                built.append(JointParams(**kw, **common, standalone=False))
            except ParameterError as e:
                name = {"stiffness": "stiffness_nmm_per_rad", "rotation": "rotation_deg",
                        "preload": "preload_deg", "link_length": "link_length_mm",
                        "tendon_moment_arm": "tendon_moment_arm_mm", "clearance": "clearance_mm",
                        "tendon_diameter": "tendon_diameter_mm"}.get(e.parameter, e.parameter)
                prefix = where if name in JOINT_KEYS else ""
                raise ParameterError(f"{prefix}{name}", e.value, e.limit, unit=e.unit) from None
            except RjcadError as e:
                raise RjcadError(f"{where}stiffness_nmm_per_rad = {kw['stiffness']:g}: no printable spring: {e}") \
                    from None
            requested.append(merged)
        # one eye plane for the whole finger, so that the tendon runs straight: a joint with a narrower
        # spring gets thicker cheeks, b_max − b each, and all joints share z_mid and the height
        b_max = max(p.spring.width for p in built)
        built = [replace(p, cheek_thickness=p.cheek_thickness + (b_max - p.spring.width)) for p in built]
        # desktop: each joint's tendon plane is raised to the highest one's (its band and arm grow)
        z_top = max(p.z_mid for p in built)
        built = [replace(p, tendon_lift=z_top - p.z_mid) if p.layout == "desktop" else p for p in built]
        return built, requested

    @classmethod
    def from_toml(cls, path: str | Path) -> "FingerParams":
        data = load_toml(path, GLOBAL_KEYS)
        return cls.from_dict(data, source=str(path))

    def validate_lengths(self) -> None:
        """Each link must hold its joints' blocks, the tendon slot and the anchor (rjcad.finger_lengths)."""
        js = self.joints
        lo = base_length_min(js[0])
        if not lo <= self.base_length <= 150:
            raise ParameterError("base_length_mm", self.base_length, f"must be in [{lo:.1f}, 150] mm", unit="mm")
        for i, p in enumerate(js, start=1):
            need = link_length_min(p, js[i] if i < len(js) else None)
            if p.link_length < need - 1e-9:
                raise ParameterError(f"joint[{i}].link_length_mm", p.link_length, f"must be >= {need:.1f} mm for "
                                     "these joints (their blocks, the slot, the tendon's channel)", unit="mm")
        length, bed = self.base_length + sum(p.link_length for p in js), js[0].printer_spec.bed_length
        if length > bed + 1e-9:
            raise ParameterError("base_length_mm + link_length_mm", length,
                                 f"the finger lies straight on the bed: must be <= {bed:g} mm on {js[0].printer}",
                                 unit="mm")

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


def _moved(shapes: list[cq.Shape], dx: float) -> list[cq.Shape]:
    v = cq.Vector(dx, 0, 0)
    return [s.translate(v) for s in shapes]


def link_channel_points(p: JointParams, q: JointParams, length: float) -> list[tuple[float, float, float]]:
    """Channel through link i: from joint i's slot to joint i+1's fork face (x = L − X_g of q)."""
    s = moving_channel_start(p)
    e = (length - q.ground_block_start + 0.5, q.moment_arm, q.z_mid)
    if channel_shift(p, q) < 1e-9:
        return [s, e]
    out, into = CHANNEL_RUNS
    return [s, (s[0] + out, s[1], s[2]), (e[0] - into, e[1], e[2]), e]


def m3_hole_heights(p: JointParams) -> tuple[float, float]:
    """Heights of the base's two M3 holes: 4 mm above the bed and 4 mm below the top, the upper one moved
    below the tendon's channel when it would come within a wall of it (the holes cross y = r) [mm]."""
    r_hole, r_t = M3_CLEARANCE_DIAMETER / 2, p.tendon_diameter / 2
    tip, wall = 1.0 / math.cos(CHANNEL_ROOF), p.printer_spec.min_wall_mm + 0.2
    z = p.height - 4.0
    if z - r_hole - wall < p.z_mid + r_t * tip and z + r_hole * tip + wall > p.z_mid - r_t:
        z = p.z_mid - r_t - wall - r_hole * tip
    return 4.0, z


def base_body(fp: FingerParams) -> cq.Shape:
    """Fork of joint 1, the base block with two M3 through holes (along Y) and the entry channel."""
    p = fp.joints[0]
    body = _fuse(ground_side(p) + [link_block(-fp.base_length, -p.ground_block_start, p.link_width, p.height)],
                 "base fuse")
    x_h = -fp.base_length + 5.0
    # teardrop holes (a round hole's crown is a flat overhang the length of the hole)
    holes = [h for z in m3_hole_heights(p)
             for h in tube_path([(x_h, -p.link_width / 2 - 1, z), (x_h, p.link_width / 2 + 1, z)],
                                M3_CLEARANCE_DIAMETER / 2)]
    cuts = tube_path(ground_channel_points(p, fp.base_length), p.tendon_diameter / 2) + holes + ground_side_cuts(p)
    return _one_solid(body.cut(*cuts), "base cuts")


def link_body(p: JointParams, q: JointParams) -> cq.Shape:
    """Moving side of joint p fused with the fork of joint q placed at x = L_p."""
    L = p.link_length
    H = max(p.height, q.height)
    W = max(p.link_width, q.link_width)
    parts = moving_side(p) + [link_block(p.block_start, L - q.ground_block_start, W, H)] + _moved(ground_side(q), L)
    body = _fuse(parts, "link fuse")
    cuts = (moving_side_cuts(p, H) + tube_path(link_channel_points(p, q, L), p.tendon_diameter / 2)
            + _moved(ground_side_cuts(q), L))
    body = _one_solid(body.cut(*cuts), "link cuts")
    return _fuse([body, support_pin(p)], "link support pin")


def distal_anchor_x(p: JointParams) -> float:
    """x of the tendon's cross-hole anchor in the distal link [mm]."""
    return p.link_length - p.link_width / 2 - 2.0


def distal_body(p: JointParams) -> cq.Shape:
    """Moving side of the last joint, ending in a rounded fingertip, with the tendon's cross-hole anchor.

    The tip is a cylinder of the link's width cut at the block's start: a wide, short link's whole cylinder
    would reach back behind it, into the joint's clearance."""
    L, W, H = p.link_length, p.link_width, p.height
    tip = cq.Solid.makeCylinder(W / 2, H, cq.Vector(L - W / 2, 0, 0), Z)
    if L - W < p.block_start:
        tip = tip.intersect(link_block(p.block_start, L, W, H))
    body = _fuse(moving_side(p) + [link_block(p.block_start, L - W / 2, W, H), tip], "distal fuse")
    xa = distal_anchor_x(p)
    anchor = cq.Solid.makeCylinder(max(1.0, p.tendon_diameter), H + 2, cq.Vector(xa, p.moment_arm, -1), Z)
    channel = tube_path([moving_channel_start(p), (xa, p.moment_arm, p.z_mid)], p.tendon_diameter / 2)
    body = _one_solid(body.cut(*moving_side_cuts(p, H), *channel, anchor), "distal cuts")
    return _fuse([body, support_pin(p)], "distal support pin")


def tendon_path(fp: FingerParams) -> list[tuple[float, float, float]]:
    """Tendon centreline at rest, base entry to the distal anchor, in finger coordinates [mm]."""
    js = fp.joints
    pts = ground_channel_points(js[0], fp.base_length)[:-1]
    pts = [(pts[0][0] + 0.5, *pts[0][1:])] + pts[1:] + [(-js[0].ground_block_start, js[0].moment_arm, js[0].z_mid)]
    for i, p in enumerate(js):
        x0 = fp.axis_x[i]
        if i + 1 < len(js):
            seg = link_channel_points(p, js[i + 1], p.link_length)
            seg[-1] = (seg[-1][0] - 0.5, *seg[-1][1:])
        else:
            seg = [moving_channel_start(p), (distal_anchor_x(p), p.moment_arm, p.z_mid)]
        pts += [(x + x0, y, z) for x, y, z in seg]
    return pts


def build_finger(fp: FingerParams) -> dict[str, cq.Shape]:
    """Every body of the finger, named, in finger coordinates (joint 1's axis at the origin)."""
    js = fp.joints
    bodies = {"base": base_body(fp)}
    for i in range(len(js) - 1):
        bodies[f"link{i + 1}"] = link_body(js[i], js[i + 1]).translate(cq.Vector(fp.axis_x[i], 0, 0))
    bodies["distal"] = distal_body(js[-1]).translate(cq.Vector(fp.axis_x[-1], 0, 0))
    return bodies
