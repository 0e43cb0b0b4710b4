"""Spring surrogate benchmark: throughput of the table lookups, their error against the rod model.

Prints one JSON object:
* surrogate throughput [designs/s]: coil gap at θ + worst stress factor over [0, θ] +
  stiffness ratio, vectorised over ``--n`` designs (median of ``--repeats``);
* against the rod model (rjcad.spring.rod.spiral_windup) on ``--designs`` seeded random
  designs (r_in 3–10 mm, t 0.4–3 mm with r_in ≥ 3t, pitch t+0.25–4 mm, 1–20 turns,
  θ 0–2π), clamped outer end, both senses: the worst coil-gap error [mm] of the raw
  lookup (surrogate − rod, + = the surrogate promises more gap) and where, how often the
  lookup with its margin still promises more than the rod model gives, and the same
  for the stiffness ratio c and the stress factor m;
* the rod model's solve time (median of 5) for the default spring to 180°.
The rod runs use per_turn ≥ 2π·r_out/p so that no element is longer than the pitch
(rod.node_gaps can pair a node with a coil two pitches away otherwise).
Benchmarks are not tests: nothing here asserts on time. Takes ~10–20 min (the rod solves).
Run: .venv/bin/python benchmarks/spring_surrogate.py [--designs 200] [--n 100000]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time

import numpy as np

from rjcad.spring import rod
from rjcad.spring import surrogate as sg

DEFAULT = dict(r_in=3.0, pitch=1.1434137451636173, turns=5.620157989891363, b=7.6, t=0.8, E=2200.0)
TWO_PI = 2.0 * math.pi
H_OPEN = 0.1  # below this centreline distance / p every printable design touches: the table reports 0


def median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def random_designs(n: int, seed: int):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        r_in = rng.uniform(3.0, 10.0)
        t = rng.uniform(0.4, min(3.0, r_in / 3.0))
        pitch = rng.uniform(t + 0.25, 4.0)
        out.append(dict(r_in=r_in, t=t, pitch=pitch, turns=rng.uniform(1.0, 20.0), theta=rng.uniform(0.0, 2 * math.pi)))
    return out


def throughput(n: int, repeats: int, sense: str) -> float:
    rng = np.random.default_rng(0)
    rho, turns, theta = 2.0 ** rng.uniform(-0.4, 3.9, n), rng.uniform(1, 20, n), rng.uniform(0, 2 * math.pi, n)

    def evaluate():
        return (sg.gap_ratio_min(theta, rho, turns, sense=sense), sg.stress_factor(rho, turns, theta, sense=sense),
                sg.stiffness_ratio(rho, turns))

    evaluate()
    return n / median_time(evaluate, repeats)


def compare(design: dict, sense: str) -> dict:
    """One design, clamped, wound to its θ: rod model vs surrogate (gap in mm, c, m)."""
    r_in, t, p, n, theta = design["r_in"], design["t"], design["pitch"], design["turns"], design["theta"]
    per_turn = max(80, math.ceil(TWO_PI * (r_in + p * n) / p))
    steps = max(1, math.ceil(theta / math.radians(3.75)))
    res = rod.spiral_windup(r_in, p, n, 2 * t, t, 2200.0, end="clamped", sense=sense, theta_max=theta,
                            steps=steps, per_turn=per_turn)
    rho = r_in / p
    rod_gap = float(res.coil_gap.min())
    raw = float(p * sg.gap_ratio_min(theta, rho, n, sense=sense, margin=False) - t)
    safe = float(p * sg.gap_ratio_min(theta, rho, n, sense=sense) - t)
    m_rod = float(np.max(res.max_moment[1:] / res.torque[1:]))
    c_rod = rod.stiffness_ratio(r_in, p, n, t, end="clamped", per_turn=per_turn)
    m0_rod = rod.stress_factor(r_in, p, n, t, end="clamped", per_turn=per_turn)
    return dict(design=design, sense=sense, open=(rod_gap + t) / p >= H_OPEN or (raw + t) / p >= H_OPEN,
                gap_rod=rod_gap, gap_err=raw - rod_gap, gap_safe_excess=safe - rod_gap,
                c_err=float(sg.stiffness_ratio(rho, n)) - c_rod,
                m0_err=m0_rod - float(sg.stress_factor(rho, n, margin=False)),
                m_err=m_rod - float(sg.stress_factor(rho, n, theta, sense=sense, margin=False)),
                m_safe_short=m_rod - float(sg.stress_factor(rho, n, theta, sense=sense)))


def worst(rows, key, sign=1.0):
    row = max(rows, key=lambda r: sign * r[key])
    d = row["design"]
    return {"error": row[key], "sense": row["sense"], "r_in": round(d["r_in"], 3), "t": round(d["t"], 3),
            "pitch": round(d["pitch"], 3), "turns": round(d["turns"], 3), "theta_deg": round(math.degrees(d["theta"]), 1)}


def worst_abs(rows, key):
    return worst(rows, key, 1.0 if max(r[key] for r in rows) >= -min(r[key] for r in rows) else -1.0)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=200)
    ap.add_argument("--n", type=int, default=100_000, help="designs per vectorised lookup")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--seed", type=int, default=14)
    args = ap.parse_args()

    rates = {s: throughput(args.n, args.repeats, s) for s in ("unwind", "tighten")}
    default_s = median_time(lambda: rod.spiral_windup(**DEFAULT, end="clamped", theta_max=math.pi, steps=36), 5)
    t0 = time.perf_counter()
    rows = [compare(d, s) for d in random_designs(args.designs, args.seed) for s in ("unwind", "tighten")]
    open_rows = [r for r in rows if r["open"]]
    out = {
        "surrogate_designs_per_s": rates,
        "surrogate_note": "gap_ratio_min(θ) + stress_factor(θ) + stiffness_ratio, clamped, vectorised",
        "surrogate_target_designs_per_s": 1e4,
        "rod_default_180deg_median_s": default_s,
        "designs": args.designs, "comparisons": len(rows), "comparisons_gap_open": len(open_rows),
        "rod_compare_s": time.perf_counter() - t0,
        "gap_worst_raw_error_mm": worst(open_rows, "gap_err"),
        "gap_worst_raw_underestimate_mm": worst(open_rows, "gap_err", -1.0),
        "gap_median_abs_error_mm": statistics.median(abs(r["gap_err"]) for r in open_rows),
        "gap_with_margin_above_rod": sum(r["gap_safe_excess"] > 0 for r in open_rows),
        "gap_with_margin_worst_excess_mm": worst(open_rows, "gap_safe_excess"),
        "c_worst_abs_error": worst_abs(rows, "c_err"),
        "m_small_windup_worst_abs_error": worst_abs(rows, "m0_err"),
        "m_worst_over_theta_rod_above_raw": worst(open_rows, "m_err"),
        "m_with_margin_below_rod": sum(r["m_safe_short"] > 0 for r in open_rows),
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
