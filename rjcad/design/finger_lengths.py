"""The shortest base and link lengths that hold a finger's joints (pure: from JointParams, no CAD) [mm].

A link from joint i to joint i+1 holds joint i's moving block (from X_m), the tendon slot with its support
pin, the tendon's channel (which, between joints of different moment arms, runs straight out of the slot,
shifts to the next arm at 45° at most and runs straight into the next fork), and joint i+1's ground block (from
L − X_g); the distal link ends past the slot in a rounded tip of radius W/2 with the tendon's anchor; the base
holds joint 1's ground block and two M3 holes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rjcad.design.params import JointParams

#: The paper's link length, axis to axis, and the default base length [mm].
PAPER_LINK_LENGTH = 40.0
DEFAULT_BASE_LENGTH = 25.0
#: Base beyond joint 1's ground block: the M3 holes' land [mm].
BASE_LAND = 12.0


def base_length_min(p: JointParams) -> float:
    """Shortest base: X_g + BASE_LAND [mm]."""
    return p.ground_block_start + BASE_LAND


#: Straight runs of a link's tendon channel out of the slot and into the next fork, around its shift between two
#: moment arms (rjcad.cad.finger.link_channel_points) [mm].
CHANNEL_RUNS = (2.0, 3.5)


def channel_shift(p: JointParams, q: JointParams) -> float:
    """How far the tendon's channel moves across a link, from joint ``p``'s moment arm and plane to ``q``'s [mm]."""
    return math.hypot(q.moment_arm - p.moment_arm, q.z_mid - p.z_mid)


#: Added to the printer's thinnest wall for the wall between a slot's end and the next fork's face: a faceted
#: face may measure this much thinner than modelled [mm].
WALL_ALLOWANCE = 0.1


def link_length_min(p: JointParams, q: JointParams | None = None) -> float:
    """Shortest link after joint ``p``: X_m + slot + X_g(q) + w to the next joint ``q``, w the printer's thinnest
    wall + WALL_ALLOWANCE between the slot's end and the fork's face (or, when the moment arms differ, + 4 + the
    channel's shift: its runs and a shift at 45° at most, from the slot's end at X_m + slot − 0.5 to the fork's face
    at L − X_g + 0.5), or, distal, X_m + slot + W/2 + 6 [mm]."""
    if q is not None:
        shift = channel_shift(p, q)
        wall = max(p.printer_spec.min_wall_mm, q.printer_spec.min_wall_mm) + WALL_ALLOWANCE
        extra = wall if shift < 1e-9 else sum(CHANNEL_RUNS) - 1.0 + shift
        return p.block_start + p.slot_length + q.ground_block_start + extra
    return p.block_start + p.slot_length + p.link_width / 2 + 6.0


def whole_mm(x: float, at_least: float = 0.0) -> float:
    """x rounded up to a whole millimetre, at least ``at_least`` [mm]."""
    return float(max(at_least, math.ceil(x - 1e-9)))


def shortest_lengths(joints: Sequence[JointParams], at_least: float = PAPER_LINK_LENGTH) -> tuple[float, list[float]]:
    """(base, links): the shortest whole-millimetre lengths that hold ``joints``, links at least ``at_least``."""
    links = [
        whole_mm(link_length_min(p, joints[i + 1] if i + 1 < len(joints) else None), at_least)
        for i, p in enumerate(joints)
    ]
    return whole_mm(base_length_min(joints[0]), DEFAULT_BASE_LENGTH), links
