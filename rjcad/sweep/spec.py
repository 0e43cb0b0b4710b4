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

from rjcad.errors import ParameterError
from rjcad.io.config import load_toml
from rjcad.materials import beside, profiles_beside
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
DESIGN_KEYS = (
    "width_mm",
    "thickness_mm",
    "length_mm",
    "inner_radius_mm",
    "pitch_mm",
    "turns",
    "outer_radius_mm",
    "spring_stiffness_nmm_per_rad",
    "joint_stiffness_nmm_per_rad",
    "max_stress_mpa",
    "allowed_stress_mpa",
    "min_coil_gap_mm",
)


#: Most design points one sweep may name (a grid's product of steps and value counts, or lhs samples).
MAX_POINTS = 10_000_000
#: Largest lhs seed (numpy takes any non-negative integer; 63 bits keep it an int64).
MAX_SEED = 2**63 - 1


def _whole(name: str, value, lo: int, hi: int) -> int:
    """A TOML integer (not a bool, not a float) in [lo, hi]; else ParameterError naming ``name``."""
    limit = f"must be a whole number in [{lo}, {hi}]"
    if isinstance(value, bool) or not isinstance(value, int):
        raise ParameterError(name, value, limit)
    return int(in_range(name, value, lo, hi, limit=limit))


def _typed(name: str, input_: str, value):
    """``value`` if it has the type of sweep input ``input_`` (a finite number, not a bool; or a string)."""
    if INPUTS[input_][0] is str:
        if not isinstance(value, str):
            raise ParameterError(name, value, f"must be a string ({input_} is a name)")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(name, value, "must be a number")
    in_range(name, value, limit="must be a finite number")
    return value


def _table(name: str, value) -> dict:
    if not isinstance(value, dict):
        raise ParameterError(name, value, "must be a table")
    return value


def _param(name: str, spec, mode: str) -> int:
    """Check ``[params.NAME]``; the number of values it gives a grid (0 for an lhs range)."""
    where = f"params.{name}"
    spec = _table(where, spec)
    if ("values" in spec) == ("range" in spec):
        raise ParameterError(where, spec, "give exactly one of values = [...] or range = [lo, hi]")
    extra = set(spec) - {"values", "range", "steps"}
    if extra:
        raise ParameterError(
            f"{where}.{sorted(extra)[0]}", spec[sorted(extra)[0]], "unknown key; known keys: values, range, steps"
        )
    if "values" in spec:
        values = spec["values"]
        if not isinstance(values, list) or not values:
            raise ParameterError(f"{where}.values", values, "must be a non-empty list of values")
        for i, v in enumerate(values, 1):
            _typed(f"{where}.values[{i}]", name, v)
        return len(values)
    rng = spec["range"]
    if INPUTS[name][0] is str:
        raise ParameterError(f"{where}.range", rng, f"{name} is a name: give values = [...]")
    if not isinstance(rng, list) or len(rng) != 2:
        raise ParameterError(f"{where}.range", rng, "must be [lo, hi]: two numbers")
    lo, hi = (_typed(f"{where}.range[{i}]", name, v) for i, v in enumerate(rng, 1))
    if lo > hi:
        raise ParameterError(f"{where}.range", rng, "must be [lo, hi] with lo <= hi")
    if "steps" in spec:
        return _whole(f"{where}.steps", spec["steps"], 1, MAX_POINTS)
    if mode == "grid":
        raise ParameterError(f"{where}.steps", None, "a grid range needs steps >= 1")
    return 0


@dataclass(frozen=True)
class SweepSpec:
    """Parsed sweep: varied parameters, fixed ones, and the sampling plan."""

    params: dict[str, dict]
    fixed: dict[str, Any]
    mode: str = "grid"
    samples: int = 0
    seed: int = 0

    @classmethod
    def from_toml(cls, path: str | Path) -> SweepSpec:
        """The sweep file ``path`` (rjcad.io.untrusted); a bad file is one error line naming it and the key."""
        data = load_toml(path, {"sweep": dict, "fixed": dict, "params": dict})
        folder = Path(path).parent
        if isinstance(data.get("fixed"), dict):
            data["fixed"] = profiles_beside(data["fixed"], folder)
        for name, spec in data.get("params", {}).items() if isinstance(data.get("params"), dict) else ():
            if name in ("printer", "material") and isinstance(spec, dict) and isinstance(spec.get("values"), list):
                spec["values"] = [beside(v, folder) for v in spec["values"]]
        try:
            return cls.from_dict(data)
        except ParameterError as e:
            raise ParameterError(f"{Path(path).name}: {e.parameter}", e.value, e.limit, e.unit) from None

    @classmethod
    def from_dict(cls, data: dict) -> SweepSpec:
        """Check types and structure (a wrong type is a bad file); values out of range are bad designs (rows)."""
        data = _table("sweep file", data)
        sweep = _table("sweep", data.get("sweep", {}))
        for k in sweep:
            if k not in ("mode", "samples", "seed"):
                raise ParameterError(f"sweep.{k}", sweep[k], "unknown key; known keys: mode, samples, seed")
        mode = sweep.get("mode", "grid")
        if mode not in ("grid", "lhs"):
            raise ParameterError("sweep.mode", mode, "must be 'grid' or 'lhs'")
        samples = _whole("sweep.samples", sweep["samples"], 1, MAX_POINTS) if "samples" in sweep else 0
        if mode == "lhs" and not samples:
            raise ParameterError("sweep.samples", None, f"an lhs sweep needs 1 to {MAX_POINTS} samples")
        seed = _whole("sweep.seed", sweep.get("seed", 0), 0, MAX_SEED)
        fixed = dict(_table("fixed", data.get("fixed", {})))
        params = dict(_table("params", data.get("params", {})))
        for where, names in (("fixed", fixed), ("params", params)):
            for name in names:
                if name not in INPUTS:
                    raise ParameterError(
                        f"{where}.{name}", names[name], f"unknown parameter; known: {', '.join(INPUTS)}"
                    )
        for name, value in fixed.items():
            if name in params:
                raise ParameterError(f"fixed.{name}", value, "is also in [params]: fix it or vary it, not both")
            _typed(f"fixed.{name}", name, value)
        total = 1
        for name, spec in params.items():
            n = _param(name, spec, mode)
            total *= n if mode == "grid" else 1
            if total > MAX_POINTS:
                raise ParameterError(f"params.{name}", n, f"makes the grid {total} designs; at most {MAX_POINTS}")
        return cls(params, fixed, mode, samples, seed)

    def points(self) -> list[dict]:
        """Every design point (fixed values, then varied ones), in a deterministic order."""
        base = {k: v for k, (_, v) in INPUTS.items()}
        base.update(self.fixed)
        names = list(self.params)
        if self.mode == "grid":
            axes = []
            for n in names:
                s = self.params[n]
                axes.append(
                    list(s["values"])
                    if "values" in s
                    else list(np.linspace(s["range"][0], s["range"][1], int(s["steps"])))
                )
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


def _canonical(v):
    """A number by its value (5, 5.0 and 5.00 are one design: a whole number hashes as an integer); anything
    else as it is."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return v
    return int(v) if float(v).is_integer() else float(v)


def point_id(point: dict) -> str:
    """Stable id of a design point: a hash of its inputs (so that --resume matches rows)."""
    key = json.dumps({k: _canonical(point[k]) for k in INPUTS}, sort_keys=True, default=float)
    return hashlib.sha1(key.encode()).hexdigest()[:12]
