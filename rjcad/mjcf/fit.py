"""What MuJoCo's joint friction cannot say about rjcad's friction model, measured on the paper's finger.

rjcad's finger (``rjcad.physics.finger``) has three friction effects: a constant pin friction band f0, a
tendon-induced pin friction that grows with the spring torque (γ⁺ closing, γ⁻ opening: paper Eq. 4), and a
capstan on the tendon's path in the base (the tension reaching the joints is T·e^{∓μα}: paper Eq. 5–7).
MuJoCo has a constant ``frictionloss`` per joint and one tension along a tendon. Here one constant
frictionloss for every joint is fitted (least RMS of the joint angles, or of the tension, over the whole pull
and release) so that MuJoCo comes closest to rjcad, and what remains is reported. ``damping`` is not fitted:
the pull/release is quasi-static (rate-independent), and at rest damping exerts no torque, so the data cannot
tell any value from another.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from rjcad.paper import FINGER, JOINT
from rjcad.physics.finger import Closure, FingerModel, model_from_template, simulate_stroke

#: Normal load on each pin for its constant friction: a 15 g link's weight [N]; f0 = μ_j·F_n [N·mm]
PIN_LOAD_N = 0.15
#: Steps each way of the strokes compared (the fit's and the report's)
STEPS = 250
#: The fit: a common frictionloss scanned over SCAN [N·mm], then refined (a bounded search, at most REFINE runs)
SCAN = (0.0, 1.0, 2.0, 4.0, 8.0, 12.0, 16.0)
REFINE = 10


def paper_friction_model() -> FingerModel:
    """The paper's finger (templates: K 5.2·[1, 1.5, 2], 90° preload and range, r 6 mm, 40 mm links) with rjcad's
    friction model at the paper's joint values: f0 = μ_j·F_n (F_n = PIN_LOAD_N), γ⁺ 1.89 / γ⁻ 3.15 N·mm/rad,
    and the capstan β⁺ = 1.24 in the base (μα = ln β⁺ before joint 1). No gravity."""
    from rjcad.io.templates import PAPER_FINGER

    m = model_from_template(PAPER_FINGER)
    n = m.n
    return replace(
        m,
        friction=(JOINT.mu_j * PIN_LOAD_N,) * n,
        gamma_pos=(JOINT.gamma_pos,) * n,
        gamma_neg=(JOINT.gamma_neg,) * n,
        wrap=(math.log(JOINT.beta_pos),) + (0.0,) * (n - 1),
        mu_t=1.0,
    )


def representable(m: FingerModel) -> FingerModel:
    """``m`` with what MuJoCo cannot represent switched off: no capstan, no load-dependent (γ) friction."""
    return replace(m, mu_t=0.0, gamma=(), gamma_pos=(0.0,) * m.n, gamma_neg=(0.0,) * m.n)


def mujoco_stroke(m: FingerModel, frictionloss, stroke: float = FINGER.stroke, steps: int = STEPS) -> Closure:
    """The quasi-static stroke of ``m``'s geometry and springs in MuJoCo, with these frictionlosses [N·mm]."""
    from rjcad.mjcf.model import spec_from_model
    from rjcad.mjcf.simulate import load, run_stroke
    from rjcad.mjcf.spec import to_xml

    return run_stroke(load(to_xml(spec_from_model(m, frictionloss=frictionloss))), stroke, steps)


@dataclass
class Comparison:
    """MuJoCo against rjcad over one pull/release: angle errors [deg] (RMS and largest, all and release only)."""

    frictionloss_nmm: list[float]
    tension_rms_n: float
    rms_deg: float
    max_deg: float
    release_rms_deg: float
    release_max_deg: float
    per_joint_release_max_deg: list[float]
    rjcad: Closure
    mujoco: Closure

    def to_dict(self) -> dict:
        r = lambda x: round(float(x), 4)  # noqa: E731
        return {
            "frictionloss_nmm": [r(x) for x in self.frictionloss_nmm],
            "tension_rms_n": r(self.tension_rms_n),
            "rms_deg": r(self.rms_deg),
            "max_deg": r(self.max_deg),
            "release_rms_deg": r(self.release_rms_deg),
            "release_max_deg": r(self.release_max_deg),
            "per_joint_release_max_deg": [r(x) for x in self.per_joint_release_max_deg],
        }


def compare(ref: Closure, mj: Closure, frictionloss) -> Comparison:
    err = np.degrees(mj.theta - ref.theta)
    rel = np.array([p == "release" for p in ref.phase])
    return Comparison(
        [float(x) for x in frictionloss],
        float(np.sqrt(np.mean((mj.tension - ref.tension) ** 2))),
        float(np.sqrt(np.mean(err**2))),
        float(np.abs(err).max()),
        float(np.sqrt(np.mean(err[rel] ** 2))),
        float(np.abs(err[rel]).max()),
        np.abs(err[rel]).max(axis=0).tolist(),
        ref,
        mj,
    )


def start_frictionloss(m: FingerModel, ref: Closure) -> np.ndarray:
    """A start for the fit: each joint's friction band averaged over the stroke [N·mm] (f0 + mean γ·(θ+θ0))."""
    _K, th0, *_ = m.arrays()
    g = (np.asarray(m.gamma_pos) + np.asarray(m.gamma_neg)) / 2
    return np.asarray(m.friction) + g * np.mean(ref.theta + th0, axis=0)


def fit_frictionloss(
    m: FingerModel, stroke: float = FINGER.stroke, steps: int = STEPS, target: str = "angles"
) -> Comparison:
    """The constant frictionloss, the same on every joint [N·mm], with which MuJoCo's stroke comes closest to
    rjcad's: the smallest RMS of every joint angle at every step (``target`` "angles") or of the actuator's
    tension ("tension"); and the errors that remain.

    One value for all joints (what a user can set without a fit of his own; per joint would cost a search in N
    dimensions of MuJoCo runs). Search: the values in ``SCAN`` and the joints' mean friction band, then a bounded
    scalar search around the best."""
    from scipy.optimize import minimize_scalar

    ref = simulate_stroke(m, stroke, steps)
    seen: dict[float, float] = {}

    def cost(f):
        key = round(max(float(f), 0.0), 3)
        if key not in seen:
            c = compare(ref, mujoco_stroke(m, np.full(m.n, key), stroke, steps), [key] * m.n)
            seen[key] = c.rms_deg if target == "angles" else c.tension_rms_n
        return seen[key]

    grid = sorted(set(SCAN) | {round(float(np.mean(start_frictionloss(m, ref))), 3)})
    i = int(np.argmin([cost(f) for f in grid]))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if hi > lo:
        minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 0.02, "maxiter": REFINE})
    best = np.full(m.n, min(seen, key=seen.__getitem__))
    return compare(ref, mujoco_stroke(m, best, stroke, steps), best)


def analyse(stroke: float = FINGER.stroke, steps: int = STEPS) -> dict:
    """The numbers of docs/mujoco.md: MuJoCo (frictionless, and with fitted frictionloss) against rjcad's full
    friction model of the paper's finger, and against the same model with capstan and γ switched off."""
    full = paper_friction_model()
    rep = representable(full)
    ref = simulate_stroke(full, stroke, steps)
    none = compare(ref, mujoco_stroke(full, np.zeros(full.n), stroke, steps), np.zeros(full.n))
    fitted = fit_frictionloss(full, stroke, steps)
    fitted_t = fit_frictionloss(full, stroke, steps, target="tension")
    fitted_rep = fit_frictionloss(rep, stroke, steps)
    fitted_rep_t = fit_frictionloss(rep, stroke, steps, target="tension")
    return {
        "model": {
            "stiffness_nmm_per_rad": list(full.stiffness),
            "moment_arm_mm": list(full.moment_arm),
            "pin_friction_nmm": full.friction[0],
            "gamma_pos_nmm_per_rad": full.gamma_pos[0],
            "gamma_neg_nmm_per_rad": full.gamma_neg[0],
            "capstan_beta_pos": JOINT.beta_pos,
            "stroke_mm": stroke,
            "steps_each_way": steps,
        },
        "frictionless_mujoco": none,
        "fitted": fitted,
        "fitted_to_tension": fitted_t,
        "fitted_without_capstan_and_gamma": fitted_rep,
        "fitted_to_tension_without_capstan_and_gamma": fitted_rep_t,
    }
