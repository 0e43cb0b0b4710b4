"""The effect catalogue: candidate physical effects, as small strategy classes.

Each effect names its physical cause, its parameters (JSON names, pinned by issue #7),
the JointModel fields they set, bounds, a typical size (used by the synthetic bench), the
start points a fit of it begins from, and what a campaign needs to show it.
Units inside are the JointModel's (rad, N·mm); JSON values use the units in their names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rjcad import DEG
from rjcad.errors import ParameterError
from rjcad.paper import JOINT


@dataclass(frozen=True)
class Param:
    """One parameter: JSON ``name``, JointModel ``field``, json→model ``scale``, bounds and typical value (JSON units).

    ``lower``/``upper``/``typical`` may be callables of the design (stiffness, preload_deg) when they scale with it.
    """

    name: str
    field: str
    scale: float
    lower: float | None
    upper: float | None
    typical: float | None
    neutral: float  # value (JSON units) when the effect is absent

    def to_model(self, value: float) -> float:
        return value * self.scale

    def to_json(self, value: float) -> float:
        return value / self.scale


@dataclass(frozen=True)
class Limit:
    """Where an effect reduces to a simpler one: with ``param`` at its limit the effect is ``simpler`` (an effect
    id, or "" for none) with the parameters ``start`` gives from the fitted values (JSON units); ``words`` say so."""

    param: str
    simpler: str
    words: str

    def start(self, values: dict[str, float]) -> dict[str, float]:
        if self.simpler == "viscous":  # a Maxwell arm with T_r → 0: c = K_M·T_r
            return {"viscous_nmm_s_per_rad": values["relaxation_stiffness_nmm_per_rad"] * values["relaxation_time_s"]}
        return {}


class Effect:
    """A candidate effect. Subclasses set ``id``, ``cause``, ``params``, ``needs`` and ``needs_text``; ``limits``:
    where it reduces to a simpler effect (nested models, tried once the selection is done)."""

    limits: tuple[Limit, ...] = ()

    id: str = ""
    name: str = ""  # short name of the cause, e.g. "Coulomb pin friction"
    cause: str = ""
    params: tuple[Param, ...] = ()
    #: what kind of experiment carries the effect: "any", "normal_load", "tendon", "routed", "holds", "speeds",
    #: "bearing" (a tendon drive on a joint whose geometry the campaign names)
    needs: str = "any"
    #: ``needs`` in words, completing "it needs …" ("" when any experiment will do)
    needs_text: str = ""

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    def typical(self, design: dict) -> dict:
        """Realistic parameter values (JSON units) for a bench campaign of this ``design``."""
        return {p.name: p.typical for p in self.params}

    def bounds(self, design: dict) -> tuple[list[float], list[float]]:
        lo = [(-math.inf if p.lower is None else p.lower) for p in self.params]
        hi = [(math.inf if p.upper is None else p.upper) for p in self.params]
        return lo, hi

    def neutral(self, design: dict) -> dict:
        return {p.name: p.neutral for p in self.params}

    def starts(self, design: dict) -> list[dict]:
        """Start points (JSON units) of a fit that adds this effect: its typical sizes."""
        return [self.typical(design)]

    def __repr__(self) -> str:
        return f"<{self.id}: {', '.join(self.param_names)}>"


class SpringCalibration(Effect):
    id = "spring_calibration"
    name = "spring calibration"
    cause = (
        "the printed spring is not the designed one: its modulus, rod thickness or the preload "
        "set at assembly differ, so the stiffness and the zero-torque angle move"
    )
    params = (
        Param("stiffness_nmm_per_rad", "stiffness", 1.0, None, None, None, 0.0),
        Param("preload_deg", "preload", DEG, -90.0, 360.0, None, 0.0),
    )

    def typical(self, design):
        return {
            "stiffness_nmm_per_rad": 0.85 * design["stiffness_nmm_per_rad"],
            "preload_deg": design["preload_deg"] + 8.0,
        }

    def bounds(self, design):
        k = design["stiffness_nmm_per_rad"]
        return [0.2 * k, -90.0], [5.0 * k, 360.0]

    def neutral(self, design):
        return {"stiffness_nmm_per_rad": design["stiffness_nmm_per_rad"], "preload_deg": design["preload_deg"]}

    def starts(self, design):
        """The design itself: the fit moves it only as far as the data ask."""
        return [self.neutral(design)]


class CoulombPin(Effect):
    id = "coulomb_pin"
    name = "Coulomb pin friction"
    cause = (
        "Coulomb friction in the pin under the transverse load: a torque ±μ_j·F_n that opposes "
        "the motion, the same at every angle"
    )
    needs = "normal_load"
    needs_text = "an experiment with a transverse load F_n > 0"
    params = (Param("mu_j_mm", "mu_j", 1.0, 0.0, 60.0, JOINT.mu_j, 0.0),)


class TendonPinFriction(Effect):
    id = "tendon_pin_friction"
    name = "tendon-induced pin friction"
    cause = (
        "pin friction from the tendon's own load: the tendon presses the pin harder as the spring "
        "winds up, so the friction grows with the deflection (paper Eq. 4)"
    )
    needs = "tendon"
    needs_text = "a tendon-driven experiment"
    params = (
        Param("gamma_pos_nmm_per_rad", "gamma_pos", 1.0, 0.0, 50.0, JOINT.gamma_pos, 0.0),
        Param("gamma_neg_nmm_per_rad", "gamma_neg", 1.0, 0.0, 50.0, JOINT.gamma_neg, 0.0),
    )


class CapstanPath(Effect):
    id = "capstan_path"
    name = "capstan friction on the tendon path"
    cause = (
        "tendon friction on its path through the base link (capstan, paper Eq. 5–7): pulling "
        "costs a factor β⁺ more force at the actuator, releasing a factor β⁻ less"
    )
    needs = "routed"
    needs_text = "a tendon routed through the base link"
    params = (
        Param("beta_pos", "beta_pos", 1.0, 1.0, 4.0, JOINT.beta_pos, 1.0),
        Param("beta_neg", "beta_neg", 1.0, 0.1, 1.0, JOINT.beta_neg, 1.0),
    )


class BearingFriction(Effect):
    id = "bearing_friction"
    name = "bearing friction from the joint's geometry"
    cause = (
        "dry friction in the joint's own bearing: the tendon's pull and the springs' end forces press the bearing "
        "surfaces of the printed joint (cones, collar, pin), and one material-pair μ turns their normal forces "
        "into a torque μ·Σ N_i·ρ_i (rjcad.physics.bearing)"
    )
    needs = "bearing"
    needs_text = "a tendon-driven experiment and the joint's manifest ([design] joint)"
    params = (Param("bearing_mu", "mu_bearing", 1.0, 0.0, 2.0, 0.4, 0.0),)

    def starts(self, design):
        """μ at 0.15, 0.4 and 1.0: dry plastic on plastic is 0.2–0.6, the paper's bar test asks for 1.46."""
        return [{"bearing_mu": mu} for mu in (0.15, 0.4, 1.0)]


class Viscous(Effect):
    id = "viscous"
    name = "viscous damping"
    cause = "velocity-proportional damping (c·θ̇): the friction band widens when the joint moves faster"
    needs = "speeds"
    needs_text = "moves at several speeds"
    params = (Param("viscous_nmm_s_per_rad", "viscous", 1.0, 0.0, 100.0, 0.5, 0.0),)


class Stiffening(Effect):
    id = "stiffening"
    name = "spring stiffening"
    cause = (
        "the spring stiffens at large wind-up (coils touching, large-deflection geometry): "
        "the torque grows faster than linearly, +k₃·θ³ on the total spring deformation"
    )
    params = (Param("cubic_nmm_per_rad3", "cubic", 1.0, 0.0, 20.0, 0.15, 0.0),)
    limits = (Limit("cubic_nmm_per_rad3", "", "stiffening with k₃ → 0 is no stiffening"),)


class Relaxation(Effect):
    id = "relaxation"
    name = "stress relaxation"
    cause = (
        "viscoelastic stress relaxation of the printed polymer (a Maxwell arm beside the spring): "
        "the torque overshoots after a move and decays while the joint is held"
    )
    needs = "holds"
    needs_text = "holds (the joint standing still)"
    params = (
        Param("relaxation_stiffness_nmm_per_rad", "relaxation_stiffness", 1.0, 0.0, 200.0, 1.5, 0.0),
        Param("relaxation_time_s", "relaxation_time", 1.0, 0.5, 1000.0, 1.5, 1.0),
    )
    limits = (
        Limit("relaxation_time_s", "viscous", "a Maxwell arm with T_r → 0 is a viscous damper, c = K_M·T_r"),
        Limit("relaxation_stiffness_nmm_per_rad", "", "a Maxwell arm with K_M → 0 does nothing"),
    )
    # T_r ≥ 0.5 s: a Maxwell arm much faster than that acts as damping (c = K_M·T_r) on bench data whose
    # velocity is smoothed over 0.15 s, and would compete with `viscous` by filtering the velocity noise.

    def starts(self, design):
        """The typical sizes with T_r at 0.6, 1.5 and 6 s: the fit in T_r has local minima."""
        return [dict(self.typical(design), relaxation_time_s=tr) for tr in (0.6, 1.5, 6.0)]


#: The catalogue, in a fixed order (ties in selection are broken by this order).
CATALOGUE: tuple[Effect, ...] = (
    SpringCalibration(),
    CoulombPin(),
    TendonPinFriction(),
    CapstanPath(),
    BearingFriction(),
    Viscous(),
    Stiffening(),
    Relaxation(),
)
EFFECTS: dict[str, Effect] = {e.id: e for e in CATALOGUE}
#: JSON parameter name → (effect, Param)
PARAMS: dict[str, tuple[Effect, Param]] = {p.name: (e, p) for e in CATALOGUE for p in e.params}


def effect(effect_id: str) -> Effect:
    """The catalogue entry ``effect_id``, or a ParameterError listing the known ids."""
    try:
        return EFFECTS[effect_id]
    except KeyError:
        raise ParameterError("effect", effect_id, f"unknown effect; known: {', '.join(EFFECTS)}") from None


def model_kwargs(values: dict[str, float]) -> dict[str, float]:
    """JSON-named parameter values → JointModel keyword arguments (model units)."""
    out = {}
    for name, v in values.items():
        if name not in PARAMS:
            raise ParameterError("parameter", name, f"unknown; known: {', '.join(PARAMS)}")
        p = PARAMS[name][1]
        out[p.field] = p.to_model(float(v))
    return out


def json_values(model, names) -> dict[str, float]:
    """The JSON-named parameters ``names`` read from a JointModel (JSON units)."""
    return {n: PARAMS[n][1].to_json(getattr(model, PARAMS[n][1].field)) for n in names}
