"""The spring optimiser: the smallest printable spiral spring meeting a requirement, by the rod model.

For every printable thickness t the best spring is found vectorised (:func:`optimise_arrays`) with the
rod model's factors (:mod:`rjcad.spring.factors`, table lookups): width from stress, turns and life,
length from the rod's stiffness ratio, pitch the smallest whose coil gap stays ≥ the printer's minimum
over the whole wind-up. The thickness with the thinnest envelope wins. :func:`design_spring` then winds
that spring with the full rod model (:mod:`rjcad.spring.verify`), adjusts it a bounded number of
times if the table was optimistic, and refuses it naming the constraint if that does not suffice.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from rjcad.errors import InfeasibleDesign
from rjcad.life.constraint import amplitude_limit, predict_cycles
from rjcad.materials import Material, Printer
from rjcad.spring import factors as fx
from rjcad.spring.correct import RodRefusal, verify
from rjcad.spring.correct import snap_down as _snap_down
from rjcad.spring.correct import snap_up as _snap_up
from rjcad.spring.design import (
    MIN_RADIUS_TO_THICKNESS,
    MIN_WIDTH_TO_THICKNESS,
    STIFFNESS_TOLERANCE,
    SpringDesign,
    SpringRequirement,
    check_end,
)
from rjcad.spring.formulas import DEFAULT_END, archimedean_length, end_factors, outer_radius, turns_for_length
from rjcad.spring.messages import CONSTRAINTS, contact_angles, infeasible_message, row_message

#: Thickest strip the optimiser tries [mm].
MAX_THICKNESS = 3.0
#: Fixed-point rounds of width → length → pitch → rod factors (most cells converge in 3–5).
ROUNDS = 8
#: Length iterations at a fixed pitch within a round (c and τ move with the turns).
POLISH = 3
#: Pitch search: log-spaced scan points, then bisection steps (pitch to ~1e-4 relative).
SCAN, BISECT = 8, 12
#: Widths tried per thickness, from the narrowest that meets stress, turns and life (0) to width_max (1),
#: log-spaced: the rod model's coil gap is not monotone in the turns, so a longer strip is sometimes the
#: smaller spring.
WIDTH_FACTORS = np.linspace(0.0, 1.0, 9)
#: Searches again, with the rod model's coil-gap shortfall as a margin, before a refusal.
RESEARCH = 2
#: Hub radii a two-arm spring is searched at, from inner_radius_min (0) to inner_radius_max (1), log-spaced: each
#: arm's end force shifts its coil pack the opposite way to the other's, and only a few coarse turns round a
#: larger hub stay apart (one arm keeps r_in at its lower bound).
HUB_FACTORS = np.linspace(0.0, 1.0, 7)


def thickness_candidates(printer: Printer, t_max: float = MAX_THICKNESS) -> np.ndarray:
    """Printable thicknesses: whole multiples of the printer's step, ≥ min wall, ≤ t_max [mm]."""
    step = printer.thickness_step_mm
    k0 = math.ceil(printer.min_wall_mm / step - 1e-9)
    k1 = math.floor(t_max / step + 1e-9)
    return np.round(np.arange(k0, k1 + 1) * step, 9)


def _grid(spring_stiffness, max_windup, allowed_stress, printer: Printer):
    """Requirements (rows) × cells (columns: printable thickness × width factor): K, θ, σ_allow, t and the
    width factor broadcast to one shape."""
    K = np.atleast_1d(np.asarray(spring_stiffness, dtype=float))[:, None]
    theta = np.atleast_1d(np.asarray(max_windup, dtype=float))[:, None]
    K, theta = np.broadcast_arrays(K, theta)
    s_allow = np.broadcast_to(np.atleast_1d(np.asarray(allowed_stress, dtype=float))[:, None], K.shape)
    ts = thickness_candidates(printer)
    t = np.repeat(ts, len(WIDTH_FACTORS))[None, :]
    wf = np.tile(WIDTH_FACTORS, len(ts))[None, :]
    shape = np.broadcast_shapes(K.shape, t.shape)
    return tuple(np.broadcast_to(x, shape) for x in (K, theta, s_allow, t, wf))


def _rows(x, shape):
    """A per-requirement value broadcast over the thickness columns."""
    return np.broadcast_to(np.atleast_1d(np.asarray(x, dtype=float))[:, None], shape)


def _gap_at(p, L, r_in, t, theta, end, sense, arms=fx.ARMS):
    """Rod-model (surrogate) coil gap over 0..θ of the spiral of length L at arm pitch p [mm]; NaN: off the table."""
    return fx.coil_gap(theta, r_in, p, turns_for_length(L, r_in, p), t, end, sense, arms)


def _pitch(L, r_in, t, theta, g_min, end, sense, holes_ok=False, guess=None, arms=fx.ARMS):
    """Smallest arm pitch whose rod-model coil gap stays ≥ g_min over 0..θ, for 1-D arrays of cells.

    Searched between arms·(t + g_min) and the table's coarsest arms·r_in/0.707: a log scan, then bisection;
    or, from a ``guess`` (the last round's pitch), bisection within ±3 % of it when that brackets the
    answer. ``holes_ok``: a pitch where the table has no value (NaN, θ ≤ 2π) counts as good (the rod
    model then decides). Returns (p, found): where none is found, p is the coarsest pitch.
    """
    p_lo = t + g_min if arms == 1 else arms * (t + g_min)
    p_hi = np.maximum(
        r_in / fx.RHO_RANGE[0] * (1 - 1e-9) if arms == 1 else arms * r_in / fx.RHO_RANGE[0] * (1 - 1e-9), p_lo
    )
    hole = np.where(holes_ok & (theta <= fx.THETA_MAX + 1e-9), np.inf, -np.inf)  # the gap a NaN stands for
    cells = (L, r_in, t, theta, hole)

    def ok(p, sel, axis=False):
        args = [x[sel][:, None] if axis else x[sel] for x in cells]
        gap = _gap_at(p, args[0], args[1], args[2], args[3], end, sense, arms)
        return np.where(np.isnan(gap), args[4], gap) >= g_min - 1e-12

    def bisect(lo, hi, sel, steps):
        for _ in range(steps):
            mid = np.sqrt(lo * hi)
            good = ok(mid, sel)
            hi, lo = np.where(good, mid, hi), np.where(good, lo, mid)
        return hi

    p, found = p_hi.copy(), np.zeros(len(L), bool)
    todo = np.arange(len(L))
    if guess is not None:
        lo, hi = np.maximum(guess / 1.03, p_lo), np.minimum(guess * 1.03, p_hi)
        good_lo, good_hi = ok(lo, todo), ok(hi, todo)
        at_lo = good_lo & (lo <= p_lo)
        near = ~good_lo & good_hi
        p[at_lo], found[at_lo] = p_lo[at_lo], True
        p[near], found[near] = bisect(lo[near], hi[near], todo[near], BISECT - 4), True
        todo = todo[~(at_lo | near)]
    if todo.size:
        ps = p_lo[todo, None] * (p_hi / p_lo)[todo, None] ** (np.arange(SCAN) / (SCAN - 1))
        feas = ok(ps, todo, axis=True)
        hit = feas.any(axis=1)
        k = np.argmax(feas, axis=1)[:, None]
        hi = np.take_along_axis(ps, k, 1)[:, 0]
        lo = np.take_along_axis(ps, np.maximum(k - 1, 0), 1)[:, 0]
        search = hit & (k[:, 0] > 0)
        hi[search] = bisect(lo[search], hi[search], todo[search], BISECT)
        p[todo[hit]], found[todo[hit]] = hi[hit], True
    return p, found


def _widths(K, theta, s_allow, t, r_in, p, stiff, m_peak, b_life, wf, *, E, layer, width_min, width_max, min_turns):
    """(b, b_need): the cell's width in whole layers, b_lo·(b_max/b_lo)^wf with b_lo the narrowest meeting
    stress, minimum turns and life (≤ width_max), and the width that width_min and the strip rule b ≥ 2t
    alone need [mm].

    Stress: b ≥ 6·m_peak·K·θ/(t²·σ_allow). Turns: ``min_turns`` at pitch p need L = archimedean length,
    so b ≥ 12·K·L/(stiff·E·t³); ``stiff`` = L·12K/(E·b·t³), the rod's c·g.
    """
    b_stress = 6.0 * m_peak * K * theta / (t**2 * s_allow)
    b_turns = archimedean_length(r_in, p, min_turns) * 12.0 * K / (stiff * E * t**3)
    b_lo = np.maximum.reduce(
        [np.full(K.shape, width_min), MIN_WIDTH_TO_THICKNESS * t, b_stress, b_turns, np.minimum(b_life, 1e9)]
    )
    b_hi = max(_snap_down(width_max, layer), layer)
    b_need = _snap_up(np.maximum(width_min, MIN_WIDTH_TO_THICKNESS * t), layer)
    b_lo = np.minimum(b_lo, b_hi)
    return np.minimum(_snap_up(b_lo * (b_hi / b_lo) ** wf, layer), b_hi), b_need


def _rod_factors(r_in, p, n, pre, rot, end, sense, arms=fx.ARMS):
    """(c·g, m·τ_max/g, m): stiffness factor on E·b·t³/12L, peak-stress factor on 6·K_eff·θ/(b·t²), m.

    Table holes filled as in ``fx.cycle_stresses(fill=True)`` (τ = 1, m = FALLBACK_M): the search needs
    numbers; the final evaluation judges the holes.
    """
    theta = pre + rot
    c = fx.stiffness_ratio(r_in, p, n, end, arms)
    tau_max = np.nan_to_num(fx.torque_ratio(theta, r_in, p, n, end, sense, arms), nan=1.0)
    tau_pre = np.nan_to_num(fx.torque_ratio(pre, r_in, p, n, end, sense, arms), nan=1.0)
    m = np.nan_to_num(fx.stress_factor(theta, r_in, p, n, end, sense, arms), nan=fx.FALLBACK_M[end])
    g = (theta * tau_max - pre * tau_pre) / rot
    return c * g, m * tau_max / g, m


def _solve(K, theta, rot, s_allow, t, r_in, wf, *, E, end, sense, printer, g_min, life_amp, bounds, holes_ok, arms):
    """Fixed point of width → length → pitch → rod factors per cell; (b, b_need, L, p, n, found).

    K, L, p and n are one arm's (``arms`` of them in the spring). Cells (requirement × thickness × width factor ``wf``) are solved as flat arrays; a cell leaves the
    loop once its length stops changing.
    """
    shape = np.broadcast_shapes(K.shape, t.shape, wf.shape)
    K, theta, rot, s_allow, t, r_in, wf, life_amp = (
        np.broadcast_to(x, shape).ravel() for x in (K, theta, rot, s_allow, t, r_in, wf, life_amp)
    )
    layer = printer.layer_height_mm
    k_end, m_end = end_factors(end)
    stiff, m_peak, m = np.full(K.size, k_end), np.full(K.size, m_end), np.full(K.size, m_end)
    p, b, b_need, L, n = arms * (t + g_min), np.zeros(K.size), np.zeros(K.size), np.zeros(K.size), np.zeros(K.size)
    found = np.zeros(K.size, bool)
    act = np.arange(K.size)
    for k in range(ROUNDS):
        i = act
        with np.errstate(divide="ignore"):
            b_life = np.where(life_amp[i] > 0, 3.0 * m[i] * K[i] * rot[i] / (t[i] ** 2 * life_amp[i]), np.inf)
        b_new, b_need[i] = _widths(
            K[i],
            theta[i],
            s_allow[i],
            t[i],
            r_in[i],
            p[i],
            stiff[i],
            m_peak[i],
            b_life,
            wf[i],
            E=E,
            layer=layer,
            **bounds,
        )
        b[i] = b_new if k < ROUNDS - 3 else np.maximum(b[i], b_new)  # the last rounds settle a layer flip-flop up
        L_old, L[i] = L[i], stiff[i] * E * b[i] * t[i] ** 3 / (12.0 * K[i])
        p[i], found[i] = _pitch(L[i], r_in[i], t[i], theta[i], g_min, end, sense, holes_ok, p[i] if k else None, arms)
        for _ in range(POLISH):  # the length that gives K at this pitch (c and τ move with the turns)
            n[i] = turns_for_length(L[i], r_in[i], p[i])
            stiff[i], m_peak[i], m[i] = _rod_factors(r_in[i], p[i], n[i], theta[i] - rot[i], rot[i], end, sense, arms)
            L[i] = stiff[i] * E * b[i] * t[i] ** 3 / (12.0 * K[i])
        n[i] = turns_for_length(L[i], r_in[i], p[i])
        act = i[np.abs(L[i] - L_old) > 1e-10 * L[i]]
        if act.size == 0:
            break
    return tuple(x.reshape(shape) for x in (b, b_need, L, p, n, found))


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
    out.update(
        feasible=feasible, binding=binding, binding_value=values[bi, rows, pick], binding_limit=limits[bi, rows, pick]
    )
    return out


def _violations(
    sigma,
    s_allow,
    n,
    r_out,
    r_in,
    gap,
    pin,
    b_need,
    life_lo,
    k_err,
    *,
    g_min,
    min_turns,
    outer_radius_max,
    inner_radius_max,
    width_max,
    min_cycles,
):
    """(violation, value, limit) stacks in the order of CONSTRAINTS (violation ≤ 0: met)."""
    shape = sigma.shape
    full = lambda x: np.full(shape, x)  # noqa: E731
    life = min_cycles is not None
    viol = np.stack(
        [
            sigma / s_allow - 1.0,
            1.0 - n / min_turns,
            r_out / outer_radius_max - 1.0,
            r_in / inner_radius_max - 1.0,
            1.0 - gap / g_min,
            b_need / width_max - 1.0,
            (1.0 - life_lo / min_cycles) if life else full(-1.0),
            1.0 - pin / g_min if pin is not None else full(-1.0),
            k_err / STIFFNESS_TOLERANCE - 1.0,
        ]
    )
    values = np.stack([sigma, n, r_out, r_in, gap, b_need, life_lo, full(np.nan) if pin is None else pin, k_err])
    limits = np.stack(
        [
            s_allow,
            full(min_turns),
            full(outer_radius_max),
            full(inner_radius_max),
            full(g_min),
            full(width_max),
            full(min_cycles or 0.0),
            full(g_min),
            full(STIFFNESS_TOLERANCE),
        ]
    )
    return viol, values, limits


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
    sense: str = fx.JOINT_SENSE,
    pin_radius: float | None = None,
    holes_ok: bool = False,
    gap_margin: float = 0.0,
    min_gap: float | None = None,
    arms: int = fx.ARMS,
) -> dict[str, np.ndarray]:
    """Vectorised optimiser over D requirements; smallest outer radius per row (rod-model surrogate).

    ``spring_stiffness``: one spring's working-range slope [N·mm/rad]; ``max_windup`` preload + rotation,
    ``rotation`` the working range [rad] (None: the whole wind-up, no preload). For every printable
    thickness t and width step f (the cells): r_in at its lower bound; b from the smallest layer multiple
    meeting stress (σ = 6·m·T(θ)/(b·t²)), minimum turns and life (f = 0) to width_max (f = 1), log-spaced;
    L = c·g·E·b·t³/(12K) so the
    rod model's slope hits K; the smallest pitch keeping the rod-model coil gap ≥ the printer's minimum
    over 0..θ. Then the cell with the thinnest envelope wins.

    Returns arrays of shape (D,): width, thickness, length, inner_radius, pitch, turns, outer_radius,
    spring_stiffness, max_stress, stress_amplitude, min_coil_gap (all surrogate), feasible, binding (index into
    :data:`CONSTRAINTS`, −1 when feasible), the binding constraint's value and limit, and for the
    messages contact_deg / gap_low_deg (surrogate) and windup_deg. Where the table has a hole (a
    NaN within θ ≤ 2π) the cell is refused as ``coil_gap`` with a NaN value, unless ``holes_ok``:
    then the hole counts as met, with fallback factors, for the full rod model to judge. ``gap_margin``
    [mm] is added to the minimum gap (design_spring's retry when the rod model found less); ``min_gap`` [mm]
    replaces the printer's minimum gap when given. ``arms=2``: two interleaved arms (rjcad.spring.rod), each
    carrying half of ``spring_stiffness``; length, pitch and turns are then one arm's (pitch: the arm's, twice
    the coil-to-coil pitch), spring_stiffness the whole spring's.
    """
    check_end(end)
    E, g_min = material.youngs_modulus_mpa, (printer.min_gap_mm if min_gap is None else min_gap) + gap_margin
    per_arm = spring_stiffness if arms == 1 else np.asarray(spring_stiffness, dtype=float) / arms
    K, theta, s_allow, t, wf = _grid(per_arm, max_windup, allowed_stress, printer)
    shape = K.shape
    rot = _rows(max_windup if rotation is None else rotation, shape)
    r_in = np.maximum(inner_radius_min, MIN_RADIUS_TO_THICKNESS * t)
    life = min_cycles is not None
    life_amp = (
        np.broadcast_to(amplitude_limit(min_cycles, t[0], backlash)[None, :], shape)
        if min_cycles is not None
        else np.full(shape, np.inf)
    )
    bounds = dict(width_min=width_min, width_max=width_max, min_turns=min_turns)
    opts = dict(E=E, end=end, sense=sense, printer=printer, g_min=g_min, life_amp=life_amp, bounds=bounds, arms=arms)
    b, b_need, L, p, n, found = _solve(K, theta, rot, s_allow, t, r_in, wf, holes_ok=holes_ok, **opts)
    r_out = outer_radius(r_in, p, n) + t / 2.0
    K_eff, sigma, amp = fx.cycle_stresses(
        E, b, t, L, r_in, p, n, theta - rot, rot, end, sense, fill=holes_ok, arms=arms
    )
    gap = fx.coil_gap(theta, r_in, p, n, t, end, sense, arms)
    hole = np.isnan(gap) | np.isnan(sigma) | np.isnan(K_eff)
    unknown = (theta > fx.THETA_MAX + 1e-9) | (hole & (not holes_ok))
    gap = np.where(unknown, np.nan, np.where(np.isnan(gap), np.inf, gap))  # a hole passed over: met
    pin = None if pin_radius is None else fx.pin_gap(theta, r_in, p, n, t, pin_radius, end, sense, arms)
    life_lo = predict_cycles(amp.ravel(), t.ravel(), backlash)[1].reshape(shape) if life else np.full(shape, np.inf)
    k_err = np.abs(K_eff / K - 1.0)
    caps = dict(
        g_min=g_min,
        min_turns=min_turns,
        outer_radius_max=outer_radius_max,
        inner_radius_max=inner_radius_max,
        width_max=width_max,
        min_cycles=min_cycles,
    )
    viol, values, limits = _violations(sigma, s_allow, n, r_out, r_in, gap, pin, b_need, life_lo, k_err, **caps)
    viol = np.nan_to_num(viol, nan=-1.0)  # a value off the table is judged by the coil-gap row:
    viol[CONSTRAINTS.index("coil_gap")][~found | unknown] = np.inf
    columns = dict(width=b, thickness=t, length=L, inner_radius=r_in, pitch=p, turns=n, outer_radius=r_out)
    columns |= dict(
        spring_stiffness=K_eff * arms if arms != 1 else K_eff,
        max_stress=sigma,
        min_coil_gap=gap,
        stress_amplitude=amp,
        windup=theta,
    )
    out = _pick(viol, values, limits, r_out, columns)
    out["contact_deg"], out["gap_low_deg"] = contact_angles(
        out, CONSTRAINTS.index("coil_gap"), g_min, end, sense, arms=arms
    )
    out["windup_deg"] = np.degrees(out.pop("windup"))
    return out


def _smallest(results: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Per row, the feasible result with the smallest outer radius, else the first (its refusal names the constraint)."""
    r_out = np.stack([np.where(r["feasible"], r["outer_radius"], np.inf) for r in results])
    best = np.where(np.isfinite(r_out).any(axis=0), np.argmin(r_out, axis=0), 0)
    rows = np.arange(r_out.shape[1])
    return {k: np.stack([r[k] for r in results])[best, rows] for k in results[0]}


def design_spring(req: SpringRequirement) -> SpringDesign:
    """The spring with the smallest outer radius that meets ``req``, verified by the full rod model.

    Where the surrogate's table has a hole, the search goes past it and the rod model decides.
    Raises :class:`InfeasibleDesign` naming the binding constraint (cached per requirement).
    """
    # a design with a life constraint depends on the life model too (tests swap it): not cached
    return _design(req) if req.min_cycles is None else _design.__wrapped__(req)


def _optimise_one(req: SpringRequirement, holes_ok: bool = False, gap_margin: float = 0.0) -> dict:
    """:func:`optimise_arrays` of one requirement; two arms: at each of HUB_FACTORS' hub radii, the smallest."""
    if req.arms == 1 or req.inner_radius_max <= req.inner_radius_min:
        return _optimise_at(req, req.inner_radius_min, req.inner_radius_max, holes_ok, gap_margin)
    hubs = req.inner_radius_min * (req.inner_radius_max / req.inner_radius_min) ** HUB_FACTORS
    with np.errstate(invalid="ignore"):  # a coarse pitch round a small hub has no length for some cells
        return _smallest([_optimise_at(req, r, r, holes_ok, gap_margin) for r in hubs])


def _optimise_at(req: SpringRequirement, r_min: float, r_max: float, holes_ok: bool, gap_margin: float) -> dict:
    return optimise_arrays(
        req.spring_stiffness,
        req.max_windup,
        material=req.material_spec,
        printer=req.printer_spec,
        allowed_stress=req.allowed_stress,
        end=req.end,
        width_min=req.width_min,
        width_max=req.width_max,
        inner_radius_min=r_min,
        inner_radius_max=r_max,
        outer_radius_max=req.outer_radius_max,
        min_turns=req.min_turns,
        rotation=req.rotation,
        min_cycles=req.min_cycles,
        backlash=req.backlash,
        pin_radius=req.pin_radius,
        holes_ok=holes_ok,
        gap_margin=gap_margin,
        min_gap=req.min_gap,
        arms=req.arms,
    )


def _searched(req: SpringRequirement, gap_margin: float = 0.0) -> SpringDesign:
    """The surrogate search's design (past a table hole if need be), or InfeasibleDesign."""
    res = _optimise_one(req, gap_margin=gap_margin)
    hole = (
        not res["feasible"][0]
        and CONSTRAINTS[int(res["binding"][0])] == "coil_gap"
        and np.isnan(res["binding_value"][0])
        and req.max_windup <= fx.THETA_MAX + 1e-9
    )
    if hole:  # the table has no value there: design past the hole, and let the full rod model judge
        res = _optimise_one(req, holes_ok=True, gap_margin=gap_margin)
    if not res["feasible"][0]:
        name = CONSTRAINTS[int(res["binding"][0])]
        why = (
            ""
            if gap_margin == 0
            else f"rod-model check (the coils came {gap_margin:.3f} mm closer than the table "
            "said; searched again with that margin): "
        )
        raise InfeasibleDesign(name, why + row_message(res, 0, req.backlash, req.end) + _pair_note(req, name))
    return SpringDesign(
        width=float(res["width"][0]),
        thickness=float(res["thickness"][0]),
        length=float(res["length"][0]),
        inner_radius=float(res["inner_radius"][0]),
        pitch=float(res["pitch"][0]) / req.arms,  # the coil-to-coil pitch (each arm's is arms × it)
        turns=float(res["turns"][0]),
        requirement=req,
        life=predict_cycles,
    )


#: Why a two-arm spring is refused for its coil gap or its size, and what to change.
PAIR_NOTE = (
    "; two arms: each arm's end force shifts its coil pack the opposite way to the other's, so only a few coarse "
    "turns round a large hub stay apart: allow a larger spring (inner_radius_max, max_outer_radius) or use one arm"
)


def _pair_note(req: SpringRequirement, name: str) -> str:
    """:data:`PAIR_NOTE` for a two-arm spring refused for its coil gap or outer radius, else nothing."""
    return PAIR_NOTE if req.arms == 2 and name in ("coil_gap", "outer_radius") else ""


@functools.lru_cache(maxsize=128)
def _design(req: SpringRequirement) -> SpringDesign:
    margin = 0.0
    for _ in range(RESEARCH):
        try:
            return verify(_searched(req, margin))
        except RodRefusal as e:
            if e.constraint != "coil_gap" or not np.isfinite(e.value) or e.value < 0:
                raise
            margin += (e.limit - e.value) + 0.01  # raising the pitch did not fix it: search again with a margin
    return verify(_searched(req, margin))


def design_from_dict(d: dict, req: SpringRequirement) -> SpringDesign:
    """Rebuild a design from its ``to_dict()`` keys (e.g. a manifest's ``spring``)."""
    return SpringDesign(
        width=d["width_mm"],
        thickness=d["thickness_mm"],
        length=d["length_mm"],
        inner_radius=d["inner_radius_mm"],
        pitch=d["pitch_mm"],
        turns=d["turns"],
        requirement=req,
        life=predict_cycles,
    )


__all__ = [
    "CONSTRAINTS",
    "MAX_THICKNESS",
    "RodRefusal",
    "design_from_dict",
    "design_spring",
    "infeasible_message",
    "optimise_arrays",
    "row_message",
    "thickness_candidates",
    "verify",
]
