"""Where a joint's wound spring goes: the strip's envelope over the joint's range (no CAD kernel).

The joint prints its spring winding clockwise outwards with the outer end at −preload, and turns
that end counter-clockwise by the preload (assembly), then by the rotation (flexion): it UNWINDS
the spiral. The end reaction pushes the coil pack sideways, so the wound strip leaves the printed
outer radius (the default clamped spring: +1.8 mm at 180°; a pinned one far more). The builder
keeps its parts clear of what this module measures, with the rod model (rjcad.spring.rod: large
rotations, no contact; inner end clamped on the hub, outer end carried round the axis, its angle
held when ``clamped``, free when ``pinned``).

Frames: ground = the hub's (the printed spiral's); moving = the moving link's, in which the outer
end stays at angle 0 (the ground frame turned by θ − preload, for wind-ups θ from the preload on).
Radii are of the strip's centreline: add t/2 for its surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from rjcad.spring import rod

#: Angular bin of the moving-frame profile [rad] (5°).
BIN = math.radians(5.0)
#: Largest wind-up step between the sampled states [rad] (10°).
MAX_STEP = math.radians(10.0)
#: Nodes per turn of the rod model here: 40 puts the centreline within 0.03 mm of 80's.
PER_TURN = 40


@dataclass(frozen=True)
class WoundEnvelope:
    """The strip's centreline over wind-ups 0..preload + rotation [mm].

    ``r_max``: largest radius (ground frame, all states); ``ground_x_min``: smallest x (ground
    frame, all states); ``moving_x_max``: largest x in the moving frame (states θ ≥ preload);
    ``moving_profile``: largest radius in each 5° bin of polar angle in the moving frame, bin i
    covering [−π + i·BIN, −π + (i+1)·BIN) (states θ ≥ preload).
    """

    r_max: float
    ground_x_min: float
    moving_x_max: float
    moving_profile: tuple[float, ...]

    def radius_within(self, a0: float, a1: float) -> float:
        """Largest moving-frame radius at polar angles a0..a1 (rad, −π < a0 < a1 < π), one bin either side."""
        i0 = max(0, int((a0 + math.pi) // BIN) - 1)
        i1 = min(len(self.moving_profile) - 1, int((a1 + math.pi) // BIN) + 1)
        return max(self.moving_profile[i0 : i1 + 1])


def wound_states(
    r_in: float, pitch: float, turns: float, t: float, preload: float, rotation: float, end: str
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Wind-up angles θ (K,) [rad] and the strip's centreline (N, 2) at each, in the ground frame [mm]."""
    windup = preload + rotation
    X, tangents, _ = rod.spiral_nodes(r_in, pitch, turns, preload - 2 * math.pi * turns, per_turn=PER_TURN)
    x, y = X[-1]  # counter-clockwise spiral, end at +preload: the mirror image (y → −y) of the printed one

    # unwinding turns the end of the counter-clockwise spiral clockwise
    def path(lam: float) -> tuple[float, float, float | None]:
        c, s = math.cos(lam * windup), math.sin(lam * windup)
        return (c * x + s * y - x, -s * x + c * y - y, -lam * windup if end == "clamped" else None)

    n = max(2, math.ceil(windup / MAX_STEP))
    lams = np.unique(np.concatenate([np.linspace(0.0, 1.0, n + 1)[1:], [preload / windup]]))
    sol = rod.solve_rod(X, {0: (0.0, 0.0, 0.0), -1: path}, EI=t**2 / 12.0, EA=1.0, steps=lams, tangents=tangents)
    mirror = np.array([1.0, -1.0])
    return windup * sol.lam, [_densify(sol.positions(k)) * mirror for k in range(len(sol.lam))]


def _densify(P: np.ndarray, k: int = 4) -> np.ndarray:
    """The polyline through P with k points per segment (so that every 5° bin sees each coil)."""
    f = np.arange(k) / k
    mid = P[:-1, None, :] + f[None, :, None] * (P[1:] - P[:-1])[:, None, :]
    return np.vstack([mid.reshape(-1, 2), P[-1:]])


@lru_cache(maxsize=1024)
def wound_envelope(
    r_in: float, pitch: float, turns: float, t: float, preload: float, rotation: float, end: str, arms: int = 1
) -> WoundEnvelope:
    """:class:`WoundEnvelope` of a spring (independent of E and b: the ends' motion is prescribed).

    ``arms`` 2: two arms 180° apart (``pitch`` each arm's); the second is the first turned by 180° (each arm is
    its own rod on the fixed hub), and the envelope covers both."""
    theta, states = wound_states(r_in, pitch, turns, t, preload, rotation, end)
    if arms == 2:
        states = [np.vstack([P, -P]) for P in states]
    profile = np.zeros(round(2 * math.pi / BIN))
    r_max, x_min, x_max = 0.0, math.inf, -math.inf
    for th, P in zip(theta, states):
        r = np.hypot(P[:, 0], P[:, 1])
        r_max, x_min = max(r_max, float(r.max())), min(x_min, float(P[:, 0].min()))
        if th < preload - 1e-9:
            continue
        a = np.arctan2(P[:, 1], P[:, 0]) - (th - preload)  # into the moving frame
        a = (a + math.pi) % (2 * math.pi)
        x_max = max(x_max, float((r * np.cos(a - math.pi)).max()))
        np.maximum.at(profile, np.minimum((a // BIN).astype(int), len(profile) - 1), r)
    return WoundEnvelope(r_max, x_min, x_max, tuple(float(v) for v in profile))
