"""Spiral torsion spring formulas, the closed form: pure and numpy-vectorised (they broadcast over arrays).

Imports nothing from rjcad, so that any module (``rjcad.life`` among them) can use them.
Units: mm, N, N·mm, rad, MPa (= N/mm²). ``K`` is the stiffness of one spring.

The designer no longer rests on these: its stiffness, stress and coil gap come from the rod model
(``rjcad.spring.rod``, its surrogate ``rjcad.spring.factors``); the closed form is reported beside
it (``formula_stiffness``), and the length and turns of the Archimedean spiral are exact.

End conditions (the outer end; the inner end is always fused to the pin):

- ``clamped``: K = E·b·t³/(12·L), peak moment = T, σ = 6·T/(b·t²).
- ``pinned``: the outer end hooks on a pin and is free to turn about it (Wahl,
  *Mechanical Springs*): compliance ≈ 1.25× clamped, so K ≈ 0.8·E·b·t³/(12·L),
  and the peak moment ≈ 2·T.

Centreline: the Archimedean spiral r(φ) = r_in + p·φ/(2π), φ ∈ [0, 2π·n]. The handbook's
wound pitch (``wound_pitch``, ``coil_gap``) assumes a tightened spiral stays concentric and gains
θ/2π turns; it does not (the outer end's reaction pushes the coil pack sideways, issue #14), so
the designer uses the rod model's gap instead.
"""

from __future__ import annotations

import math
from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

TWO_PI = 2.0 * math.pi

#: A number or an array of them: every formula here broadcasts, and gives back the same kind.
Value: TypeAlias = float | npt.NDArray[np.floating[Any]]

#: Outer-end conditions: (stiffness factor on E·b·t³/(12L), peak-moment factor on T).
END_CONDITIONS: dict[str, tuple[float, float]] = {"clamped": (1.0, 1.0), "pinned": (0.8, 2.0)}
#: The designer's default outer end: clamped (the paper's measured stiffness, 5.19 for 5.2 designed with
#: the clamped formula, says its hooks behaved clamped; docs/spring-model.md).
DEFAULT_END = "clamped"


def end_factors(end: str) -> tuple[float, float]:
    """(stiffness factor, peak-moment factor) of an end condition; ValueError naming the known ones."""
    try:
        return END_CONDITIONS[end]
    except KeyError:
        raise ValueError(f"end = {end!r} is invalid: known end conditions: {', '.join(END_CONDITIONS)}") from None


def stiffness(E: Value, b: Value, t: Value, L: Value, end: str = "clamped") -> Value:
    """Torsional stiffness of one spring, K = c_end·E·b·t³/(12·L) [N·mm/rad].

    c_end = 1 (clamped) or 0.8 (pinned). E in MPa, b, t, L in mm.
    """
    k_end, _ = end_factors(end)
    return k_end * E * b * t**3 / (12.0 * L)


def length_for_stiffness(K: Value, E: Value, b: Value, t: Value, end: str = "clamped") -> Value:
    """Active length giving stiffness K, L = c_end·E·b·t³/(12·K) [mm]."""
    k_end, _ = end_factors(end)
    return k_end * E * b * t**3 / (12.0 * K)


def peak_stress(torque: Value, b: Value, t: Value, end: str = "clamped") -> Value:
    """Peak bending stress for spring torque T, σ = m_end·6·T/(b·t²) [MPa].

    m_end = 1 (clamped) or 2 (pinned, Wahl). T in N·mm.
    """
    _, m_end = end_factors(end)
    return m_end * 6.0 * torque / (b * t**2)


def windup_stress(E: Value, b: Value, t: Value, L: Value, theta: Value, end: str = "clamped") -> Value:
    """Peak stress at total wind-up θ (rad) from the printed shape [MPa].

    σ = m_end·6·K·θ/(b·t²); clamped this is E·t·θ/(2L), pinned 0.8·E·t·θ/L.
    """
    return peak_stress(stiffness(E, b, t, L, end) * theta, b, t, end)


def stress_amplitude(K: Value, rotation: Value, b: Value, t: Value, end: str = "clamped") -> Value:
    """Stress amplitude of a cycle of ``rotation`` (rad) on any preload, σ_a = m_end·6·K·rotation/(2·b·t²) [MPa].

    Half the stress swing: the stress is linear in the wind-up, so the preload drops out.
    """
    return peak_stress(K * rotation, b, t, end) / 2


def archimedean_length(r_in: Value, pitch: Value, turns: Value) -> Value:
    """Exact centreline length of r(φ) = r_in + p·φ/(2π), φ ∈ [0, 2πn] [mm].

    With k = p/(2π) and u = r/k: L = (k/2)·[u·√(u²+1) + asinh u] from u_in to u_out.
    """
    k = pitch / TWO_PI
    u0 = r_in / k
    u1 = u0 + TWO_PI * turns

    def prim(u: Value) -> Value:
        return u * np.sqrt(u * u + 1.0) + np.arcsinh(u)

    return 0.5 * k * (prim(u1) - prim(u0))


def approx_length(r_in: Value, pitch: Value, turns: Value) -> Value:
    """Mean-radius length approximation, L ≈ 2π·n·r_in + π·p·n² [mm]."""
    return TWO_PI * turns * r_in + math.pi * pitch * turns**2


def outer_radius(r_in: Value, pitch: Value, turns: Value) -> Value:
    """Centreline radius at the outer end, r_out = r_in + p·n [mm]."""
    return r_in + pitch * turns


def turns_for_length(L: Value, r_in: Value, pitch: Value, iterations: int = 6) -> Value:
    """Turns n whose exact Archimedean length is L (Newton on L(n)) [-].

    Starts from the mean-radius approximation, which overestimates n; L(n) is
    convex, so Newton converges monotonically from there.
    """
    L, r_in, pitch = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (L, r_in, pitch)))
    n = (-r_in + np.sqrt(r_in**2 + pitch * L / math.pi)) / pitch
    k = pitch / TWO_PI
    for _ in range(iterations):
        r_out = r_in + pitch * n
        n = n - (archimedean_length(r_in, pitch, n) - L) / (TWO_PI * np.sqrt(r_out**2 + k**2))
    return n


def wound_pitch(r_in: Value, pitch: Value, turns: Value, windup: Value) -> Value:
    """Pitch after tightening by θ (rad): (r_out − r_in)/(n + θ/2π) [mm]."""
    return pitch * turns / (turns + windup / TWO_PI)


def coil_gap(r_in: Value, pitch: Value, turns: Value, t: Value, windup: Value) -> Value:
    """Gap between neighbouring coils at wind-up θ, wound pitch − t [mm]."""
    return wound_pitch(r_in, pitch, turns, windup) - t
