"""A sweep file: which inputs vary and how (grid or Latin hypercube), and every design point it names.

A sweep file (TOML)::

    [sweep]
    mode = "grid"            # or "lhs" (Latin hypercube)
    samples = 200            # lhs only
    seed = 1                 # lhs only

    [fixed]
    preload_deg = 90

    [params.stiffness_nmm_per_rad]
    range = [2, 12]          # grid: with steps = N; lhs: continuous
    steps = 6
    [params.material]
    values = ["absplus-p430", "pla", "petg"]
"""

from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rjcad.config import load_toml
from rjcad.errors import ParameterError
from rjcad.spring.formulas import DEFAULT_END
from rjcad.validate import in_range

#: Sweepable inputs: name → (type, default). Angles in degrees (the column names say so).
INPUTS: dict[str, tuple[type, Any]] = {
    "stiffness_nmm_per_rad": (float, 5.2),
    "rotation_deg": (float, 90.0),
    "preload_deg": (float, 90.0),
    "material": (str, "absplus-p430"),
    "printer": (str, "generic-0.4"),
    "safety_factor": (float, 1.5),
    "end": (str, DEFAULT_END),
    "clearance_mm": (float, 0.25),
    "link_length_mm": (float, 40.0),
}
DESIGN_KEYS = ("width_mm", "thickness_mm", "length_mm", "inner_radius_mm", "pitch_mm", "turns",
               "outer_radius_mm", "spring_stiffness_nmm_per_rad", "joint_stiffness_nmm_per_rad",
               "max_stress_mpa", "allowed_stress_mpa", "min_coil_gap_mm")


@dataclass(frozen=True)
class SweepSpec:
    """Parsed sweep: varied parameters, fixed ones, and the sampling plan."""

    params: dict[str, dict]
    fixed: dict[str, Any]
    mode: str = "grid"
    samples: int = 0
    seed: int = 0

    @classmethod
    def from_toml(cls, path: str | Path) -> "SweepSpec":
        data = load_toml(path, {"sweep": dict, "fixed": dict, "params": dict})
        return cls.from_dict(data)

    @classmethod
    def from_dict(cls, data: dict) -> "SweepSpec":
        sweep = data.get("sweep", {})
        for k in sweep:
            if k not in ("mode", "samples", "seed"):
                raise ParameterError(f"sweep.{k}", sweep[k], "unknown key; known keys: mode, samples, seed")
        mode = sweep.get("mode", "grid")
        if mode not in ("grid", "lhs"):
            raise ParameterError("sweep.mode", mode, "must be 'grid' or 'lhs'")
        samples = int(sweep.get("samples", 0))
        if mode == "lhs":
            in_range("sweep.samples", samples, 1, 10_000_000, limit="an lhs sweep needs 1 to 10000000 samples")
        fixed = dict(data.get("fixed", {}))
        params = dict(data.get("params", {}))
        for name in list(fixed) + list(params):
            if name not in INPUTS:
                raise ParameterError(name, None, f"unknown parameter; known: {', '.join(INPUTS)}")
        for name, spec in params.items():
            if not isinstance(spec, dict) or not (("values" in spec) ^ ("range" in spec)):
                raise ParameterError(f"params.{name}", spec, "give exactly one of values = [...] or range = [lo, hi]")
            extra = set(spec) - {"values", "range", "steps"}
            if extra:
                raise ParameterError(f"params.{name}.{sorted(extra)[0]}", None, "known keys: values, range, steps")
            if "range" in spec:
                lo, hi = spec["range"]
                if not (isinstance(lo, (int, float)) and isinstance(hi, (int, float)) and lo <= hi):
                    raise ParameterError(f"params.{name}.range", spec["range"], "must be [lo, hi] numbers, lo <= hi")
                if mode == "grid":
                    in_range(f"params.{name}.steps", spec.get("steps"), 1, limit="a grid range needs steps >= 1")
        return cls(params, fixed, mode, samples, int(sweep.get("seed", 0)))

    def points(self) -> list[dict]:
        """Every design point (fixed values, then varied ones), in a deterministic order."""
        base = {k: v for k, (_, v) in INPUTS.items()}
        base.update(self.fixed)
        names = list(self.params)
        if self.mode == "grid":
            axes = []
            for n in names:
                s = self.params[n]
                axes.append(list(s["values"]) if "values" in s
                            else list(np.linspace(s["range"][0], s["range"][1], int(s["steps"]))))
            combos = itertools.product(*axes) if axes else [()]
        else:
            combos = self._lhs(names)
        pts = []
        for combo in combos:
            row = dict(base)
            row.update({n: (v.item() if isinstance(v, np.generic) else v) for n, v in zip(names, combo)})
            pts.append(row)
        return pts

    def _lhs(self, names: list[str]) -> list[tuple]:
        """Latin hypercube: each parameter's range cut into ``samples`` strata, one sample per stratum."""
        rng = np.random.default_rng(self.seed)
        n = self.samples
        cols = []
        for name in names:
            u = (rng.permutation(n) + rng.random(n)) / n
            s = self.params[name]
            if "range" in s:
                lo, hi = s["range"]
                cols.append(lo + u * (hi - lo))
            else:
                vals = list(s["values"])
                cols.append([vals[min(int(x * len(vals)), len(vals) - 1)] for x in u])
        return list(zip(*cols)) if cols else [()] * n


def point_id(point: dict) -> str:
    """Stable id of a design point: a hash of its inputs (so that --resume matches rows)."""
    key = json.dumps({k: point[k] for k in INPUTS}, sort_keys=True, default=float)
    return hashlib.sha1(key.encode()).hexdigest()[:12]

