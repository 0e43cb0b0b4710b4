"""The finger model's parameters: one validated, frozen set of per-joint values (re-exported by
``rjcad.physics.finger``, whose compiled solver reads them through the cached arrays here)."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from rjcad.errors import ParameterError

#: N per g: the weight of a 1 g mass [N/g]. Here, not beside the weight's kernels in ``gravity``: a model (and a
#: campaign that names one) is read without importing numba, which alone takes about 0.2 s.
G = 9.81e-3

#: ``FingerModel.arrays()``: (K, θ0, θmax, r, wrap, f0, (γ⁺, γ⁻)).
ModelArrays = tuple[
    np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray]
]


def _frozen(x: Any) -> np.ndarray:
    """A read-only float array of ``x`` (shared by every caller of a model's cached arrays)."""
    a = np.array(x, dtype=float)
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class FingerModel:
    """Per-joint arrays (length N, proximal first), lengths in mm, angles in rad."""

    stiffness: tuple[float, ...]
    preload: tuple[float, ...]
    rotation: tuple[float, ...]
    moment_arm: tuple[float, ...]
    wrap: tuple[float, ...] = ()
    mu_t: float = 0.0
    friction: tuple[float, ...] = ()  # f0_i [N·mm]
    gamma: tuple[float, ...] = ()  # γ_i [N·mm/rad], both directions (shorthand for gamma_pos = gamma_neg)
    link_length: tuple[float, ...] = ()  # axis i to axis i+1 (or the tip) [mm]
    link_mass: tuple[float, ...] = ()  # mass of the child link of joint i [g]
    gravity: tuple[float, float] | None = None  # unit direction of gravity in the finger plane (x, y)
    tendon_stiffness: float = math.inf  # k_t: the tendon stretches T/k_t [N/mm]
    gamma_pos: tuple[float, ...] = ()  # γ⁺_i while joint i closes [N·mm/rad] (default: gamma)
    gamma_neg: tuple[float, ...] = ()  # γ⁻_i while joint i opens [N·mm/rad] (default: gamma)
    damping: tuple[float, ...] = ()  # c_i: viscous damping [N·mm·s/rad]
    cubic: tuple[float, ...] = ()  # k3_i: stiffening, + k3·(θ + θ0)³ [N·mm/rad³]
    relax_stiffness: tuple[float, ...] = ()  # K_M,i: the Maxwell arm's stiffness [N·mm/rad]
    relax_time: float = 1.0  # T_r: the Maxwell arm's time constant, shared (one polymer) [s]
    #: centre of mass of joint i's child link from axis i, in that link's frame (x along the straight finger,
    #: y towards the palm) [mm] (default: (link_length/2, 0), the middle of the link)
    link_com: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        n = len(self.stiffness)
        for name in ("gamma_pos", "gamma_neg"):  # gamma is the shorthand for both; all zeros: not given
            if not getattr(self, name):
                object.__setattr__(self, name, tuple(self.gamma))
            elif any(self.gamma) and tuple(getattr(self, name)) != tuple(self.gamma):
                raise ParameterError(
                    "gamma", self.gamma, f"contradicts {name}: give gamma (both directions) or gamma_pos and gamma_neg"
                )
        if not 1 <= n <= 12:
            raise ParameterError("joints", n, "a finger has 1 to 12 joints")
        for name in ("preload", "rotation", "moment_arm"):
            if len(getattr(self, name)) != n:
                raise ParameterError(name, len(getattr(self, name)), f"needs {n} values, one per joint")
        for name, default in (
            ("wrap", 0.0),
            ("friction", 0.0),
            ("gamma", 0.0),
            ("gamma_pos", 0.0),
            ("gamma_neg", 0.0),
            ("link_length", 40.0),
            ("link_mass", 0.0),
            ("damping", 0.0),
            ("cubic", 0.0),
            ("relax_stiffness", 0.0),
        ):
            v = getattr(self, name)
            if not v:
                object.__setattr__(self, name, tuple([default] * n))
            elif len(v) != n:
                raise ParameterError(name, len(v), f"needs {n} values, one per joint")
        if not self.link_com:
            object.__setattr__(self, "link_com", tuple((L / 2, 0.0) for L in self.link_length))
        elif len(self.link_com) != n or not all(
            len(c) == 2 and all(isinstance(x, (int, float)) and math.isfinite(x) for x in c) for c in self.link_com
        ):
            raise ParameterError("link_com", self.link_com, f"needs {n} finite (x, y) pairs [mm], one per joint")
        for name in (
            "stiffness",
            "preload",
            "rotation",
            "moment_arm",
            "wrap",
            "friction",
            "gamma",
            "gamma_pos",
            "gamma_neg",
            "link_length",
            "link_mass",
            "damping",
            "cubic",
            "relax_stiffness",
        ):
            v = getattr(self, name)
            if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in v):
                raise ParameterError(name, v, "must be finite numbers")
            if min(v) < 0:
                raise ParameterError(name, min(v), "must be >= 0")
        if min(self.rotation) <= 0:
            raise ParameterError("rotation", min(self.rotation), "must be > 0 rad")
        if not (math.isfinite(self.relax_time) and self.relax_time > 0):
            raise ParameterError("relax_time", self.relax_time, "must be > 0 s")
        if not (math.isfinite(self.mu_t) and self.mu_t >= 0):
            raise ParameterError("mu_t", self.mu_t, "must be >= 0")
        if not self.tendon_stiffness > 0:
            raise ParameterError("tendon_stiffness", self.tendon_stiffness, "must be > 0 N/mm")
        if any(k <= 0 for k in self.stiffness):
            raise ParameterError("stiffness", min(self.stiffness), "must be > 0 N·mm/rad")
        if any(r <= 0 for r in self.moment_arm):
            raise ParameterError("moment_arm", min(self.moment_arm), "must be > 0 mm")
        # opening, the joint follows the band's lower edge K·s − γ⁻·s: γ⁻ ≥ K would hold it shut at any tension
        if any(g >= k for g, k in zip(self.gamma_neg, self.stiffness)):
            raise ParameterError("gamma_neg", max(self.gamma_neg), "must stay below each joint's stiffness")

    @property
    def n(self) -> int:
        return len(self.stiffness)

    @property
    def has_gravity(self) -> bool:
        """Whether the links' weight acts (a gravity direction and a link mass)."""
        return self.gravity is not None and any(self.link_mass)

    @property
    def rate_dependent(self) -> bool:
        """Whether the response depends on time (damping or relaxation): a path then needs its times."""
        return any(self.damping) or any(self.relax_stiffness)

    def rate_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """(k3, c, K_M) as arrays and T_r."""
        return self._rate_arrays

    def arrays(self) -> ModelArrays:
        """(K, θ0, θmax, r, wrap, f0, (γ⁺, γ⁻)) as read-only float arrays (made once per model: a path's
        every step reads them)."""
        return self._arrays

    def link_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(link lengths, centre-of-mass x and y in the link frame [mm], weights [N]) as read-only arrays (made once
        per model)."""
        return self._link_arrays

    @functools.cached_property
    def _link_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        lx, ly = np.asarray(self.link_com, dtype=float).reshape(-1, 2).T
        return _frozen(self.link_length), _frozen(lx), _frozen(ly), _frozen(np.asarray(self.link_mass) * G)

    @functools.cached_property
    def _rate_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        return _frozen(self.cubic), _frozen(self.damping), _frozen(self.relax_stiffness), float(self.relax_time)

    @functools.cached_property
    def _arrays(self) -> ModelArrays:
        f = _frozen
        return (
            f(self.stiffness),
            f(self.preload),
            f(self.rotation),
            f(self.moment_arm),
            f(self.wrap),
            f(self.friction),
            (f(self.gamma_pos), f(self.gamma_neg)),
        )
