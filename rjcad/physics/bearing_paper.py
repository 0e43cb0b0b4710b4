"""The bearing model (rjcad.physics.bearing) calibrated once on the paper's joint, then used to predict a joint.

* Calibration: the paper's joint (stacked layout, the Dimension Elite's 0.25 mm clearance, 70° preload) in
  its bar test (experiment A: the bar's weight and drive, the springs' end forces). One μ makes the mean
  friction torque over the range equal the paper's band μ_j·F_n = 10.38 N·mm.
* Check: the same μ in the tendon test without F_n (experiment D) gives γ± (Eq. 4) to set against the paper's.
* Prediction: any joint's friction torque at its largest tendon tension (θ_j = rotation, pulling), its tilt,
  smallest gap under load and bearing surfaces, and its hysteresis band over the range.

Units: mm, N, N·mm, rad. Every number of docs/bearing.md comes from a function here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from rjcad import DEG
from rjcad.design.layout_desktop import CONE_ANGLE, ROOF_LAND
from rjcad.design.params import JointParams
from rjcad.errors import ParameterError
from rjcad.paper import JOINT
from rjcad.physics.bearing import BAR_ARM_MM, BearingLocked, BearingState, Drive, driven, spring_forces, spring_torque
from rjcad.physics.bearing_block import MU_ASSUMED

#: The paper's band: μ_j·F_n [N·mm] (10.38 = 6.92 mm × 1.5 N).
PAPER_BAND = JOINT.mu_j * JOINT.normal_load
#: Poses over the range at which a band is averaged.
POSES = 5
#: Dry ABS on ABS, the range usually quoted.
PLAUSIBLE_MU = (0.2, 0.6)


def paper_joint() -> JointParams:
    """The paper's joint as rjcad builds it: stacked, on the paper's printer (0.25 mm clearance), 70° preload
    (the measured joint's), 90° rotation; its pin radius (2 mm) is rjcad's, the paper does not state one."""
    return JointParams(printer="dimension-elite", layout="stacked", preload=70 * DEG)


def _poses(p: JointParams) -> np.ndarray:
    return np.linspace(0.0, p.rotation, POSES)


def loop(p: JointParams, mu: float, drive: str, push_at: float | None = BAR_ARM_MM) -> tuple[list[Drive], list[Drive]]:
    """The driven poses over the range, flexing and releasing (``drive`` 'bar' or 'tendon'; ``push_at``:
    ``bar_loads``)."""
    springs = spring_forces(p)
    up = [driven(p, mu, float(t), 1, drive, springs=springs, push_at=push_at) for t in _poses(p)]
    down = [driven(p, mu, float(t), -1, drive, springs=springs, push_at=push_at) for t in _poses(p)]
    return up, down


def band(p: JointParams, mu: float, drive: str, push_at: float | None = BAR_ARM_MM) -> float:
    """Mean half-width of the hysteresis loop over the range, as a joint torque [N·mm]:
    mean of (τ⁺ − τ⁻)/2, τ the bar's torque or r·T for the tendon."""
    up, down = loop(p, mu, drive, push_at)
    arm = p.moment_arm if drive == "tendon" else 1.0
    return float(np.mean([(u.drive - d.drive) * arm / 2 for u, d in zip(up, down)]))


@dataclass(frozen=True)
class BarLoop:
    """The bar test's loop (experiment A) sampled along the range: the slopes dτ/dθ_j of its flexing and
    releasing branches and Eq. 3's one K_s fitted to both (their mean, both sampled at the same angles)
    [N·mm/rad], and its mean half-width [N·mm]."""

    slope_pull: float
    slope_release: float
    band: float

    @property
    def slope(self) -> float:
        return 0.5 * (self.slope_pull + self.slope_release)


def bar_loop(p: JointParams, mu: float, poses: int = 25, push_at: float | None = BAR_ARM_MM) -> BarLoop:
    """:class:`BarLoop` of ``p`` with μ, at ``poses`` angles from 0 to the rotation (``push_at``: ``bar_loads``)."""
    th = np.linspace(0.0, p.rotation, poses)
    springs = spring_forces(p)
    up = np.array([driven(p, mu, float(t), 1, "bar", springs=springs, push_at=push_at).drive for t in th])
    down = np.array([driven(p, mu, float(t), -1, "bar", springs=springs, push_at=push_at).drive for t in th])
    return BarLoop(float(np.polyfit(th, up, 1)[0]), float(np.polyfit(th, down, 1)[0]), float(np.mean(up - down) / 2))


def cycle_drive(p: JointParams, mu: float, drive: str, theta_j: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The drive at each sample of a cycle, with friction from ``p``'s bearing: the bar's torque [N·mm] or the
    tendon's tension [N] (not routed; 0 where slack). Raises ``BearingLocked``."""
    springs = spring_forces(p)
    return np.array([driven(p, mu, float(t), int(s), drive, springs=springs).drive for t, s in zip(theta_j, direction)])


@lru_cache(maxsize=8)
def calibrate(target: float = PAPER_BAND, push_at: float | None = BAR_ARM_MM) -> float:
    """μ such that the paper's joint in its bar test has the band ``target`` [N·mm] (bisection on μ; ``push_at``:
    where the bar is pushed, ``bar_loads``)."""
    from scipy.optimize import brentq

    p = paper_joint()
    lo, hi = 0.01, 2.0
    f_hi = band(p, hi, "bar", push_at) - target
    if f_hi < 0:
        raise ParameterError("target", target, f"needs μ > {hi}: the model's load path cannot make that band")
    return float(brentq(lambda mu: band(p, mu, "bar", push_at) - target, lo, hi, xtol=1e-5))


@dataclass(frozen=True)
class Gammas:
    """γ⁺, γ⁻ [N·mm/rad] fitted as the paper did (Eq. 4, F_n = 0): γ⁺·θ = r·T⁺ − τ_s, γ⁻·θ = τ_s − r·T⁻,
    θ = θ_j + θ_0, least squares through the origin."""

    pos: float
    neg: float


def tendon_gammas(p: JointParams, mu: float) -> Gammas:
    """The tendon test without F_n (experiment D) on ``p`` with μ: γ± of its loop."""
    up, down = loop(p, mu, "tendon")
    th = np.array([u.theta_j for u in up]) + p.preload
    ts = np.array([spring_torque(p, u.theta_j) for u in up])
    r = p.moment_arm
    y_pos = np.array([u.drive for u in up]) * r - ts
    y_neg = ts - np.array([d.drive for d in down]) * r
    return Gammas(float(th @ y_pos / (th @ th)), float(th @ y_neg / (th @ th)))


@dataclass(frozen=True)
class Prediction:
    """A joint's bearing at its largest tendon tension (θ_j = rotation, pulling) and its hysteresis band.

    ``tension`` [N], ``friction_torque`` [N·mm], ``tilt_deg``, ``min_gap`` [mm] (between surfaces not designed
    to bear), ``contacts`` {surface: normal force [N]}, ``binding`` surfaces that bear but must not; ``band`` the
    mean half-width of its tendon loop [N·mm], ``band_paper`` the same from the paper's γ± (Eq. 4, F_n = 0),
    ``spring_force`` the largest net spring force on the moving body over the range [N]. ``locked``: the tendon
    cannot turn the joint to its rotation (its own friction outgrows it); then the numbers are NaN."""

    tension: float
    friction_torque: float
    tilt_deg: float
    min_gap: float
    contacts: dict[str, float]
    binding: list[str]
    band: float
    band_paper: float
    spring_force: float
    locked: bool = False

    def summary(self) -> dict[str, object]:
        """Manifest-style keys [N, N·mm, deg, mm]."""
        return {
            "friction_torque_nmm": round(self.friction_torque, 3),
            "tilt_deg": round(self.tilt_deg, 3),
            "min_gap_under_load_mm": round(self.min_gap, 3),
            "contacts": sorted(self.contacts),
        }


def predict(p: JointParams, mu: float) -> Prediction:
    """:class:`Prediction` of ``p`` with μ."""
    mean_theta = float(np.mean(_poses(p))) + p.preload
    paper = 0.5 * (JOINT.gamma_pos + JOINT.gamma_neg) * mean_theta
    net = float((spring_forces(p).magnitude() * p.springs).max())  # the stacked layout's two springs push alike
    try:
        s = driven(p, mu, p.rotation, 1, "tendon").state
        width = band(p, mu, "tendon")
    except BearingLocked:
        nan = math.nan
        return Prediction(nan, nan, nan, nan, {}, [], nan, paper, net, locked=True)
    tension = s.loads[0].force
    return Prediction(
        tension=math.hypot(tension[0], tension[1]),
        friction_torque=s.friction_torque,
        tilt_deg=math.degrees(s.tilt),
        min_gap=s.min_gap,
        contacts=s.bearing,
        binding=s.binding,
        band=width,
        band_paper=paper,
        spring_force=net,
    )


def _sum_n_rho(state: BearingState) -> float:
    """Σ N_i·ρ_i of a bearing state: its friction torque per unit μ [N·mm]."""
    return float(sum(f * c.radius for f, c in zip(state.forces, state.contacts)))


#: A μ inside the plausible range at which docs/bearing.md also states the predictions (the manifest's).
MU_DRY = MU_ASSUMED


def _push_sensitivity(paper: JointParams) -> dict[str, str]:
    """Eq. 3's slope of the bar loop (μ calibrated each time) with the bar pushed at 105 and 140 mm from the axis,
    and turned by a couple: the paper does not say how its bar was turned."""
    out = {}
    for key, at in (("105", 105.0), ("140", 140.0), ("couple", None)):
        slope = bar_loop(paper, calibrate(PAPER_BAND, at), push_at=at).slope
        out[f"bar_slope_{key}"] = f"{slope:.3f}"
        out[f"bar_slope_{key}_error"] = f"{100 * (slope / JOINT.stiffness - 1):.2f}"
    return out


@lru_cache(maxsize=1)
def doc_numbers() -> dict[str, str]:
    """Every number docs/bearing.md quotes, formatted as it quotes them (tests/test_bearing.py checks the page)."""
    mu = calibrate()
    paper = paper_joint()
    g = tendon_gammas(paper, mu)
    bar = bar_loop(paper, mu)
    out = {
        "mu": f"{mu:.2f}",
        "band_paper_joint": f"{band(paper, mu, 'bar'):.2f}",
        "gamma_pos": f"{g.pos:.2f}",
        "gamma_neg": f"{g.neg:.2f}",
        "bar_contacts": ", ".join(sorted(driven(paper, mu, 0.0, 1, "bar").state.bearing)),
        "bar_sum_n_rho": f"{_sum_n_rho(driven(paper, 0.0, 0.0, 1, 'bar').state):.2f}",
        "bar_slope_pull": f"{bar.slope_pull:.3f}",
        "bar_slope_release": f"{bar.slope_release:.3f}",
        "bar_slope": f"{bar.slope:.3f}",
        "bar_slope_error": f"{100 * (bar.slope / JOINT.stiffness - 1):.1f}",
        "bar_band": f"{bar.band:.2f}",
        "paper_spring": f"{paper.spring.joint_stiffness:.3f}",
        **_push_sensitivity(paper),
        "wedge_radial": f"{1 / math.sin(CONE_ANGLE):.2f}",
        "wedge_axial": f"{1 / math.cos(CONE_ANGLE):.2f}",
    }
    for m_key, m in (("cal", mu), ("dry", MU_DRY)):
        for layout in ("desktop", "stacked"):
            pr = predict(JointParams(layout=layout), m)
            key = f"{layout}_{m_key}"
            out[f"{key}_locked"] = "locks" if pr.locked else "turns"
            if pr.locked:
                continue
            out[f"{key}_tension"] = f"{pr.tension:.2f}"
            out[f"{key}_torque"] = f"{pr.friction_torque:.2f}"
            out[f"{key}_tilt"] = f"{pr.tilt_deg:.1f}"
            out[f"{key}_gap"] = f"{pr.min_gap:.2f}"
            out[f"{key}_band"] = f"{pr.band:.2f}"
            out[f"{key}_band_paper"] = f"{pr.band_paper:.2f}"
            out[f"{key}_contacts"] = ", ".join(sorted(pr.contacts))
            out[f"{key}_binding"] = ", ".join(pr.binding) or "none"
    L = JointParams(layout="desktop").desktop
    out["bore_length"] = f"{L.roof_top(L.R_bore + ROOF_LAND) - L.roof_under(L.R_bore):.2f}"
    dry = predict(JointParams(layout="desktop"), MU_DRY)
    out["desktop_band_ratio"] = f"{dry.band / dry.band_paper:.1f}"
    out["desktop_spring_force"] = f"{dry.spring_force:.2f}"
    return out
