"""Identify benchmark: the paper campaign end to end, and how the time grows with the samples.

Prints one JSON object. Each figure is the median of --repeats runs (1e5 samples: one run
unless --repeats-large). Target (issue #7): the paper campaign (5 × 3000 samples, full
selection) in ≤ 10 s; the time grows no worse than linearly with samples per experiment.
The scaling exponent is log(t_b/t_a)/log(n_b/n_a) between sizes measured in this same run.
Run: .venv/bin/python benchmarks/identify.py [--sizes 1000,10000,100000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path

from rjcad.identify.bench import PAPER_PRESET, write_campaign
from rjcad.identify.data import load_campaign
from rjcad.identify.select import identify

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "examples" / "paper_campaign" / "campaign.toml"


def timed(fn, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def run(path):
    camp = load_campaign(path)
    return identify(camp)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000,100000", help="samples per experiment")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--repeats-large", type=int, default=1, help="repeats for sizes ≥ 1e5")
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",") if s]

    t_load, _ = timed(lambda: load_campaign(PAPER), args.repeats)
    t_paper, ident = timed(lambda: run(PAPER), args.repeats)
    out = {
        "paper_campaign_s": round(t_paper, 3),
        "paper_campaign_load_s": round(t_load, 4),
        "paper_campaign_effects": ident.effects,
        "paper_campaign_budget_s": 10.0,
        "paper_campaign_within_budget": t_paper <= 10.0,
        "samples_per_experiment": [],
        "seconds": [],
        "effects_found": [],
    }
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            d = Path(tmp) / f"n{n}"
            write_campaign(d, PAPER_PRESET["effects"], PAPER_PRESET["params"], design=PAPER_PRESET["design"],
                           seed=1, samples=n)
            reps = args.repeats_large if n >= 100_000 else args.repeats
            t, ident = timed(lambda: run(d / "campaign.toml"), reps)
            out["samples_per_experiment"].append(n)
            out["seconds"].append(round(t, 3))
            out["effects_found"].append(ident.effects)
    s, t = out["samples_per_experiment"], out["seconds"]
    out["us_per_sample"] = [round(1e6 * ti / (5 * ni), 2) for ni, ti in zip(s, t)]
    out["scaling_exponent"] = [round(math.log(t[i + 1] / t[i]) / math.log(s[i + 1] / s[i]), 3)
                               for i in range(len(s) - 1)]
    out["at_most_linear"] = all(e <= 1.05 for e in out["scaling_exponent"])
    json.dump(out, sys.stdout, indent=2)
    print()


if __name__ == "__main__":
    main()
