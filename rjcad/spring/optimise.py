"""The spring optimiser: the smallest printable spiral spring meeting a requirement.

For every printable thickness t the best spring is closed-form (see :func:`optimise_arrays`);
the thickness with the thinnest envelope wins. Vectorised over requirements (rows) and
thicknesses (columns). The life constraint (``--min-cycles``) reads Table I's model from
:mod:`rjcad.life.constraint`; designs carry its predictor so that they report their life.
"""

from __future__ import annotations

import math

import numpy as np

from rjcad.errors import InfeasibleDesign
from rjcad.life.constraint import amplitude_limit, predict_cycles, remedy
from rjcad.materials import Material, Printer
from rjcad.spring.design import (
    MIN_RADIUS_TO_THICKNESS,
    MIN_WIDTH_TO_THICKNESS,
    SpringDesign,
    SpringRequirement,
    check_end,
)
from rjcad.spring.formulas import (
    DEFAULT_END,
    TWO_PI,
    archimedean_length,
    coil_gap,
    end_factors,
    length_for_stiffness,
    outer_radius,
    stress_amplitude,
    turns_for_length,
    windup_stress,
)

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


def _grid(spring_stiffness, max_windup, allowed_stress, printer: Printer):
    """Requirements (rows) × printable thicknesses (columns): K, θ, σ_allow and t broadcast to one shape."""
    K = np.atleast_1d(np.asarray(spring_stiffness, dtype=float))[:, None]
    theta = np.atleast_1d(np.asarray(max_windup, dtype=float))[:, None]
    K, theta = np.broadcast_arrays(K, theta)
    s_allow = np.broadcast_to(np.atleast_1d(np.asarray(allowed_stress, dtype=float))[:, None], K.shape)
    t = thickness_candidates(printer)[None, :]
    shape = np.broadcast_shapes(K.shape, t.shape)
    return tuple(np.broadcast_to(x, shape) for x in (K, theta, s_allow, t))


def _rows(x, shape):
    """A per-requirement value broadcast over the thickness columns."""
    return np.broadcast_to(np.atleast_1d(np.asarray(x, dtype=float))[:, None], shape)


def _life_width(K, rotation, t, end: str, min_cycles: float, backlash: float):
    """Narrowest width whose stress amplitude meets the life bound (σ_a ∝ 1/b); ∞ when none does [mm]."""
    amp_max = np.broadcast_to(amplitude_limit(min_cycles, t[0], backlash)[None, :], K.shape)
    with np.errstate(divide="ignore"):
        return np.where(amp_max > 0, stress_amplitude(K, rotation, 1.0, t, end) / amp_max, np.inf)


def _widths(K, theta, s_allow, t, r_in, c, a, b_life, *, E, end, layer, width_min, width_max, min_turns):
    """(b, b_need): the narrowest width in whole layers that meets stress, minimum turns and life
    (at most ``width_max``), and the width that width_min and the strip rule b ≥ 2t alone need [mm].

    Stress: b ≥ 6·m·K·θ/(t²·σ_allow). Turns: the length of ``min_turns`` at the gap-limited pitch
    gives b = 12·K·L/(c_end·E·t³).
    """
    k_end, m_end = end_factors(end)
    b_stress = m_end * 6.0 * K * theta / (t**2 * s_allow)
    p_turns = c * (1.0 + a / min_turns)
    L_turns = archimedean_length(r_in, p_turns, min_turns)
    b_turns = L_turns * 12.0 * K / (k_end * E * t**3)
    b_lo = np.maximum.reduce([np.full(K.shape, width_min), MIN_WIDTH_TO_THICKNESS * t, b_stress, b_turns,
                              np.minimum(b_life, 1e9)])
    b_hi = max(_snap_down(width_max, layer), layer)
    b_need = _snap_up(np.maximum(width_min, MIN_WIDTH_TO_THICKNESS * t), layer)
    return np.minimum(_snap_up(b_lo, layer), b_hi), b_need


def _pick(viol, values, limits, r_out, columns: dict) -> dict:
    """Per row: the feasible thickness with the smallest envelope, or (infeasible rows) the thickness
    closest to feasibility and its worst constraint."""
    ok = np.all(viol <= 1e-9, axis=0)
    worst = viol.max(axis=0)
    score = np.where(ok, r_out, np.inf)
    best = np.argmin(score, axis=1)
    rows = np.arange(r_out.shape[0])
    feasible = np.isfinite(score[rows, best])
    nearest = np.argmin(worst, axis=1)
    pick = np.where(feasible, best, nearest)
    binding = np.where(feasible, -1, np.argmax(viol[:, rows, pick], axis=0))
    bi = np.maximum(binding, 0)
    out = {k: np.asarray(x)[rows, pick] for k, x in columns.items()}
    out.update(feasible=feasible, binding=binding, binding_value=values[bi, rows, pick],
               binding_limit=limits[bi, rows, pick])
    return out


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
    check_end(end)
    E = material.youngs_modulus_mpa
    K, theta, s_allow, t = _grid(spring_stiffness, max_windup, allowed_stress, printer)
    shape = K.shape
    g_min = printer.min_gap_mm
    c = t + g_min
    a = theta / TWO_PI
    r_in = np.maximum(inner_radius_min, MIN_RADIUS_TO_THICKNESS * t)
    life = min_cycles is not None
    rot = _rows(rotation, shape) if life else None
    b_life = _life_width(K, rot, t, end, min_cycles, backlash) if life else np.zeros(shape)
    b, b_need = _widths(K, theta, s_allow, t, r_in, c, a, b_life, E=E, end=end, layer=printer.layer_height_mm,
                        width_min=width_min, width_max=width_max, min_turns=min_turns)
    L = length_for_stiffness(K, E, b, t, end)
    p, n = _solve_pitch(L, r_in, c, a)
    r_out = outer_radius(r_in, p, n) + t / 2.0

    # Constraint values evaluated with the model itself.
    sigma = windup_stress(E, b, t, L, theta, end)
    gap = coil_gap(r_in, p, n, t, theta)
    life_lo = np.full(shape, np.inf)
    if life:
        amp = stress_amplitude(K, rot, b, t, end)
        life_lo = predict_cycles(amp.ravel(), t.ravel(), backlash)[1].reshape(shape)
    viol = np.stack([
        sigma / s_allow - 1.0,
        1.0 - n / min_turns,
        r_out / outer_radius_max - 1.0,
        r_in / inner_radius_max - 1.0,
        1.0 - gap / g_min,
        b_need / width_max - 1.0,
        (1.0 - life_lo / min_cycles) if life else np.full(shape, -1.0),
    ])
    values = np.stack([sigma, n, r_out, r_in, gap, b_need, life_lo])
    limits = np.stack([s_allow, np.full(shape, min_turns), np.full(shape, outer_radius_max),
                       np.full(shape, inner_radius_max), np.full(shape, g_min),
                       np.full(shape, width_max), np.full(shape, min_cycles or 0.0)])
    return _pick(viol, values, limits, r_out, {
        "width": b, "thickness": t, "length": L, "inner_radius": r_in, "pitch": p, "turns": n,
        "outer_radius": r_out, "max_stress": sigma, "min_coil_gap": gap,
    })


#: One line per binding constraint: its value and limit at thickness t, width b, and what to change.
_INFEASIBLE = {
    "stress": "stress {value:.1f} MPa > {limit:.1f} MPa allowed at t = {t:g} mm (width b = {b:g} mm, its maximum "
              "--width-max): lower the stiffness or the rotation, or choose a stronger material",
    "turns": "turns {value:.2f} < {limit:g} minimum at t = {t:g} mm (width b = {b:g} mm, its maximum): the strip is "
             "too short to coil; lower the stiffness or allow a wider spring (--width-max)",
    "outer_radius": "outer radius {value:.1f} mm > {limit:g} mm allowed (smallest spring: t = {t:g} mm, b = {b:g} mm): "
                    "raise the limit (--max-outer-radius), lower the stiffness or the rotation, or choose a material "
                    "with a higher yield/E ratio",
    "inner_radius": "inner radius {value:.2f} mm > {limit:g} mm allowed at t = {t:g} mm (thin-strip theory needs "
                    "r_in >= {r_to_t:g}·t): raise --inner-radius-max",
    "life": "predicted life {value:.3g} cycles (lower 90 % bound at backlash {backlash:g} mm, t = {t:g} mm) < "
            "--min-cycles {limit:.3g}: {remedy}",
    "width": "width {value:g} mm needed (>= width_min and >= {b_to_t:g}·t at t = {t:g} mm, in whole layers) > "
             "--width-max {limit:g} mm: raise --width-max",
    "coil_gap": "coil gap {value:.3f} mm < {limit:g} mm printer minimum at t = {t:g} mm: lower the rotation or the "
                "preload",
}


def infeasible_message(constraint: str, value: float, limit: float, t: float, b: float,
                       backlash: float = 0.25) -> str:
    """One line: which constraint binds (its value and limit at thickness t, width b) and what to change."""
    template = _INFEASIBLE.get(constraint, _INFEASIBLE["coil_gap"])
    return template.format(value=value, limit=limit, t=t, b=b, backlash=backlash,
                           r_to_t=MIN_RADIUS_TO_THICKNESS, b_to_t=MIN_WIDTH_TO_THICKNESS,
                           remedy=remedy() if constraint == "life" else "")


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
            infeasible_message(name, float(res["binding_value"][0]), float(res["binding_limit"][0]),
                               float(res["thickness"][0]), float(res["width"][0]), req.backlash),
        )
    design = SpringDesign(
        width=float(res["width"][0]),
        thickness=float(res["thickness"][0]),
        length=float(res["length"][0]),
        inner_radius=float(res["inner_radius"][0]),
        pitch=float(res["pitch"][0]),
        turns=float(res["turns"][0]),
        requirement=req,
        life=predict_cycles,
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
        life=predict_cycles,
    )


__all__ = [
    "CONSTRAINTS", "MAX_THICKNESS", "design_from_dict", "design_spring", "infeasible_message",
    "optimise_arrays", "thickness_candidates",
]
