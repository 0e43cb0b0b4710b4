"""The effect catalogue for whole-finger campaigns: what the design model of a finger may miss.

Built per finger (per-joint parameters carry the suffix ``_j1`` … ``_jN``). Each effect names its cause, its
parameters (JSON names with units), bounds, a typical size for the synthetic bench, and what it needs.
The design model (``FingerDesign``) is as designed: frictionless, inextensible tendon, no gravity, linear springs
with no damping or relaxation. The joint catalogue's rate and wind-up effects are here per joint (viscous
damping, stiffening) or shared (stress relaxation: one polymer, so one time constant and one arm-to-spring
stiffness ratio).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from rjcad import DEG
from rjcad.identify.catalogue import Effect, Param
from rjcad.physics.finger import FingerModel


class FingerEffect(Effect):
    """An effect whose parameters are built for a finger of ``n`` joints."""

    def __init__(
        self,
        id: str,
        name: str,
        cause: str,
        params: tuple[Param, ...],
        needs: str = "any",
        needs_text: str = "",
        also: tuple[dict, ...] = (),
    ):
        self.id, self.name, self.cause, self.params, self.needs, self.needs_text = (
            id,
            name,
            cause,
            params,
            needs,
            needs_text,
        )
        self.also = also  # further start points (overrides of the typical sizes): the fit has local minima

    # The parameters are built for the finger (``catalogue``): their neutral and typical values need no design
    # object, and the finger's callers pass None.
    def neutral(self, design: dict[str, Any] | None) -> dict:
        return {p.name: p.neutral for p in self.params}

    def typical(self, design: dict[str, Any] | None) -> dict:
        return {p.name: p.typical for p in self.params}

    def starts(self, design):
        t = self.typical(design)
        return [t] + [{**t, **o} for o in self.also]


def _p(name, lo, hi, typical, neutral) -> Param:
    return Param(name, name, 1.0, lo, hi, typical, neutral)


def catalogue(design: FingerModel) -> tuple[FingerEffect, ...]:
    """The finger catalogue for this design (ids pinned by issue #18)."""
    return _per_joint(design) + _along_finger(range(1, design.n + 1))


def _per_joint(design: FingerModel) -> tuple[FingerEffect, ...]:
    """The effects sized by the design's joints: spring calibration, pin friction, capstan, moment arms."""
    n = design.n
    js = range(1, n + 1)
    K = design.stiffness
    kmin = min(K)
    return (
        FingerEffect(
            "spring_calibration",
            "spring calibration",
            "a printed spring is not the designed one: its stiffness or its preload differ per joint",
            tuple(
                _p(f"stiffness_nmm_per_rad_j{j}", 0.2 * K[j - 1], 5.0 * K[j - 1], 0.85 * K[j - 1], K[j - 1]) for j in js
            )
            + tuple(
                _p(f"preload_deg_j{j}", 0.0, 180.0, design.preload[j - 1] / DEG - 12.0, design.preload[j - 1] / DEG)
                for j in js
            ),
            also=({f"preload_deg_j{j}": max(design.preload[j - 1] / DEG - 45.0, 5.0) for j in js},),
        ),
        FingerEffect(
            "coulomb_pin",
            "Coulomb pin friction",
            "dry friction in each joint's pin: a constant band the tendon must overcome both ways",
            tuple(_p(f"friction_nmm_j{j}", 0.0, 20.0 * kmin, 1.5, 0.0) for j in js),
            also=({f"friction_nmm_j{j}": 8.0 for j in js},),
        ),
        FingerEffect(
            "tendon_pin_friction",
            "tendon-induced pin friction",
            "the tendon's own load presses each pin: friction grows with the spring torque, γ⁺ while "
            "a joint closes, γ⁻ while it opens (paper Eq. 4), shared by the joints",
            (
                _p("gamma_pos_nmm_per_rad", 0.0, 0.9 * kmin, 1.0, 0.0),
                _p("gamma_neg_nmm_per_rad", 0.0, 0.9 * kmin, 1.5, 0.0),
            ),
        ),
        FingerEffect(
            "capstan_path",
            "capstan on the tendon's path to the actuator",
            "the tendon slides over the base before the actuator: the actuator pulls β⁺·T and "
            "releases at β⁻·T; only the tension shows it",
            (_p("beta_pos", 1.0, 3.0, 1.2, 1.0), _p("beta_neg", 0.3, 1.0, 0.8, 1.0)),
            needs="tension",
            needs_text="a tension record (a load cell on the tendon)",
        ),
        FingerEffect(
            "moment_arm",
            "effective moment arms",
            "the tendon runs at another distance from each joint's axis than the built geometry says",
            tuple(
                _p(
                    f"tendon_moment_arm_mm_j{j}",
                    0.3 * design.moment_arm[j - 1],
                    3.0 * design.moment_arm[j - 1],
                    1.15 * design.moment_arm[j - 1],
                    design.moment_arm[j - 1],
                )
                for j in js
            ),
        ),
    )


def _along_finger(js: range) -> tuple[FingerEffect, ...]:
    """The effects of the tendon along the finger, the links' weight, damping and the polymer (joints ``js``)."""
    return (
        FingerEffect(
            "capstan_along_finger",
            "capstan along the finger",
            "the tendon rubs on each eye and support pin past the first joint: the tension drops by "
            "exp(−μα) at every joint it crosses (μα per joint, shared)",
            (_p("mu_alpha", 0.0, 2.0, 0.15, 0.0),),
        ),
        FingerEffect(
            "tendon_stretch",
            "tendon stretch",
            "the tendon is a spring in series: it lengthens by T·c, so the joints close less than the stroke says",
            (_p("tendon_compliance_mm_per_n", 0.0, 10.0, 0.4, 0.0),),
        ),
        FingerEffect(
            "link_weight",
            "link weight",
            "gravity on the links (the experiment's orientation): each joint carries the weight of the "
            "links beyond it; the links' mass is λ per mm of link",
            (_p("link_mass_g_per_mm", 0.0, 5.0, 0.15, 0.0),),
            needs="orientation",
            needs_text="an experiment with the finger's orientation given",
        ),
        FingerEffect(
            "viscous",
            "viscous damping",
            "velocity-proportional damping in each joint (c·θ̇): a joint lags more the faster the tendon moves",
            tuple(_p(f"viscous_nmm_s_per_rad_j{j}", 0.0, 100.0, 0.5, 0.0) for j in js),
            needs="speeds",
            needs_text="moves at several speeds",
        ),
        FingerEffect(
            "stiffening",
            "spring stiffening",
            "each spring stiffens at large wind-up: + k₃·(θ + θ0)³ on its torque",
            tuple(_p(f"cubic_nmm_per_rad3_j{j}", 0.0, 20.0, 0.15, 0.0) for j in js),
        ),
        FingerEffect(
            "relaxation",
            "stress relaxation",
            "viscoelastic relaxation of the printed springs (a Maxwell arm beside each, of stiffness "
            "ρ·K_i and time T_r, shared: one polymer): the joints creep on while the tendon is held",
            (_p("relaxation_ratio", 0.0, 5.0, 0.3, 0.0), _p("relaxation_time_s", 0.5, 1000.0, 1.5, 1.0)),
            needs="holds",
            needs_text="holds (the tendon standing still)",
            also=({"relaxation_time_s": 0.6}, {"relaxation_time_s": 6.0}),
        ),
    )


#: Parameters the finger's simulation does not read: ``actuator_tension`` applies them to its tension afterwards.
AFTER_SIMULATION = frozenset({"beta_pos", "beta_neg"})


def acting_gravity(values: dict[str, float], gravity):
    """The gravity direction ``model_of`` gives the model: ``gravity``, or None when the links weigh nothing."""
    return gravity if float(values.get("link_mass_g_per_mm", 0.0)) > 0 else None


def model_of(values: dict[str, float], design: FingerModel, gravity) -> FingerModel:
    """The finger model with ``values`` (JSON names, every catalogue parameter) under ``gravity`` (or None)."""
    n = design.n
    per = lambda name, default: tuple(float(values.get(f"{name}_j{j}", default[j - 1])) for j in range(1, n + 1))  # noqa: E731
    comp = float(values.get("tendon_compliance_mm_per_n", 0.0))
    lam = float(values.get("link_mass_g_per_mm", 0.0))
    mu = float(values.get("mu_alpha", 0.0))
    K = per("stiffness_nmm_per_rad", design.stiffness)
    cap = lambda g: tuple(min(float(g), 0.95 * k) for k in K)  # noqa: E731  (γ below K: the model requires it)
    return replace(
        design,
        stiffness=K,
        preload=tuple(v * DEG for v in per("preload_deg", [p / DEG for p in design.preload])),
        moment_arm=per("tendon_moment_arm_mm", design.moment_arm),
        friction=per("friction_nmm", [0.0] * n),
        gamma=(),
        gamma_pos=cap(values.get("gamma_pos_nmm_per_rad", 0.0)),
        gamma_neg=cap(values.get("gamma_neg_nmm_per_rad", 0.0)),
        wrap=(0.0,) + (1.0,) * (n - 1),
        mu_t=mu,
        tendon_stiffness=math.inf if comp <= 0 else 1.0 / comp,
        link_mass=tuple(lam * L for L in design.link_length) if lam > 0 else (0.0,) * n,
        gravity=acting_gravity(values, gravity),
        damping=per("viscous_nmm_s_per_rad", [0.0] * n),
        cubic=per("cubic_nmm_per_rad3", [0.0] * n),
        relax_stiffness=tuple(float(values.get("relaxation_ratio", 0.0)) * k for k in K),
        relax_time=float(values.get("relaxation_time_s", 1.0)),
    )


def actuator_tension(values: dict[str, float], T: np.ndarray, pulling: np.ndarray) -> np.ndarray:
    """The tension at the actuator: β⁺·T while pulling, β⁻·T while releasing [N]."""
    return T * np.where(pulling, values.get("beta_pos", 1.0), values.get("beta_neg", 1.0))
