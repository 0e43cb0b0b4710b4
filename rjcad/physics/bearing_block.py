"""The manifest's ``bearing`` block of a joint: its bearing (``rjcad.physics.bearing``) at the design's largest
tendon tension, θ_j = rotation, flexing, with the tendon ending in the moving link and no gravity.

μ is assumed, not calibrated: dry ABS or PLA on itself is 0.2–0.6, and the paper's one bar test cannot decide
μ (docs/bearing.md), so the block uses the middle of that range and says so. The model is linearised (small
displacements) with a rigid spring: a tilt of several degrees reads "rocks until something stops it" (the note
says so in every block)."""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

from rjcad.design.params import JointParams
from rjcad.physics.bearing import BearingLocked, Drive, FirstTouch, driven, first_touch, locking_mu

#: The friction coefficient of the printed material on itself that the block assumes (dry ABS or PLA: 0.2–0.6).
MU_ASSUMED = 0.4

#: What the block's numbers are, written with them.
NOTE = (
    "the bearing at the largest tendon tension (rotation, flexing; tendon ending in the moving link; no gravity); "
    "linearised small displacements, rigid spring; mu assumed for dry plastic on plastic, not measured "
    "(docs/bearing.md); binding: surfaces not designed to bear that close under this load. A tilt of more than "
    "a few degrees, and a binding found there, may be the linearisation's: first_touch is where the exact gaps "
    "first close along the same motion from rest (on the default desktop joint it is the collar, as on the "
    "built solids; docs/bearing.md)"
)


@lru_cache(maxsize=32)
def _solved(p: JointParams, mu: float) -> tuple[Drive | None, FirstTouch | None, float]:
    """The block's driven pose (None: locked), its first touch and the locking μ; kept, so that a build that
    computes them meanwhile (rjcad.cad.build.write_joint) does not compute them again for the manifest."""
    try:
        d = driven(p, mu, p.rotation, 1, "tendon")
    except BearingLocked:
        d = None
    return d, None if d is None else first_touch(d.state), locking_mu(p)


def bearing_block(p: JointParams, mu: float = MU_ASSUMED) -> dict[str, Any]:
    """``{mu, tendon_tension_n, friction_torque_nmm, tilt_deg, min_gap_under_load_mm, contacts {surface: N},
    binding, first_touch {tilt_deg, surface, designed} or None, locked, locks_above_mu, note}`` [N, N·mm, deg, mm];
    locked (the tendon's own friction outgrows it): numbers None; locks_above_mu: ``locking_mu`` (None: never)."""
    d, touch, lock = _solved(p, mu)
    block: dict[str, Any] = {"mu": mu}
    ends = {"locks_above_mu": round(lock, 4) if math.isfinite(lock) else None, "note": NOTE}
    if d is None:
        nothing = dict.fromkeys(("tendon_tension_n", "friction_torque_nmm", "tilt_deg", "min_gap_under_load_mm"))
        return block | nothing | {"contacts": {}, "binding": [], "first_touch": None, "locked": True} | ends
    s = d.state
    return (
        block
        | {
            "tendon_tension_n": round(d.drive, 4),
            "friction_torque_nmm": round(s.friction_torque, 4),
            "tilt_deg": round(math.degrees(s.tilt), 3),
            "min_gap_under_load_mm": round(s.min_gap, 4),
            "contacts": {k: round(v, 4) for k, v in s.bearing.items()},
            "binding": list(s.binding),
            "first_touch": None
            if touch is None
            else {
                "tilt_deg": round(math.degrees(touch.tilt), 3),
                "surface": touch.contact.surface,
                "designed": touch.contact.designed,
            },
            "locked": False,
        }
        | ends
    )
