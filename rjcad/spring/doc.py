"""docs/spring-model.md (and docs/spring.png): the spring model's numbers, every one computed here.

Run: ``python -m rjcad.spring.doc docs`` (about a minute: a few dozen rod-model solves).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from rjcad.io.config import write_atomic
from rjcad.materials import Material, Printer, _builtin
from rjcad.spring import factors as fx
from rjcad.spring import rod
from rjcad.spring.formulas import coil_gap as handbook_gap
from rjcad.spring.formulas import turns_for_length
from rjcad.spring.paper_check import TABLE_I_PAIRS, paper_check, paper_length, paper_spring, table_i_spread
from rjcad.spring.rod import ENDS

#: The first wave's default spring (b 7.6, t 0.8, L 219.5, r_in 3, pitch 1.1434, 5.62 turns, E 2200).
OLD: dict[str, float] = dict(r_in=3.0, pitch=1.1434137451636173, turns=5.620157989891363, b=7.6, t=0.8, E=2200.0)
DEG = math.pi / 180


def _contact(end, sense, arms=1, theta=math.pi):
    """(first contact [deg] or None, min gap over 0..θ [mm]) of the old default spring wound to θ.

    ``arms=2``: two such arms interleaved 180° apart, each at twice the pitch (the same coil-to-coil gap).
    """
    res = rod.spiral_windup(
        OLD["r_in"],
        OLD["pitch"],
        OLD["turns"],
        OLD["b"],
        OLD["t"],
        OLD["E"],
        end=end,
        sense=sense,
        arms=arms,
        theta_max=theta,
        steps=72,
    )
    fc = res.first_contact
    return (None if fc is None else math.degrees(fc)), float(res.gap.min())


def _fmt_contact(fc, gap) -> str:
    return f"{fc:.1f}°" if fc is not None else f"none (gap ≥ {gap:.3f} mm)"


def _paper_section() -> list[str]:
    c = paper_check()
    s = c["spring"]
    rows = table_i_spread()
    lo = min(r["clamped"]["slope_error"] for r in rows)
    hi = max(r["clamped"]["slope_error"] for r in rows)
    plo = min(r["pinned"]["small_error"] for r in rows)
    phi = max(r["pinned"]["small_error"] for r in rows)
    return [
        "## Stiffness: formula, rod model and the paper's measurement",
        "",
        f"The paper designed its joint with the clamped formula K = E·b·t³/(12L) for {c['designed']:g} N·mm/rad "
        f"(two springs), b = {s['b']:g} mm, ABSplus-P430 (E 2200 MPa), and measured {c['measured']:g}. Its t, "
        f"pitch and inner radius are not given; rjcad's optimiser on the Dimension Elite with b held at "
        f"{s['b']:g} mm picks t = {s['t']:g} mm, r_in = {s['r_in']:g} mm, pitch {s['pitch']:.3f} mm, and the "
        f"formula gives L = {s['length']:.1f} mm ({s['turns']:.2f} turns). The rod model winds that spring over "
        "the measured joint's range (70° preload + 90°, unwinding):",
        "",
        "| outer end | joint K, slope over the range | error vs 5.19 | K at small wind-up | error vs 5.19 |",
        "|---|---|---|---|---|",
        *[
            f"| {end} | {c[end]['slope']:.3f} | {c[end]['slope_error']:+.1%} | {c[end]['small']:.3f} | "
            f"{c[end]['small_error']:+.1%} |"
            for end in ("clamped", "pinned")
        ],
        "",
        f"Over Table I's five pitch/thickness pairs (r_in 3 mm, L from the same formula) the clamped slope is "
        f"{lo:+.1%} to {hi:+.1%} from the measurement and the pinned small-wind-up stiffness {plo:+.1%} to "
        f"{phi:+.1%}: with the clamped end the rod model predicts the paper's joint within a few percent whatever "
        f"its geometry was, with the pinned end it is {-phi:.0%} to {-plo:.0%} low. The closed form's c = 1 (clamped) and "
        "c = 0.8 (pinned, Wahl) are close to the rod model's small-wind-up ratios; the rod model adds how the "
        "torque curve bends at large wind-up (τ), which a pinned spring unwound far feels most.",
    ]


def _gap_section(cases: dict) -> list[str]:
    hb = float(handbook_gap(OLD["r_in"], OLD["pitch"], OLD["turns"], OLD["t"], math.pi))
    lines = [
        "## Coil gap under wind-up",
        "",
        f"The old default spring (b {OLD['b']:g}, t {OLD['t']:g}, r_in {OLD['r_in']:g}, pitch "
        f"{OLD['pitch']:.4f} mm, {OLD['turns']:.2f} turns; printed gap {OLD['pitch'] - OLD['t']:.3f} mm) wound "
        "to 180° by the rod model. The handbook model (the wound spiral stays concentric) keeps "
        f"{hb:.3f} mm at 180° tightened. The outer end's reaction pushes the coil pack sideways instead:",
        "",
        "| outer end | sense | one spiral: first contact | interleaved pair (each arm at twice the pitch): first "
        "contact |",
        "|---|---|---|---|",
    ]
    for end in ("clamped", "pinned"):
        for sense in ("tighten", "unwind"):
            lines.append(
                f"| {end} | {sense} | {_fmt_contact(*cases[(end, sense, 1)])} | "
                f"{_fmt_contact(*cases[(end, sense, 2)])} |"
            )
    fc = cases[("pinned", "tighten", 1)][0]
    lines += [
        "",
        f"The first wave printed this spring pinned and tightened it: its coils touch at {fc:.1f}° of a 180° "
        "wind-up (`rjcad.spring.optimise.verify` refuses it; tests/test_spring_verified.py). Only a clamped "
        "end loaded in the unwinding sense keeps its coils apart to 180°; an interleaved pair closes much "
        "earlier in every case (its two coil packs drift in opposite directions), so the designer prints one "
        "spiral per spring.",
    ]
    return lines


def _why_section(cases: dict) -> list[str]:
    (fc_t, _), (fc_u, gap_u) = cases[("clamped", "tighten", 1)], cases[("clamped", "unwind", 1)]
    unwind = f"keeps {gap_u:.3f} mm to 180°" if fc_u is None else f"touches only at {fc_u:.0f}°"
    return [
        "## Why the designer's defaults are what they are",
        "",
        "- **Outer end clamped** (`--end clamped`, the default): the only measurement there is, the paper's "
        "joint, says its hooks behaved clamped (above), and a clamped end keeps the coils apart longest. "
        "The joint builder realises it as a key in a socket; `--end pinned` (a ring on a post, free to turn) "
        "stays an option with its own geometry.",
        f"- **Loaded unwinding** (`rjcad.spring.factors.JOINT_SENSE` = `{fx.JOINT_SENSE}`): the printed spiral "
        "winds so that preload and flexion open it. Tightened, the old default spring's coils bunch on one "
        f"side and touch at {fc_t:.0f}° even with a clamped end; unwound, it {unwind}.",
        "- **Every emitted spring is wound by the full rod model** (`rjcad.spring.verify`; corrections in `rjcad.spring.correct`): stiffness (the "
        "torque slope over the working range within 0.5 % of the request), peak stress, the smallest coil "
        "gap over 0..preload + rotation (≥ the printer's minimum) and the first contact. If the table "
        "was optimistic the design is corrected (pitch, width, length; at most three times, then searched "
        "again with the shortfall as a margin) or refused in one line that names the constraint.",
    ]


def _ratio_range(values, digits: int) -> str:
    lo, hi = f"{min(values):.{digits}f}", f"{max(values):.{digits}f}"
    return lo if lo == hi else f"{lo}–{hi}"


def _model_section() -> list[str]:
    """The model in brief: twin springs, the rod model and its references, the end condition, the optimiser's
    constraints and the geometry (the small-wind-up ratios computed on this page's springs)."""
    from rjcad.spring.design import MIN_RADIUS_TO_THICKNESS, MIN_WIDTH_TO_THICKNESS, STIFFNESS_TOLERANCE
    from rjcad.spring.optimise import WIDTH_FACTORS

    s = paper_spring()
    springs = [(OLD["r_in"], OLD["pitch"], OLD["turns"], OLD["t"]), (s["r_in"], s["pitch"], s["turns"], s["t"])]
    for pitch, t in TABLE_I_PAIRS:
        springs.append((3.0, pitch, float(turns_for_length(paper_length(t), 3.0, pitch)), t))
    c = {end: [rod.stiffness_ratio(*g, end=end, sense=fx.JOINT_SENSE) for g in springs] for end in ENDS}
    m = {end: [rod.stress_factor(*g, end=end, sense=fx.JOINT_SENSE) for g in springs] for end in ENDS}
    return [
        "## The model in brief",
        "",
        "- **Joint stiffness is the sum of the twin springs**: each spring is designed for K_joint/2. Every "
        'stiffness rjcad prints is per joint unless its key or row says "one spring".',
        "- **The rod model** (`rjcad.spring.rod`): corotational planar beam elements solved by Newton, the strip as "
        "printed, its inner end fused to the pin, its outer end carried round by the moving link. At every "
        "wind-up from 0 to preload + rotation it gives the torque, the peak bending stress and where it is, the "
        "smallest gap between coils (and to the pin) and where, the first contact, and the reaction on the outer "
        "end's post. `tests/test_spring_rod.py` checks it against references that share no code with it: the "
        "exact circular arc under an end moment, the elastica under a tip force, and a linear frame FE and a "
        "shooting elastica of the old default spring (below).",
        "- **The outer end**: `clamped` (the default: its position and angle held, a key in a socket) or "
        "`pinned` (free to turn, a ring on a post). The closed forms K = c·E·b·t³/(12·L) with c = 1 clamped, "
        "0.8 pinned, and σ = m·6·T/(b·t²) with m = 1 clamped, 2 pinned, are reported beside the rod model. The "
        f"rod model's own small-wind-up ratios on the {len(springs)} springs of this page (the old default, the "
        f"paper's and Table I's five) are c = {_ratio_range(c['clamped'], 3)} and m = {_ratio_range(m['clamped'], 2)} "
        f"clamped, c = {_ratio_range(c['pinned'], 3)} and m = {_ratio_range(m['pinned'], 2)} pinned. Why clamped is "
        "the default: below.",
        "- **The optimiser** minimises the outer radius subject to: the stiffness within "
        f"{STIFFNESS_TOLERANCE * 100:g} % (rod model, slope over the rotation); the peak stress over the whole wind-up "
        "≤ yield / safety factor; t ≥ the printer's minimum wall and a whole number of its thickness steps; b a "
        f"whole number of layers and ≥ {MIN_WIDTH_TO_THICKNESS:g}t; r_in ≥ {MIN_RADIUS_TO_THICKNESS:g}t; the "
        "turns ≥ the minimum; no coil contact and the printer's minimum gap kept over 0..preload + rotation; "
        "your bounds. The search uses a table of the rod model's factors (below): for each printable t and "
        f"{len(WIDTH_FACTORS)} widths from the narrowest that passes stress to `--width-max`, the length that "
        "gives the stiffness and the smallest pitch that keeps the gap, vectorised "
        "(`rjcad.spring.optimise.optimise_arrays`, also a sweep's analytic mode). `design_spring` (used by "
        "`rjcad spring`, `joint`, `finger` and `sweep --build`) then winds the chosen spring with the full rod "
        "model; `benchmarks/spring.py` times it.",
        "- **Geometry**: an Archimedean centreline r(φ) = r_in + p·φ/(2π) over n turns, with its exact arc "
        "length. The reported outer radius is the printed envelope r_in + p·n + t/2 (the wound strip reaches "
        "further; the joint builder clears it).",
        "- **Materials and printers**: `rjcad profiles` lists them, [Printers and filaments](profiles.md) says "
        "how to add yours. Built in: "
        + "; ".join(
            f"{mat.name} E {mat.youngs_modulus_mpa:g} MPa, yield {mat.yield_strength_mpa:g} MPa"
            for mat in sorted(
                (v for v in _builtin("materials").values() if isinstance(v, Material)), key=lambda x: x.key
            )
        )
        + ". Printers: "
        + "; ".join(
            f"`{pr.key}` ({pr.nozzle_mm:g} mm nozzle, walls ≥ {pr.min_wall_mm:g} mm in {pr.thickness_step_mm:g} mm "
            f"steps, {pr.layer_height_mm:g} mm layers, {pr.min_gap_mm:g} mm XY gaps, {pr.min_gap_vertical_mm:g} "
            "mm vertical gaps" + (", soluble support)" if pr.soluble_support else ")")
            for pr in sorted((v for v in _builtin("printers").values() if isinstance(v, Printer)), key=lambda x: x.key)
        )
        + ".",
    ]


def _surrogate_section(n: int = 40, seed: int = 5) -> list[str]:
    rng = np.random.default_rng(seed)
    found: list[float] = []
    for _ in range(n):
        r_in = rng.uniform(3.0, 8.0)
        t = rng.uniform(0.5, min(1.6, r_in / 3))
        p, turns, theta = rng.uniform(t + 0.25, 2.5), rng.uniform(1.5, 8.0), rng.uniform(30, 270) * DEG
        res = rod.spiral_windup(
            r_in,
            p,
            turns,
            2 * t,
            t,
            2200.0,
            end="clamped",
            sense=fx.JOINT_SENSE,
            theta_max=theta,
            steps=max(2, math.ceil(theta / (3.75 * DEG))),
        )
        ours = float(fx.coil_gap(theta, r_in, p, turns, t, "clamped"))
        if np.isfinite(ours) and (res.coil_gap.min() + t) / p >= 0.1:
            found.append(ours - float(res.coil_gap.min()))
    errs = np.array(found)
    return [
        "## The surrogate the search uses",
        "",
        "`rjcad.spring.surrogate` holds the rod model's factors on a grid of r_in/p, turns and wind-up "
        "(`tools/make_spring_surrogate.py`); `rjcad.spring.factors` looks them up for the optimiser. On "
        f"{len(errs)} seeded random clamped springs unwound 30–270° its smallest coil gap over the wind-up is "
        f"within {errs.min():+.3f} … {errs.max():+.3f} mm of the rod model's (median |error| "
        f"{np.median(np.abs(errs)):.3f} mm; + means the table promises more gap; "
        f"{'with' if fx.use_margin('clamped') else 'without'} the table's error margins). The full rod model's "
        "check catches what the table gets wrong. `benchmarks/spring.py` reports the same on 200 designs.",
    ]


def write_doc(out_dir) -> Path:
    """Write docs/spring-model.md and docs/spring.png (the default design's plot) into ``out_dir``."""
    from rjcad.spring import SpringRequirement
    from rjcad.spring.optimise import design_spring
    from rjcad.spring.plot import write_plot

    out = Path(out_dir)
    d = design_spring(SpringRequirement(5.2, 90 * DEG, 90 * DEG))
    write_plot(d, out / "spring.png")
    e = d.to_dict()
    lines = [
        "# The spring model",
        "",
        "Generated by `python -m rjcad.spring.doc docs`; every number below is computed, none typed by hand. "
        "The rod model (`rjcad.spring.rod`) is a large-rotation planar beam model of the printed strip: it "
        "gives the torque curve, the peak stress, the coil gap and the first contact at every wind-up.",
        "",
        f"The default design (`rjcad spring --stiffness 5.2`): b {e['width_mm']:g} × t {e['thickness_mm']:g} mm, "
        f"L {e['length_mm']:.1f} mm, r_in {e['inner_radius_mm']:g} mm, pitch {e['pitch_mm']:.3f} mm, "
        f"{e['turns']:.2f} turns, clamped, unwinding: joint K {e['rod_stiffness_nmm_per_rad']:.3f} (rod model; "
        f"the formula says {e['formula_stiffness_nmm_per_rad']:.3f}), peak stress {e['peak_stress_mpa']:.1f} of "
        f"{e['allowed_stress_mpa']:.1f} MPa allowed, smallest coil gap {e['min_coil_gap_mm']:.3f} mm at "
        f"{e['min_coil_gap_windup_deg']:.0f}°, no contact up to 180°.",
        "",
        "![spring](spring.png)",
        "",
        *_model_section(),
        "",
    ]
    cases = {
        (end, sense, arms): _contact(end, sense, arms)
        for end in ("clamped", "pinned")
        for sense in ("tighten", "unwind")
        for arms in (1, 2)
    }
    lines += _paper_section() + [""] + _gap_section(cases) + [""] + _why_section(cases) + [""] + _surrogate_section()
    path = out / "spring-model.md"
    write_atomic(path, "\n".join(lines) + "\n")
    return path


if __name__ == "__main__":
    print(write_doc(sys.argv[1] if len(sys.argv) > 1 else "docs"))
