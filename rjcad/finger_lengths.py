"""The shortest base and link lengths that hold a finger's joints (pure: from JointParams, no CAD) [mm].

A link from joint i to joint i+1 holds joint i's moving block (from X_m), the tendon slot with its support
pin, and joint i+1's ground block (from L − X_g); the distal link ends past the slot in a rounded tip of
radius W/2 with the tendon's anchor; the base holds joint 1's ground block and two M3 holes.
"""

from __future__ import annotations

import math

#: The paper's link length, axis to axis, and the default base length [mm].
PAPER_LINK_LENGTH = 40.0
DEFAULT_BASE_LENGTH = 25.0
#: Base beyond joint 1's ground block: the M3 holes' land [mm].
BASE_LAND = 12.0


def base_length_min(p) -> float:
    """Shortest base: X_g + BASE_LAND [mm]."""
    return p.ground_block_start + BASE_LAND


def link_length_min(p, q=None) -> float:
    """Shortest link after joint ``p``: X_m + slot + X_g(q) + 0.5 to the next joint ``q``, or, distal,
    X_m + slot + W/2 + 6 [mm]."""
    if q is not None:
        return p.block_start + p.slot_length + q.ground_block_start + 0.5
    return p.block_start + p.slot_length + p.link_width / 2 + 6.0


def whole_mm(x: float, at_least: float = 0.0) -> float:
    """x rounded up to a whole millimetre, at least ``at_least`` [mm]."""
    return float(max(at_least, math.ceil(x - 1e-9)))


def shortest_lengths(joints, at_least: float = PAPER_LINK_LENGTH) -> tuple[float, list[float]]:
    """(base, links): the shortest whole-millimetre lengths that hold ``joints``, links at least ``at_least``."""
    links = [whole_mm(link_length_min(p, joints[i + 1] if i + 1 < len(joints) else None), at_least)
             for i, p in enumerate(joints)]
    return whole_mm(base_length_min(joints[0]), DEFAULT_BASE_LENGTH), links
