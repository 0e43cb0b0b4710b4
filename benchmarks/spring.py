"""Spring benchmark: the rod model, the designer with its rod-model verification, the surrogate, the vector model.

Prints one JSON object with ``targets``. Every time is the median of several repeats after a warm-up
(the machine is noisy); the designer is timed cold (its caches cleared before every run).
* rod model: the old default spring (b 7.6, t 0.8, r_in 3, p 1.1434, 5.62 turns, clamped, unwinding)
  wound to 180° at the designer's resolution (target <= 0.3 s);
* designer: ``design_spring`` per design including the final rod-model verification, for the paper's
  joint and ``--random`` random requirements (target: median <= 0.5 s for the paper's joint);
* surrogate: coil gap + worst stress factor + stiffness ratio + torque ratio, vectorised over ``--n``
  designs (target >= 1e4 designs/s), and its worst coil-gap error against the rod model on
  ``--designs`` seeded random designs (clamped, the joint's unwinding sense);
* the closed-form vector model and the batched optimiser (the sweep's path), designs per second.
Run: .venv/bin/python benchmarks/spring.py [--designs 200] [--n 100000] [--repeats 7] [--quick]
"""

from __future__ import annotations

import argparse
import math
import statistics
from functools import partial

import numpy as np
from _timing import emit, median_time, parse_args, target

from rjcad import spring as sp
from rjcad.errors import InfeasibleDesign
from rjcad.materials import get_material, get_printer
from rjcad.spring import factors as fx
from rjcad.spring import optimise as opt
from rjcad.spring import rod, verify
from rjcad.spring import surrogate as sg

OLD_DEFAULT = dict(r_in=3.0, pitch=1.1434137451636173, turns=5.620157989891363, b=7.6, t=0.8, E=2200.0)


def cold_design(req: sp.SpringRequirement):
    """``design_spring`` with every cache cleared first (None when infeasible)."""
    verify.rod_check.cache_clear()
    try:
        return opt._design.__wrapped__(req)
    except InfeasibleDesign:
        return None


def surrogate_rate(n: int, repeats: int) -> float:
    rng = np.random.default_rng(0)
    rho, turns, theta = 2.0 ** rng.uniform(-0.4, 3.9, n), rng.uniform(1, 20, n), rng.uniform(0, 2 * math.pi, n)
    s = fx.JOINT_SENSE

    def lookups():
        return (
            sg.gap_ratio_min(theta, rho, turns, sense=s, margin=fx.use_margin("clamped")),
            sg.stress_factor(rho, turns, theta, sense=s),
            sg.stiffness_ratio(rho, turns),
            sg.torque_ratio(theta, rho, turns, sense=s),
        )

    return n / median_time(lookups, repeats)[0]


def gap_errors(n_designs: int, seed: int = 14) -> dict:
    """Surrogate coil gap (as the designer looks it up) minus the rod model's, on random designs [mm]."""
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(n_designs):
        r_in = rng.uniform(3.0, 10.0)
        t = rng.uniform(0.4, min(3.0, r_in / 3.0))
        p = rng.uniform(t + 0.25, min(4.0, r_in / 0.71))
        n, theta = rng.uniform(1.0, 12.0), rng.uniform(0.2, 2 * math.pi)
        res = rod.spiral_windup(
            r_in,
            p,
            n,
            2 * t,
            t,
            2200.0,
            end="clamped",
            sense=fx.JOINT_SENSE,
            theta_max=theta,
            steps=max(2, math.ceil(theta / math.radians(3.75))),
            per_turn=max(80, math.ceil(2 * math.pi * (r_in + p * n) / p)),
        )
        rod_gap = float(res.coil_gap.min())
        if (rod_gap + t) / p < 0.1:  # every printable spring touches there: the table holds 0
            continue
        ours = float(fx.coil_gap(theta, r_in, p, n, t, "clamped"))
        if np.isfinite(ours):
            rows.append((ours - rod_gap, dict(r_in=r_in, t=t, pitch=p, turns=n, theta_deg=math.degrees(theta))))
    worst = max(rows, key=lambda r: r[0])
    return {
        "designs": n_designs,
        "compared": len(rows),
        "worst_optimistic_mm": worst[0],
        "worst_optimistic_design": {k: round(v, 3) for k, v in worst[1].items()},
        "worst_conservative_mm": min(r[0] for r in rows),
        "median_abs_mm": statistics.median(abs(r[0]) for r in rows),
        "optimistic_count": sum(r[0] > 0 for r in rows),
        "margins_used": fx.use_margin("clamped"),
    }


def vector_model(n: int, repeats: int, rng) -> dict:
    E, b, t, L = np.full(n, 2200.0), rng.uniform(2, 10, n), rng.uniform(0.5, 2, n), rng.uniform(50, 500, n)
    r_in, p, theta = rng.uniform(3, 6, n), rng.uniform(1, 3, n), rng.uniform(0.5, 3, n)

    def full_model():
        turns = sp.turns_for_length(L, r_in, p)
        return fx.cycle_stresses(E, b, t, L, r_in, p, turns, theta / 2, theta / 2, "clamped"), fx.coil_gap(
            theta, r_in, p, turns, t, "clamped"
        )

    t_plain = median_time(lambda: E * b * t**3 / L, repeats)[0]
    t_stiff = median_time(lambda: sp.stiffness(E, b, t, L, "clamped"), repeats)[0]
    t_full = median_time(full_model, repeats)[0]
    return {
        "vector_designs": n,
        "numpy_plain_a_b3_over_c_per_s": n / t_plain,
        "stiffness_evals_per_s": n / t_stiff,
        "stiffness_vs_numpy_ceiling": t_plain / t_stiff,
        "full_model_evals_per_s": n / t_full,
        "full_model_vs_numpy_ceiling": t_plain / t_full,
        "full_model_note": "exact-length turns + rod-model K, peak and amplitude stress + coil gap (surrogate)",
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=100_000, help="designs in the vectorised arrays")
    ap.add_argument("--designs", type=int, default=200, help="random designs compared with the rod model")
    ap.add_argument("--random", type=int, default=30, help="random requirements through the designer")
    ap.add_argument("--repeats", type=int, default=7)
    args = parse_args(ap, quick={"n": 500, "designs": 2, "random": 3, "repeats": 2})
    rng = np.random.default_rng(0)

    rod_s = median_time(
        lambda: verify.rod_check.__wrapped__(
            OLD_DEFAULT["r_in"],
            OLD_DEFAULT["pitch"],
            OLD_DEFAULT["turns"],
            OLD_DEFAULT["b"],
            OLD_DEFAULT["t"],
            OLD_DEFAULT["E"],
            "clamped",
            fx.JOINT_SENSE,
            math.pi / 2,
            math.pi / 2,
        ),
        args.repeats,
    )[0]
    paper = sp.SpringRequirement(5.2, math.radians(90), math.radians(90))
    per_paper = median_time(partial(cold_design, paper), args.repeats)[0]
    reqs = [
        sp.SpringRequirement(float(k), math.radians(float(r)), math.radians(float(p)), outer_radius_max=60.0)
        for k, r, p in zip(
            rng.uniform(1, 15, args.random), rng.uniform(30, 150, args.random), rng.uniform(0, 120, args.random)
        )
    ]
    per_random = [median_time(partial(cold_design, req), 1, warmup=0)[0] for req in reqs]
    surrogate = surrogate_rate(args.n, args.repeats)
    m = min(args.n, 5000)
    K, rot = rng.uniform(1, 6, m), rng.uniform(0.5, 2.5, m)
    batch = partial(
        opt.optimise_arrays,
        K,
        rot + np.pi / 2,
        rotation=rot,
        material=get_material("absplus-p430"),
        printer=get_printer("generic-0.4"),
        allowed_stress=31 / 1.5,
        outer_radius_max=60.0,
    )
    t_batch = median_time(batch, max(2, args.repeats // 3))[0]
    out = {
        "rod_default_180deg_s": rod_s,
        "optimiser_median_s_per_design_verified_paper_joint": per_paper,
        "optimiser_median_ms_per_design_paper_joint": per_paper * 1e3,
        "optimiser_median_ms_per_design_random": statistics.median(per_random) * 1e3,
        "optimiser_max_ms_per_design_random": max(per_random) * 1e3,
        "surrogate_designs_per_s": surrogate,
        "surrogate_gap_vs_rod": gap_errors(args.designs),
        **vector_model(args.n, args.repeats, rng),
        "batched_optimiser_designs_per_s": m / t_batch,
        "batched_optimiser_note": "surrogate search only (the sweep's analytic mode): no rod-model verification",
        "repeats": args.repeats,
        "targets": {
            "rod_default_180deg_s": target(rod_s, at_most=0.3),
            "optimiser_median_s_per_design_verified_paper_joint": target(per_paper, at_most=0.5),
            "surrogate_designs_per_s": target(surrogate, at_least=1e4),
        },
    }
    emit(out)


if __name__ == "__main__":
    main()
