"""The full rod model's verdict on one spring: torque curve, stiffness, peak stress, coil gap, contact.

Every spring the designer emits is wound by :func:`rjcad.spring.rod.spiral_windup` from its printed
shape to preload + rotation, in the joint's sense, and judged on what comes out (:func:`rod_check`,
cached by geometry). Units: mm, N, N·mm, rad, MPa; per spring unless a name says joint.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from rjcad.spring import rod

#: Largest wind-up step of the verification [rad]; first contact moves < 0.1° from 5° to 2.5° steps.
STEP = math.radians(5.0)
#: Elements per turn of the verification (gaps within 1 µm of 80 per turn, the rod model's reference).
PER_TURN = 60


@dataclass(frozen=True)
class RodCheck:
    """One spring wound 0 → θ_max by the rod model (arrays over the wind-up samples ``theta``).

    ``torque`` one spring [N·mm]; ``stiffness`` the working-range slope (T(θ_max) − T(θ_p))/rotation
    [N·mm/rad]; ``stress`` max|M|·6/(b·t²) per sample [MPa], its peak at ``stress_xy``; ``gap`` the
    smallest coil (and pin) gap per sample [mm], its minimum ``min_gap`` at wind-up ``min_gap_theta``
    and point ``gap_xy``; ``coil_gap`` and ``pin_gap`` (None without a pin radius) the two apart; ``first_contact`` where the gap first closes [rad] (None: never);
    ``pin_force`` the largest reaction on the outer end's post [N]; ``wound`` the centreline at θ_max
    and ``printed`` as printed, in the hub frame [mm]. Two arms (``arms`` 2): ``arm_force`` one arm's largest
    reaction on the hub [N], ``hub_force`` the largest net force of both arms on the hub [N] (one arm: its
    reaction), ``key_gap`` each arm's smallest gap to the other arm's key per sample [mm] (None: one arm).
    """

    theta: np.ndarray
    torque: np.ndarray
    stiffness: float
    stress: np.ndarray
    stress_xy: np.ndarray
    gap: np.ndarray
    coil_gap: np.ndarray
    pin_gap: np.ndarray | None
    min_gap: float
    min_gap_theta: float
    gap_xy: np.ndarray
    first_contact: float | None
    pin_force: float
    wound: np.ndarray
    printed: np.ndarray
    preload: float
    arms: int = 1
    hub_force: float = 0.0
    arm_force: float = 0.0
    key_gap: np.ndarray | None = None

    @property
    def hub_force_ratio(self) -> float:
        """Largest net hub force over one arm's largest reaction (0 for a spring without load)."""
        return self.hub_force / self.arm_force if self.arm_force > 0 else 0.0

    @property
    def min_key_gap(self) -> float | None:
        """Smallest gap between an arm and the other arm's key over the wind-up [mm] (None: one arm)."""
        return None if self.key_gap is None else float(self.key_gap.min())

    @property
    def peak_stress(self) -> float:
        """Largest bending stress over the whole wind-up [MPa]."""
        return float(self.stress.max())

    def torque_at(self, theta: float) -> float:
        """Torque of one spring at wind-up θ (linear between samples) [N·mm]."""
        return float(np.interp(theta, self.theta, self.torque))

    def stress_at(self, theta: float) -> float:
        """Peak bending stress at wind-up θ (linear between samples) [MPa]."""
        return float(np.interp(theta, self.theta, self.stress))

    def below(self, limit: float) -> float | None:
        """First wind-up where the gap falls below ``limit`` [rad] (linear between samples), or None."""
        return rod.first_crossing(self.theta, self.gap - limit)


@functools.lru_cache(maxsize=256)
def rod_check(
    r_in: float,
    pitch: float,
    turns: float,
    b: float,
    t: float,
    E: float,
    end: str,
    sense: str,
    preload: float,
    rotation: float,
    pin_radius: float | None = None,
    arms: int = 1,
    key: tuple[float, float, float] | None = None,
) -> RodCheck:
    """Wind the spring by the rod model to preload + rotation in ``sense``; see :class:`RodCheck`.

    ``arms`` 2: two interleaved arms (``pitch`` the coil-to-coil pitch); ``key`` (u0, u1, w) [mm]: each arm's key,
    radially from the end's centreline point, for the gap to the other arm (rjcad.spring.rod.key_box)."""
    theta_max = preload + rotation
    steps = max(4, math.ceil(theta_max / STEP - 1e-9))
    res = rod.spiral_windup(
        r_in,
        pitch,
        turns,
        b,
        t,
        E,
        end=end,
        sense=sense,
        theta_max=theta_max,
        steps=steps,
        per_turn=PER_TURN,
        pin_radius=pin_radius,
        arms=arms,
        key=key,
    )
    i_gap = int(np.argmin(res.gap))
    i_stress = int(np.argmax(res.stress))
    T_pre = float(np.interp(preload, res.theta, res.torque))
    printed, _, _ = rod.spiral_nodes(r_in, arms * pitch, turns, -math.pi / 2 - 2 * math.pi * turns, PER_TURN)
    for arr in (res.theta, res.torque, res.stress, res.gap, res.coil_gap):
        arr.setflags(write=False)
    return RodCheck(
        theta=res.theta,
        torque=res.torque,
        stiffness=(float(res.torque[-1]) - T_pre) / rotation,
        stress=res.stress,
        stress_xy=res.stress_xy[i_stress],
        gap=res.gap,
        coil_gap=res.coil_gap,
        pin_gap=res.hub_gap,
        min_gap=float(res.gap[i_gap]),
        min_gap_theta=float(res.theta[i_gap]),
        gap_xy=res.gap_xy[i_gap],
        first_contact=res.first_contact,
        pin_force=float(res.pin_force.max()),
        wound=res.centreline[0],
        printed=printed,
        preload=preload,
        **({} if arms == 1 else _pair_keys(res, arms)),
    )


def _pair_keys(res: rod.RodResult, arms: int) -> dict:
    """A two-arm check's extra fields: net and one arm's hub force, and the key gaps (read-only)."""
    assert res.arm_force is not None
    key_gap = res.key_gap
    if key_gap is not None:
        key_gap.setflags(write=False)
    return dict(arms=arms, hub_force=float(res.hub_force.max()), arm_force=float(res.arm_force.max()), key_gap=key_gap)


def check_design(design) -> RodCheck:
    """:func:`rod_check` of a :class:`~rjcad.spring.design.SpringDesign` under its requirement."""
    req = design.requirement
    return rod_check(
        float(design.inner_radius),
        float(design.pitch),
        float(design.turns),
        float(design.width),
        float(design.thickness),
        float(design.youngs_modulus),
        design.end,
        design.sense,
        float(req.preload),
        float(req.rotation),
        req.pin_radius,
        **({} if req.arms == 1 else {"arms": req.arms, "key": design.nominal_key}),
    )
