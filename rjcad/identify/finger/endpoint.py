"""Finger endpoints as data: a few joint angles at the end of a pull (the paper's 65/50/50° at 25 mm), not a
record. Every set of catalogue effects the endpoints can carry (one effect, or two, with no more free parameters
than measured angles) is fitted; the simplest set that explains the endpoints within their error is the answer,
and every other set that explains them as well is reported as what the data cannot decide.

Campaign form (beside ``[[experiment]]`` records, not mixed with them):

    finger = "finger.toml"
    [[endpoint]]
    tendon_mm = 25.0            # the pull's end [mm], from the straight finger
    theta_deg = [65, 50, 50]    # each joint's angle there, proximal first
    sigma_deg = 2.0             # optional: the angles' 1σ error (default 2°)

An endpoint has no tension, no time and no orientation: effects that need a tension record, several speeds,
holds or gravity cannot show in it. Without a tension, joint 1's stiffness is the reference (angles fix the
springs' ratios, not their scale).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from rjcad import DEG
from rjcad.errors import RjcadError, quote
from rjcad.identify.catalogue import Param
from rjcad.identify.finger.catalogue import FingerEffect, catalogue, model_of
from rjcad.identify.finger.data import FingerDesign, finger_design
from rjcad.identify.result import _r
from rjcad.physics.finger import FingerModel, simulate_angles
from rjcad.physics.uncertainty import parameter_std

ENDPOINT_KEYS = ("tendon_mm", "theta_deg", "sigma_deg")
DEFAULT_SIGMA_DEG = 2.0
#: a set explains the endpoints when its RMS error is within this many σ
EXPLAINS_SIGMA = 1.0
#: steps of the simulated pull per endpoint stroke
STEPS = 160
#: what an endpoint cannot carry (the catalogue's needs) and why
NEEDS_RECORD = {
    "tension": "a tension record",
    "speeds": "several speeds",
    "holds": "holds",
    "orientation": "the finger's orientation (gravity)",
}
SEPARATE_BY = (
    "a full pull/release record (each joint's angle against the tendon stroke, both ways): "
    "`rjcad paper-finger --records` shows on SYNTHETIC records which of these sets it separates"
)


@dataclass(frozen=True)
class Endpoint:
    """The angles θ [rad] of every joint at tendon displacement ``tendon`` [mm] on the pull, 1σ ``sigma`` [rad]."""

    tendon: float
    theta: np.ndarray
    sigma: float


@dataclass(frozen=True)
class EndpointCampaign:
    path: Path
    design: FingerDesign
    endpoints: tuple[Endpoint, ...]
    notes: tuple[str, ...] = ()
    kind: str = "finger-endpoint"


def load_endpoint_campaign(path: Path, doc: dict, allow_outside: bool = False) -> EndpointCampaign:
    """A finger campaign of ``[[endpoint]]`` tables (one error line naming the file, table and key)."""
    for key in doc:
        if key not in ("finger", "endpoint"):
            raise RjcadError(
                f"{path}: unknown key or table {quote(key)}"
                + (
                    ": [[endpoint]] and [[experiment]] cannot be mixed; identify the records, or the endpoints, in "
                    "campaigns of their own"
                    if key == "experiment"
                    else '; an endpoint campaign has finger = "PATH" and [[endpoint]] tables'
                )
            )
    design = finger_design(path, doc.get("finger"), allow_outside)
    return EndpointCampaign(path, design, read_endpoints(path, doc["endpoint"], design.model.n))


def read_endpoints(path: Path, tables, n: int) -> tuple[Endpoint, ...]:
    """The ``[[endpoint]]`` tables of a finger campaign (one error line naming the table and key)."""
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise RjcadError(f"{path}: [[endpoint]] must be tables with tendon_mm and theta_deg")
    out = []
    for i, t in enumerate(tables, start=1):
        where = f"{path}: endpoint {i}: "
        for key in t:
            if key not in ENDPOINT_KEYS:
                raise RjcadError(f"{where}unknown key {quote(key)}; known: {', '.join(ENDPOINT_KEYS)}")
        td, th, sig = t.get("tendon_mm"), t.get("theta_deg"), t.get("sigma_deg", DEFAULT_SIGMA_DEG)
        if not _num(td) or not 0 < td <= 1000:
            raise RjcadError(f"{where}tendon_mm must be a number in (0, 1000] mm (got {quote(td)})")
        if not isinstance(th, list) or len(th) != n or not all(_num(x) and -5 <= x <= 360 for x in th):
            raise RjcadError(f"{where}theta_deg must be {n} angles in [-5, 360] deg, one per joint, proximal first")
        if not _num(sig) or not 0.01 <= sig <= 45:
            raise RjcadError(f"{where}sigma_deg must be a number in [0.01, 45] deg (got {quote(sig)})")
        out.append(Endpoint(float(td), np.asarray(th, float) * DEG, float(sig) * DEG))
    return tuple(out)


def _num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


@dataclass
class SetFit:
    """One candidate set fitted to the endpoints."""

    effects: tuple[str, ...]
    names: tuple[str, ...]
    values: dict[str, float]
    chi2: float
    rms_sigma: float  # √(mean of the whitened residuals²)
    end_deg: list[list[float]]
    why: dict[str, str]
    std: dict[str, float]

    @property
    def k(self) -> int:
        return len(self.names)

    def bic(self, n_data: int) -> float:
        return self.chi2 + self.k * math.log(n_data)


class EndpointProblem:
    """The endpoints' whitened residuals for parameter values (JSON units) of the finger catalogue."""

    def __init__(self, camp: EndpointCampaign):
        self.camp, self.design = camp, camp.design.model
        strokes = sorted({e.tendon for e in camp.endpoints})
        pts = [0.0]
        for s in strokes:
            pts = pts + list(np.linspace(pts[-1], s, STEPS + 1)[1:])
        self.path = np.asarray(pts)
        self.at = [int(np.argmin(np.abs(self.path - e.tendon))) for e in camp.endpoints]
        self.base: dict[str, float] = {}
        for e in catalogue(self.design):
            self.base.update(e.neutral(None))

    def ends(self, values: dict) -> np.ndarray:
        scale = values.get(ARM_SCALE.name)
        if scale is not None:  # one scale on every joint's arm (the moment_arm effect, constrained)
            values = {
                **values,
                **{f"tendon_moment_arm_mm_j{j + 1}": scale * a for j, a in enumerate(self.design.moment_arm)},
            }
        theta, _ = simulate_angles(model_of(values, self.design, None), self.path)
        return theta[self.at]

    def residuals(self, values: dict) -> np.ndarray:
        ends = self.ends(values)
        return np.concatenate([(ends[i] - e.theta) / e.sigma for i, e in enumerate(self.camp.endpoints)])


#: the moment arms' common scale: ``moment_arm`` with every joint's arm changed by one factor
ARM_SCALE = Param("moment_arm_scale", "moment_arm_scale", 1.0, 0.3, 3.0, 1.15, 1.0)


#: an effect and the parameters of it an endpoint fits
Group = tuple[FingerEffect, tuple[Param, ...]]


def groups(design: FingerModel) -> list[Group]:
    """(effect, its parameters an endpoint can fit) for each catalogue effect an endpoint can carry (no tension,
    time or gravity). A spring calibration is two groups, stiffness or preload: joint 1's stiffness is the
    reference (no tension), and both together have more parameters than an endpoint has angles. The moment arms
    are two: per joint, or one common scale."""
    out: list[Group] = []
    for e in catalogue(design):
        if e.needs != "any":
            continue
        if e.id == "moment_arm":
            out.append((e, (ARM_SCALE,)))
        if e.id == "spring_calibration":
            out.append((e, tuple(p for p in e.params if p.name.startswith("stiffness") and not p.name.endswith("_j1"))))
            out.append((e, tuple(p for p in e.params if p.name.startswith("preload"))))
        else:
            out.append((e, tuple(e.params)))
    return [g for g in out if g[1]]


#: free parameters a set may have beyond the measured angles: such a set cannot be identified, but if it explains
#: the endpoints the answer must not be called certain (the data cannot rule it out)
EXTRA_PARAMS = 1


def candidate_sets(design: FingerModel, n_data: int) -> list[tuple[Group, ...]]:
    """Every group and pair of groups of different effects with at most ``n_data`` + EXTRA_PARAMS free parameters
    (the design model first)."""
    gs = groups(design)
    sets: list[tuple[Group, ...]] = [()]
    for k in (1, 2):
        for combo in itertools.combinations(gs, k):
            if len({g[0].id for g in combo}) == k and sum(len(g[1]) for g in combo) <= n_data + EXTRA_PARAMS:
                sets.append(combo)
    return sets


#: random start points per fit, beside the neutral and typical ones (the range stops make the fit non-smooth:
#: a joint at its stop has no gradient)
RANDOM_STARTS = 8


def fit_set(prob: EndpointProblem, combo: tuple[Group, ...]) -> SetFit:
    """Least squares of the set's free parameters from its neutral, typical and random start points (bounded)."""
    params = [p for _, ps in combo for p in ps]
    names = tuple(p.name for p in params)
    effects = tuple(dict.fromkeys(e.id for e, _ in combo))
    if not params:
        return _setfit(prob, (), names, dict(prob.base), prob.residuals(prob.base), None, [], [])
    lb = np.array([p.lower for p in params], float)
    ub = np.array([p.upper for p in params], float)

    def resid(x):
        return prob.residuals({**prob.base, **dict(zip(names, x))})

    typical = {ARM_SCALE.name: ARM_SCALE.typical}
    for e, _ in combo:
        typical.update(e.typical(None))
    rng = np.random.default_rng(len(names) * 7919 + sum(map(len, names)))
    base = {**prob.base, ARM_SCALE.name: ARM_SCALE.neutral}
    starts = [np.array([base[n] for n in names]), np.array([typical[n] for n in names])]
    starts += [lb + (ub - lb) * rng.uniform(0.02, 0.6, len(names)) for _ in range(RANDOM_STARTS)]
    best = None
    for x0 in starts:
        x0 = np.clip(x0, lb + 1e-6 * (ub - lb), ub - 1e-6 * (ub - lb))
        res = least_squares(resid, x0, bounds=(lb, ub), diff_step=1e-3, max_nfev=150)
        if best is None or res.cost < best.cost:
            best = res
        if 2.0 * best.cost < 1e-6:
            break
    assert best is not None  # two start points at least
    values = {**prob.base, **dict(zip(names, best.x))}
    return _setfit(prob, effects, names, values, best.fun, best, lb, ub)


def _setfit(prob, effects, names, values, r, res, lb, ub) -> SetFit:
    ends = prob.ends(values) / DEG
    if res is not None:
        std, why = parameter_std(res.jac, res.x, lb, ub, list(names))
    else:
        std, why = np.zeros(0), []
    return SetFit(
        effects,
        names,
        values,
        float(r @ r),
        float(np.sqrt(np.mean(r**2))),
        ends.tolist(),
        dict(zip(names, why)),
        dict(zip(names, map(float, std))),
    )


def identify_endpoints(camp: EndpointCampaign) -> dict:
    """Fit every candidate set; the JSON result (the record result's top-level keys, ``kind: finger-endpoint``)."""
    prob = EndpointProblem(camp)
    n_data = prob.design.n * len(camp.endpoints)
    fits = [fit_set(prob, combo) for combo in candidate_sets(prob.design, n_data)]
    design = fits[0]
    explain = sorted((f for f in fits if f.rms_sigma <= EXPLAINS_SIGMA), key=lambda f: (f.k, f.chi2))
    answer = explain[0] if explain else min(fits, key=lambda f: f.bic(n_data))
    return _json(camp, prob, design, answer, explain, fits, n_data)


def _json(camp, prob, design, answer, explain, fits, n_data) -> dict:
    not_ident = {n: w for n, w in answer.why.items() if w}
    params = {n: _r(answer.values[n]) for n in answer.names if n not in not_ident}
    exps = []
    for i, e in enumerate(camp.endpoints):
        q = [f"theta{j + 1}_deg" for j in range(prob.design.n)]
        d = np.asarray(design.end_deg[i]) - e.theta / DEG
        f = np.asarray(answer.end_deg[i]) - e.theta / DEG
        sig = e.sigma / DEG
        exps.append(
            {
                "file": f"endpoint {i + 1}",
                "drive": "finger",
                "tendon_mm": e.tendon,
                "quantities": q,
                "measured_deg": [_r(x) for x in e.theta / DEG],
                "rmse_design": {k: _r(abs(x)) for k, x in zip(q, d)},
                "rmse_final": {k: _r(abs(x)) for k, x in zip(q, f)},
                "noise": {k: _r(sig) for k in q},
                "final_over_noise": {k: _r(abs(x) / sig) for k, x in zip(q, f)},
            }
        )
    # RMS errors in σ; an exact fit (as many parameters as angles) counts as the noise floor, not as infinite gain
    rd, rf = math.sqrt(design.chi2 / n_data), max(math.sqrt(answer.chi2 / n_data), 1.0)
    others = [f for f in explain if f is not answer]
    return {
        "kind": "finger-endpoint",
        "effects": list(answer.effects),
        "params": params,
        "param_ci95": {
            n: [_r(answer.values[n] - 1.96 * s), _r(answer.values[n] + 1.96 * s)]
            for n, s in answer.std.items()
            if n in params and math.isfinite(s)
        },
        "not_identifiable": sorted(not_ident),
        "not_identifiable_why": dict(sorted(not_ident.items())),
        "explained": bool(explain),
        "experiments": exps,
        "gain": _r(max(rd, 1.0) / rf),
        "ambiguous": [
            {
                "effects": list(f.effects),
                "delta_bic": _r(f.bic(n_data) - answer.bic(n_data)),
                "free_parameters": f.k,
                "only_bounded": sorted(n for n, w in f.why.items() if w),
                "separate_by": SEPARATE_BY,
                "params": {n: _r(f.values[n]) for n in f.names},
            }
            for f in others
        ],
        "candidates": [
            {
                "effects": list(f.effects),
                "parameters": list(f.names),
                "answer": f is answer,
                "free_parameters": f.k,
                "rms_over_sigma": _r(f.rms_sigma),
                "chi2": _r(f.chi2),
                "explains": f.rms_sigma <= EXPLAINS_SIGMA,
                "end_deg": [[_r(x, 4) for x in row] for row in f.end_deg],
            }
            for f in fits
        ],
        "cannot_show": {e.id: NEEDS_RECORD[e.needs] for e in catalogue(prob.design) if e.needs in NEEDS_RECORD},
        "design": camp.design.as_json(),
        "notes": list(camp.notes) + _notes(answer, explain, n_data),
    }


def _notes(answer, explain, n_data) -> list[str]:
    out = [
        f"{n_data} measured angle(s): single effects and pairs with up to {n_data + EXTRA_PARAMS} free parameters "
        "are tried (those with more parameters than angles cannot be identified, but may explain the endpoints); "
        "joint 1's stiffness is the reference (no tension record)"
    ]
    if not explain:
        out.append(
            "no single effect or pair explains the endpoints within their error: the best by BIC is "
            "reported, and the model misses something the catalogue does not hold"
        )
    elif len(explain) > 1:
        out.append(
            f"{len(explain)} sets explain the endpoints within their error: the endpoints cannot tell them "
            "apart; the simplest is the answer"
        )
    return out


def render_markdown(js: dict) -> str:
    """report.md of an endpoint identification."""
    from rjcad.identify.formatting import fmt

    lines = [
        "# Identification report: finger endpoints",
        "",
        f"Finger: `{js['design']['finger']}`, {js['design']['joints']} joints; {len(js['experiments'])} endpoint(s).",
        "",
    ]
    if js["explained"]:
        lines.append("Explained by: " + (", ".join(f"`{e}`" for e in js["effects"]) or "the design model") + ".")
    else:
        lines.append(
            "Not explained within the angles' error by any one or two catalogue effects; closest: "
            + (", ".join(f"`{e}`" for e in js["effects"]) or "the design model")
            + "."
        )
    lines += ["", "| endpoint | tendon [mm] | measured [deg] | design [deg] | answer [deg] |", "|---|---|---|---|---|"]
    design = js["candidates"][0]["end_deg"]
    ans = next(c for c in js["candidates"] if c["answer"])["end_deg"]
    for i, e in enumerate(js["experiments"]):
        lines.append(
            f"| {e['file']} | {fmt(e['tendon_mm'])} | {_row(e['measured_deg'])} | {_row(design[i])} | {_row(ans[i])} |"
        )
    lines += ["", "## Parameters", ""] + [f"- `{k}` = {fmt(v)}" for k, v in js["params"].items()]
    lines += [f"- `{k}`: not identifiable ({w})" for k, w in js["not_identifiable_why"].items()]
    if js["ambiguous"]:
        lines += [
            "",
            "## What the endpoints cannot decide",
            "",
            "Every set below explains the endpoints as well as the answer:",
            "",
            "| set | free parameters | ΔBIC vs the answer | fitted |",
            "|---|---|---|---|",
        ]
        for a in js["ambiguous"]:
            lines.append(
                f"| {', '.join(a['effects'])} | {a['free_parameters']} | {fmt(a['delta_bic'], 3)} | "
                + "; ".join(f"{k} = {fmt(v)}" for k, v in a["params"].items())
                + " |"
            )
        lines += ["", f"Separate them by {SEPARATE_BY}."]
    lines += ["", "## What endpoints cannot show", ""]
    lines += [f"- `{k}`: needs {v}" for k, v in js["cannot_show"].items()]
    lines += ["", "## Notes", ""] + [f"- {n}" for n in js["notes"]]
    return "\n".join(lines) + "\n"


def _row(v) -> str:
    return ", ".join(f"{x:.1f}" for x in v)
