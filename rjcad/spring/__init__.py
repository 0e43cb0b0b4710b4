"""Spiral torsion spring (STS): model and optimiser.

Model functions are pure and numpy-vectorised (they broadcast over arrays).
Units: mm, N, N·mm, rad, MPa (= N/mm²).

Conventions
-----------
* ``K`` is the torsional stiffness of one spring. A joint has two springs in
  parallel, so a joint of stiffness ``K_joint`` uses springs of ``K_joint/2``.
* End conditions (the outer end; the inner end is always fused to the pin):

  - ``clamped``: K = E·b·t³/(12·L), peak moment = T, σ = 6·T/(b·t²).
  - ``pinned``: the outer end hooks on a pin and is free to turn about it
    (Wahl, *Mechanical Springs*): compliance ≈ 1.25× clamped, so
    K ≈ 0.8·E·b·t³/(12·L), and the peak moment ≈ 2·T.

  rjcad's default is ``pinned``: the paper's springs hook on a cylindrical
  protrusion of the moving link.
* Centreline geometry is an Archimedean spiral r(φ) = r_in + p·φ/(2π),
  φ ∈ [0, 2π·n]. Wind-up (preload + joint rotation) *tightens* the spiral.
* Coil gap at wind-up θ: the wound spiral keeps its end radii and gains θ/2π
  turns, so the pitch becomes (r_out − r_in)/(n + θ/2π) and the gap between
  neighbouring coils is that pitch minus t. The linear law holds until coils
  touch, so the optimiser keeps this gap ≥ the printer's minimum gap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rjcad.errors import InfeasibleDesign, ParameterError
from rjcad.materials import (
    DEFAULT_MATERIAL,
    DEFAULT_PRINTER,
    Material,
    Printer,
    get_material,
    get_printer,
)

TWO_PI = 2.0 * math.pi

#: Outer-end conditions: (stiffness factor on E·b·t³/(12L), peak-moment factor on T).
END_CONDITIONS: dict[str, tuple[float, float]] = {
    "clamped": (1.0, 1.0),
    "pinned": (0.8, 2.0),
}
DEFAULT_END = "pinned"

#: Thin-strip validity: the innermost centreline radius is at least this many t.
MIN_RADIUS_TO_THICKNESS = 3.0
#: A strip, not a plate on edge: width b is at least this many t.
MIN_WIDTH_TO_THICKNESS = 2.0
#: Stiffness tolerance the optimiser guarantees (relative).
STIFFNESS_TOLERANCE = 0.005


def _end_factors(end: str) -> tuple[float, float]:
    try:
        return END_CONDITIONS[end]
    except KeyError:
        raise ParameterError("end", end, f"known end conditions: {', '.join(END_CONDITIONS)}") from None


# --------------------------------------------------------------------------
# Model: pure, vectorised
# --------------------------------------------------------------------------


def stiffness(E, b, t, L, end: str = "clamped"):
    """Torsional stiffness of one spring, K = c_end·E·b·t³/(12·L) [N·mm/rad].

    c_end = 1 (clamped) or 0.8 (pinned). E in MPa, b, t, L in mm.
    """
    k_end, _ = _end_factors(end)
    return k_end * E * b * t**3 / (12.0 * L)


def length_for_stiffness(K, E, b, t, end: str = "clamped"):
    """Active length giving stiffness K, L = c_end·E·b·t³/(12·K) [mm]."""
    k_end, _ = _end_factors(end)
    return k_end * E * b * t**3 / (12.0 * K)


def peak_stress(torque, b, t, end: str = "clamped"):
    """Peak bending stress for spring torque T, σ = m_end·6·T/(b·t²) [MPa].

    m_end = 1 (clamped) or 2 (pinned, Wahl). T in N·mm.
    """
    _, m_end = _end_factors(end)
    return m_end * 6.0 * torque / (b * t**2)


def windup_stress(E, b, t, L, theta, end: str = "clamped"):
    """Peak stress at total wind-up θ (rad) from the printed shape [MPa].

    σ = m_end·6·K·θ/(b·t²); clamped this is E·t·θ/(2L), pinned 0.8·E·t·θ/L.
    """
    return peak_stress(stiffness(E, b, t, L, end) * theta, b, t, end)


def archimedean_length(r_in, pitch, turns):
    """Exact centreline length of r(φ) = r_in + p·φ/(2π), φ ∈ [0, 2πn] [mm].

    With k = p/(2π) and u = r/k: L = (k/2)·[u·√(u²+1) + asinh u] from u_in to u_out.
    """
    k = pitch / TWO_PI
    u0 = r_in / k
    u1 = u0 + TWO_PI * turns

    def prim(u):
        return u * np.sqrt(u * u + 1.0) + np.arcsinh(u)

    return 0.5 * k * (prim(u1) - prim(u0))


def approx_length(r_in, pitch, turns):
    """Mean-radius length approximation, L ≈ 2π·n·r_in + π·p·n² [mm]."""
    return TWO_PI * turns * r_in + math.pi * pitch * turns**2


def outer_radius(r_in, pitch, turns):
    """Centreline radius at the outer end, r_out = r_in + p·n [mm]."""
    return r_in + pitch * turns


def turns_for_length(L, r_in, pitch, iterations: int = 6):
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


def wound_pitch(r_in, pitch, turns, windup):
    """Pitch after tightening by θ (rad): (r_out − r_in)/(n + θ/2π) [mm]."""
    return pitch * turns / (turns + windup / TWO_PI)


def coil_gap(r_in, pitch, turns, t, windup):
    """Gap between neighbouring coils at wind-up θ, wound pitch − t [mm]."""
    return wound_pitch(r_in, pitch, turns, windup) - t


# --------------------------------------------------------------------------
# Requirement and design
# --------------------------------------------------------------------------


def _finite(x) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


@dataclass(frozen=True)
class SpringRequirement:
    """What the user asks of one joint; validated on construction.

    Angles in rad. ``joint_stiffness`` is the sum of the twin springs (N·mm/rad).
    """

    joint_stiffness: float
    rotation: float
    preload: float = math.pi / 2
    material: str = DEFAULT_MATERIAL
    printer: str = DEFAULT_PRINTER
    safety_factor: float = 1.5
    end: str = DEFAULT_END
    width_min: float = 1.0
    width_max: float = 10.0
    inner_radius_min: float = 3.0
    inner_radius_max: float = 10.0
    outer_radius_max: float = 20.0
    min_turns: float = 1.0
    min_cycles: float | None = None
    backlash: float = 0.25

    def __post_init__(self):
        def need(name, value, ok, limit, deg=False):
            if not _finite(value) or not ok(float(value)):
                if deg and _finite(value):
                    raise ParameterError(name, math.degrees(float(value)), limit, unit="deg")
                raise ParameterError(name, value, limit)

        need("stiffness", self.joint_stiffness, lambda v: 0 < v <= 1e4,
             "must be > 0 and <= 10000 N·mm/rad (joint, both springs)")
        need("rotation", self.rotation, lambda v: 0 < v <= TWO_PI + 1e-12,
             "must be > 0 and <= 360 deg", deg=True)
        need("preload", self.preload, lambda v: 0 <= v <= TWO_PI + 1e-12,
             "must be >= 0 and <= 360 deg", deg=True)
        need("safety_factor", self.safety_factor, lambda v: 1.0 <= v <= 100.0,
             "must be >= 1 and <= 100")
        for name in ("width_min", "width_max", "inner_radius_min", "inner_radius_max",
                     "outer_radius_max"):
            need(name, getattr(self, name), lambda v: 0 < v <= 1000, "must be > 0 and <= 1000 mm")
        need("width_max", self.width_max, lambda v: v >= self.width_min,
             f"must be >= width_min = {self.width_min} mm")
        need("inner_radius_max", self.inner_radius_max, lambda v: v >= self.inner_radius_min,
             f"must be >= inner_radius_min = {self.inner_radius_min} mm")
        need("min_turns", self.min_turns, lambda v: 0.25 <= v <= 100, "must be >= 0.25 and <= 100")
        if self.min_cycles is not None:
            need("min_cycles", self.min_cycles, lambda v: 1 <= v <= 1e9, "must be >= 1 and <= 1e9 cycles")
        need("backlash", self.backlash, lambda v: 0.05 <= v <= 1.5, "must be >= 0.05 and <= 1.5 mm")
        _end_factors(self.end)
        object.__setattr__(self, "material", get_material(self.material).key)
        object.__setattr__(self, "printer", get_printer(self.printer).key)

    @property
    def material_spec(self) -> Material:
        return get_material(self.material)

    @property
    def printer_spec(self) -> Printer:
        return get_printer(self.printer)

    @property
    def spring_stiffness(self) -> float:
        """Stiffness of one of the twin springs, K_joint/2 [N·mm/rad]."""
        return self.joint_stiffness / 2.0

    @property
    def max_windup(self) -> float:
        """Total wind-up from the printed shape, preload + rotation [rad]."""
        return self.preload + self.rotation

    @property
    def allowed_stress(self) -> float:
        """Yield / safety factor [MPa]."""
        return self.material_spec.yield_strength_mpa / self.safety_factor


@dataclass(frozen=True)
class SpringDesign:
    """One spiral spring of a twin-spring joint. Lengths in mm, angles in rad."""

    width: float
    thickness: float
    length: float
    inner_radius: float
    pitch: float
    turns: float
    requirement: SpringRequirement = field(repr=False)

    # --- derived, all from the model functions -----------------------------
    @property
    def end(self) -> str:
        return self.requirement.end

    @property
    def centreline_outer_radius(self) -> float:
        """r_in + p·n [mm]."""
        return float(outer_radius(self.inner_radius, self.pitch, self.turns))

    @property
    def outer_radius(self) -> float:
        """Encumbrance: outer centreline radius + t/2 [mm] (hook not included)."""
        return self.centreline_outer_radius + self.thickness / 2.0

    @property
    def spring_stiffness(self) -> float:
        E = self.requirement.material_spec.youngs_modulus_mpa
        return float(stiffness(E, self.width, self.thickness, self.length, self.end))

    @property
    def joint_stiffness(self) -> float:
        return 2.0 * self.spring_stiffness

    @property
    def max_stress(self) -> float:
        """Peak stress at preload + rotation [MPa]."""
        E = self.requirement.material_spec.youngs_modulus_mpa
        return float(windup_stress(E, self.width, self.thickness, self.length,
                                   self.requirement.max_windup, self.end))

    @property
    def preload_stress(self) -> float:
        E = self.requirement.material_spec.youngs_modulus_mpa
        return float(windup_stress(E, self.width, self.thickness, self.length,
                                   self.requirement.preload, self.end))

    @property
    def min_coil_gap(self) -> float:
        """Coil gap at maximum wind-up [mm]."""
        return float(coil_gap(self.inner_radius, self.pitch, self.turns, self.thickness,
                              self.requirement.max_windup))

    @property
    def print_coil_gap(self) -> float:
        """Coil gap as printed (no wind-up), p − t [mm]."""
        return self.pitch - self.thickness

    @property
    def stress_amplitude(self) -> float:
        """Stress amplitude of the working cycle, preload → preload + rotation [MPa]."""
        E = self.requirement.material_spec.youngs_modulus_mpa
        K = stiffness(E, self.width, self.thickness, self.length, self.end)
        return float(peak_stress(K * self.requirement.rotation, self.width, self.thickness, self.end)) / 2

    def predicted_life(self) -> tuple[float, float, float]:
        """Median cycles and 90 % interval from the Table I life model (rjcad.life)."""
        from rjcad import life

        med, lo, hi = life.predict_cycles(self.stress_amplitude, self.thickness, self.requirement.backlash)
        return float(med[0]), float(lo[0]), float(hi[0])

    def constraint_report(self) -> dict[str, tuple[float, float, bool]]:
        """Every constraint as name → (value, limit, met)."""
        req = self.requirement
        pr = req.printer_spec
        steps = self.thickness / pr.thickness_step_mm
        k_err = abs(self.spring_stiffness / req.spring_stiffness - 1.0)
        tol = 1e-9
        extra = {}
        if req.min_cycles is not None:
            lo = self.predicted_life()[1]
            extra["life_lower_cycles"] = (lo, req.min_cycles, lo >= req.min_cycles * (1 - 1e-6))
        return {**extra,
            "stiffness_error": (k_err, STIFFNESS_TOLERANCE, k_err <= STIFFNESS_TOLERANCE),
            "stress_mpa": (self.max_stress, req.allowed_stress, self.max_stress <= req.allowed_stress * (1 + tol)),
            "min_wall_mm": (self.thickness, pr.min_wall_mm, self.thickness >= pr.min_wall_mm - tol),
            "thickness_steps": (steps, round(steps), abs(steps - round(steps)) < 1e-6),
            "coil_gap_mm": (self.min_coil_gap, pr.min_gap_mm, self.min_coil_gap >= pr.min_gap_mm - tol),
            "turns": (self.turns, req.min_turns, self.turns >= req.min_turns - tol),
            "width_min_mm": (self.width, max(req.width_min, MIN_WIDTH_TO_THICKNESS * self.thickness),
                             self.width >= max(req.width_min, MIN_WIDTH_TO_THICKNESS * self.thickness) - tol),
            "width_max_mm": (self.width, req.width_max, self.width <= req.width_max + tol),
            "inner_radius_min_mm": (self.inner_radius,
                                    max(req.inner_radius_min, MIN_RADIUS_TO_THICKNESS * self.thickness),
                                    self.inner_radius >= max(req.inner_radius_min,
                                                             MIN_RADIUS_TO_THICKNESS * self.thickness) - tol),
            "inner_radius_max_mm": (self.inner_radius, req.inner_radius_max,
                                    self.inner_radius <= req.inner_radius_max + tol),
            "outer_radius_mm": (self.outer_radius, req.outer_radius_max,
                                self.outer_radius <= req.outer_radius_max + tol),
        }

    def to_dict(self) -> dict:
        """The pinned JSON keys of ``rjcad spring --json`` (and a few more)."""
        req = self.requirement
        K = self.spring_stiffness
        return {
            "width_mm": self.width,
            "thickness_mm": self.thickness,
            "length_mm": self.length,
            "inner_radius_mm": self.inner_radius,
            "pitch_mm": self.pitch,
            "turns": self.turns,
            "outer_radius_mm": self.outer_radius,
            "centreline_outer_radius_mm": self.centreline_outer_radius,
            "spring_stiffness_nmm_per_rad": K,
            "joint_stiffness_nmm_per_rad": 2.0 * K,
            "max_stress_mpa": self.max_stress,
            "allowed_stress_mpa": req.allowed_stress,
            "preload_stress_mpa": self.preload_stress,
            "min_coil_gap_mm": self.min_coil_gap,
            "print_coil_gap_mm": self.print_coil_gap,
            "preload_torque_nmm": 2.0 * K * req.preload,
            "max_torque_nmm": 2.0 * K * req.max_windup,
            "material": req.material,
            "printer": req.printer,
            "end": req.end,
            "safety_factor": req.safety_factor,
            "rotation_deg": math.degrees(req.rotation),
            "preload_deg": math.degrees(req.preload),
            "requested_joint_stiffness_nmm_per_rad": req.joint_stiffness,
            "stress_amplitude_mpa": self.stress_amplitude,
            "backlash_mm": req.backlash,
            "min_cycles": req.min_cycles,
            **self._life_keys(),
        }

    def _life_keys(self) -> dict:
        med, lo, hi = self.predicted_life()
        return {"predicted_cycles": med, "predicted_cycles_interval": [lo, hi],
                "life_model": "rjcad.life: Table I (ABSplus-P430, b = 4.8 mm, Dimension Elite), 90 % interval; "
                              "an extrapolation for other materials and printers"}


# --------------------------------------------------------------------------
# Optimiser
# --------------------------------------------------------------------------

#: Constraint names, in the order of the ``binding`` codes of :func:`optimise_arrays`.
CONSTRAINTS = ("stress", "turns", "outer_radius", "inner_radius", "coil_gap", "width", "life")

#: Thickest strip the optimiser tries [mm].
MAX_THICKNESS = 3.0


def thickness_candidates(printer: Printer, t_max: float = MAX_THICKNESS) -> np.ndarray:
    """Printable thicknesses: whole multiples of the printer's step, ≥ min wall, ≤ t_max [mm]."""
    step = printer.thickness_step_mm
    k0 = math.ceil(printer.min_wall_mm / step - 1e-9)
    k1 = math.floor(t_max / step + 1e-9)
    return np.round(np.arange(k0, k1 + 1) * step, 9)


def _snap_up(x, step):
    return np.round(np.ceil(x / step - 1e-9) * step, 9)


def _snap_down(x, step):
    return np.round(np.floor(x / step + 1e-9) * step, 9)


def _solve_pitch(L, r_in, c, a, iterations: int = 40):
    """Smallest pitch p whose wound pitch reaches c: p·n/(n + a) = c, with n = n(L, r_in, p).

    Fixed point p = c·(1 + a/n(p)), started from the mean-radius closed form.
    Returns (p, n) with the wound pitch ≥ c (p nudged up by 1e-9 relative).
    """
    # Closed form under L ≈ 2πn·r_in + πp·n² and p·n = c(n + a):
    B = TWO_PI * r_in + math.pi * c * a
    n = (-B + np.sqrt(B * B + 4.0 * math.pi * c * L)) / (TWO_PI * c)
    p = c * (n + a) / n
    for _ in range(iterations):
        n = turns_for_length(L, r_in, p)
        p_new = c * (n + a) / n
        done = np.all(np.abs(p_new - p) <= 1e-13 * p)
        p = p_new
        if done:
            break
    p = p * (1.0 + 1e-9)
    return p, turns_for_length(L, r_in, p)


def optimise_arrays(
    spring_stiffness,
    max_windup,
    *,
    material: Material,
    printer: Printer,
    allowed_stress,
    end: str = DEFAULT_END,
    width_min: float = 1.0,
    width_max: float = 10.0,
    inner_radius_min: float = 3.0,
    inner_radius_max: float = 10.0,
    outer_radius_max: float = 20.0,
    min_turns: float = 1.0,
    rotation=None,
    min_cycles: float | None = None,
    backlash: float = 0.25,
) -> dict[str, np.ndarray]:
    """Vectorised optimiser over D requirements; smallest outer radius per row.

    For every printable thickness t (axis T) the best spring is closed-form:
    the inner radius at its lower bound, the width b at the smallest layer
    multiple meeting stress (b ≥ 6·m·K·θ/(t²·σ_allow)) and minimum turns,
    L = c_end·E·b·t³/(12K), and the pitch the smallest whose wound coil gap
    reaches the printer's minimum gap. Then the thinnest-envelope t wins.

    Returns arrays of shape (D,): width, thickness, length, inner_radius,
    pitch, turns, outer_radius (envelope), feasible, binding (index into
    :data:`CONSTRAINTS`, −1 when feasible) and the binding constraint's
    value, limit and thickness for the error message.
    """
    k_end, m_end = _end_factors(end)
    E = material.youngs_modulus_mpa
    K = np.atleast_1d(np.asarray(spring_stiffness, dtype=float))[:, None]
    theta = np.atleast_1d(np.asarray(max_windup, dtype=float))[:, None]
    K, theta = np.broadcast_arrays(K, theta)
    s_allow = np.broadcast_to(np.atleast_1d(np.asarray(allowed_stress, dtype=float))[:, None], K.shape)
    t = thickness_candidates(printer)[None, :]
    shape = np.broadcast_shapes(K.shape, t.shape)
    K, theta, s_allow, t = (np.broadcast_to(x, shape) for x in (K, theta, s_allow, t))

    layer = printer.layer_height_mm
    g_min = printer.min_gap_mm
    c = t + g_min
    a = theta / TWO_PI

    r_in = np.maximum(inner_radius_min, MIN_RADIUS_TO_THICKNESS * t)
    # Width needed for stress and for the minimum number of turns.
    b_stress = m_end * 6.0 * K * theta / (t**2 * s_allow)
    p_turns = c * (1.0 + a / min_turns)
    L_turns = archimedean_length(r_in, p_turns, min_turns)
    b_turns = L_turns * 12.0 * K / (k_end * E * t**3)
    b_life = np.zeros(shape)
    life_lo = np.full(shape, np.inf)
    if min_cycles is not None:
        from rjcad import life

        rot = np.broadcast_to(np.atleast_1d(np.asarray(rotation, dtype=float))[:, None], shape)
        amp_max = np.broadcast_to(life.amplitude_limit(min_cycles, t[0], backlash)[None, :], shape)
        with np.errstate(divide="ignore"):
            b_life = np.where(amp_max > 0, m_end * 6.0 * K * rot / (2 * t**2 * amp_max), np.inf)
    b_lo = np.maximum.reduce([np.full(shape, width_min), MIN_WIDTH_TO_THICKNESS * t, b_stress, b_turns,
                              np.minimum(b_life, 1e9)])
    b_hi = max(_snap_down(width_max, layer), layer)
    b_need = _snap_up(np.maximum(width_min, MIN_WIDTH_TO_THICKNESS * t), layer)
    b = np.minimum(_snap_up(b_lo, layer), b_hi)

    L = length_for_stiffness(K, E, b, t, end)
    p, n = _solve_pitch(L, r_in, c, a)
    r_out = outer_radius(r_in, p, n) + t / 2.0

    # Constraint values evaluated with the model itself.
    sigma = windup_stress(E, b, t, L, theta, end)
    gap = coil_gap(r_in, p, n, t, theta)
    if min_cycles is not None:
        amp = m_end * 6.0 * K * rot / (2 * b * t**2)
        _, lo_c, _ = life.predict_cycles(amp.ravel(), t.ravel(), backlash)
        life_lo = lo_c.reshape(shape)
    viol = np.stack(
        [
            sigma / s_allow - 1.0,
            1.0 - n / min_turns,
            r_out / outer_radius_max - 1.0,
            r_in / inner_radius_max - 1.0,
            1.0 - gap / g_min,
            b_need / width_max - 1.0,
            (1.0 - life_lo / min_cycles) if min_cycles is not None else np.full(shape, -1.0),
        ]
    )
    values = np.stack([sigma, n, r_out, r_in, gap, b_need, life_lo])
    limits = np.stack([s_allow, np.full(shape, min_turns), np.full(shape, outer_radius_max),
                       np.full(shape, inner_radius_max), np.full(shape, g_min),
                       np.full(shape, width_max), np.full(shape, min_cycles or 0.0)])
    ok = np.all(viol <= 1e-9, axis=0)
    worst = viol.max(axis=0)

    score = np.where(ok, r_out, np.inf)
    best = np.argmin(score, axis=1)
    rows = np.arange(shape[0])
    feasible = np.isfinite(score[rows, best])
    # For infeasible rows: the thickness closest to feasibility, and its worst constraint.
    nearest = np.argmin(worst, axis=1)
    pick = np.where(feasible, best, nearest)
    binding = np.where(feasible, -1, np.argmax(viol[:, rows, pick], axis=0))
    bi = np.maximum(binding, 0)

    def sel(x):
        return np.asarray(x)[rows, pick]

    return {
        "width": sel(b),
        "thickness": sel(t),
        "length": sel(L),
        "inner_radius": sel(r_in),
        "pitch": sel(p),
        "turns": sel(n),
        "outer_radius": sel(r_out),
        "max_stress": sel(sigma),
        "min_coil_gap": sel(gap),
        "feasible": feasible,
        "binding": binding,
        "binding_value": values[bi, rows, pick],
        "binding_limit": limits[bi, rows, pick],
    }


def _infeasible_message(constraint: str, value: float, limit: float, t: float, b: float,
                        req: SpringRequirement) -> str:
    if constraint == "stress":
        return (f"stress {value:.1f} MPa > {limit:.1f} MPa allowed at t = {t:g} mm "
                f"(width b = {b:g} mm, its maximum --width-max): lower the stiffness or the rotation, "
                f"or choose a stronger material")
    if constraint == "turns":
        return (f"turns {value:.2f} < {limit:g} minimum at t = {t:g} mm (width b = {b:g} mm, its maximum): "
                f"the strip is too short to coil; lower the stiffness or allow a wider spring (--width-max)")
    if constraint == "outer_radius":
        return (f"outer radius {value:.1f} mm > {limit:g} mm allowed (smallest spring: t = {t:g} mm, "
                f"b = {b:g} mm): raise the limit (--max-outer-radius), lower the stiffness or the rotation, "
                f"or choose a material with a higher yield/E ratio")
    if constraint == "inner_radius":
        return (f"inner radius {value:.2f} mm > {limit:g} mm allowed at t = {t:g} mm "
                f"(thin-strip theory needs r_in >= {MIN_RADIUS_TO_THICKNESS:g}·t): "
                f"raise --inner-radius-max")
    if constraint == "life":
        from rjcad import life

        return (f"predicted life {value:.3g} cycles (lower 90 % bound at backlash {getattr(req, 'backlash', 0.25):g} mm, "
                f"t = {t:g} mm) < --min-cycles {limit:.3g}: {life.remedy()}")
    if constraint == "width":
        return (f"width {value:g} mm needed (>= width_min and >= {MIN_WIDTH_TO_THICKNESS:g}·t at "
                f"t = {t:g} mm, in whole layers) > --width-max {limit:g} mm: raise --width-max")
    return (f"coil gap {value:.3f} mm < {limit:g} mm printer minimum at t = {t:g} mm: "
            f"lower the rotation or the preload")


def design_spring(req: SpringRequirement) -> SpringDesign:
    """The spring with the smallest outer radius that meets ``req``.

    Raises :class:`InfeasibleDesign` naming the binding constraint.
    """
    res = optimise_arrays(
        req.spring_stiffness,
        req.max_windup,
        material=req.material_spec,
        printer=req.printer_spec,
        allowed_stress=req.allowed_stress,
        end=req.end,
        width_min=req.width_min,
        width_max=req.width_max,
        inner_radius_min=req.inner_radius_min,
        inner_radius_max=req.inner_radius_max,
        outer_radius_max=req.outer_radius_max,
        min_turns=req.min_turns,
        rotation=req.rotation,
        min_cycles=req.min_cycles,
        backlash=req.backlash,
    )
    if not res["feasible"][0]:
        name = CONSTRAINTS[int(res["binding"][0])]
        raise InfeasibleDesign(
            name,
            _infeasible_message(name, float(res["binding_value"][0]), float(res["binding_limit"][0]),
                                float(res["thickness"][0]), float(res["width"][0]), req),
        )
    design = SpringDesign(
        width=float(res["width"][0]),
        thickness=float(res["thickness"][0]),
        length=float(res["length"][0]),
        inner_radius=float(res["inner_radius"][0]),
        pitch=float(res["pitch"][0]),
        turns=float(res["turns"][0]),
        requirement=req,
    )
    failed = [k for k, (_, _, met) in design.constraint_report().items() if not met]
    if failed:  # the closed form and the model disagree: a bug, never a silent answer
        raise AssertionError(f"optimiser returned a design violating {failed}: {design}")
    return design


def design_from_dict(d: dict, req: SpringRequirement) -> SpringDesign:
    """Rebuild a design from its ``to_dict()`` keys (e.g. a manifest's ``spring``)."""
    return SpringDesign(
        width=d["width_mm"], thickness=d["thickness_mm"], length=d["length_mm"],
        inner_radius=d["inner_radius_mm"], pitch=d["pitch_mm"], turns=d["turns"], requirement=req,
    )


__all__ = [
    "CONSTRAINTS", "DEFAULT_END", "END_CONDITIONS", "SpringDesign", "SpringRequirement",
    "approx_length", "archimedean_length", "coil_gap", "design_from_dict", "design_spring",
    "length_for_stiffness", "optimise_arrays", "outer_radius", "peak_stress", "stiffness",
    "thickness_candidates", "turns_for_length", "windup_stress", "wound_pitch",
]
