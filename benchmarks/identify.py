"""Identify benchmark: the paper campaign end to end, and how the time grows with the samples.

Prints one JSON object. Each figure is the median of --repeats runs after a warm-up (the
paper campaign; 1e5 samples: one run unless --repeats-large). Targets (issue #7): the paper
campaign (5 × 3000 samples, full selection) in ≤ 10 s; the time grows no worse than linearly
with samples per experiment (every scaling exponent ≤ 1.05). The scaling exponent is
log(t_b/t_a)/log(n_b/n_a) between sizes measured in this same run.
Run: .venv/bin/python benchmarks/identify.py [--sizes 1000,10000,100000] [--repeats 3] [--quick]
"""

from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

from _timing import emit, median_time, parse_args, target

from rjcad.identify.bench import PAPER_PRESET, write_campaign
from rjcad.identify.data import load_campaign
from rjcad.identify.select import identify

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "examples" / "paper_campaign" / "campaign.toml"


def run(path):
    camp = load_campaign(path)
    return identify(camp)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000,100000", help="samples per experiment")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--repeats-large", type=int, default=1, help="repeats for sizes ≥ 1e5")
    args = parse_args(ap, quick={"sizes": "600,1200", "repeats": 1})
    sizes = [int(s) for s in args.sizes.split(",") if s]

    t_load, _ = median_time(lambda: load_campaign(PAPER), args.repeats)
    t_paper, ident = median_time(lambda: run(PAPER), args.repeats)
    out = {
        "paper_campaign_s": round(t_paper, 3),
        "paper_campaign_load_s": round(t_load, 4),
        "paper_campaign_effects": ident.effects,
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
            t, ident = median_time(lambda: run(d / "campaign.toml"), reps, warmup=0)
            out["samples_per_experiment"].append(n)
            out["seconds"].append(round(t, 3))
            out["effects_found"].append(ident.effects)
    s, t = out["samples_per_experiment"], out["seconds"]
    out["us_per_sample"] = [round(1e6 * ti / (5 * ni), 2) for ni, ti in zip(s, t)]
    out["scaling_exponent"] = [round(math.log(t[i + 1] / t[i]) / math.log(s[i + 1] / s[i]), 3)
                               for i in range(len(s) - 1)]
    out["targets"] = {
        "paper_campaign_s": target(out["paper_campaign_s"], at_most=10.0),
        "worst_scaling_exponent": target(max(out["scaling_exponent"], default=None), at_most=1.05),
    }
    emit(out)


if __name__ == "__main__":
    main()
