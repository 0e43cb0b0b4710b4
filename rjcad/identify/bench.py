"""Synthetic bench: a campaign (TOML + CSV) generated from the joint model with chosen effects and noise.

The data are SYNTHETIC: y = simulate(true model, setup, θ_true, t) + N(0, σ_y) and
θ_meas = θ_true + N(0, σ_θ). The true model is the design plus the chosen catalogue effects
(their typical values, overridden by ``params``); effects not chosen are absent.
Units in files: s, deg, N·mm, N (as the column names say).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np

from rjcad import DEG
from rjcad.errors import ParameterError, RjcadError
from rjcad.identify import catalogue as cat
from rjcad.io.outputs import write_set
from rjcad.paper import JOINT
from rjcad.physics.joint import JointModel, Setup, motion_direction, simulate
from rjcad.validate import in_range

#: The paper's designed joint (rjcad.paper.JOINT), in the campaign's JSON names and units.
DEFAULT_DESIGN = {
    "stiffness_nmm_per_rad": JOINT.designed_stiffness,
    "preload_deg": JOINT.preload / DEG,
    "pulley_radius_mm": JOINT.pulley_radius,
}
#: Gaussian noise σ per column, in the column's unit.
DEFAULT_NOISE = {"torque_nmm": 0.1, "tendon_force_n": 0.02, "theta_deg": 0.1}

#: The paper's Sec. IV experiments A–E.
PAPER_EXPERIMENTS = (
    {"name": "A", "drive": "bar", "normal_load": JOINT.normal_load, "routed": False},
    {"name": "B", "drive": "tendon", "normal_load": JOINT.normal_load, "routed": False},
    {"name": "C", "drive": "tendon", "normal_load": JOINT.normal_load, "routed": True},
    {"name": "D", "drive": "tendon", "normal_load": 0.0, "routed": False},
    {"name": "E", "drive": "tendon", "normal_load": 0.0, "routed": True},
)

#: The paper campaign preset (`rjcad bench --paper`): its design and its measured parameters.
PAPER_PRESET: dict[str, Any] = {
    "design": dict(DEFAULT_DESIGN),
    "effects": ("spring_calibration", "coulomb_pin", "tendon_pin_friction", "capstan_path"),
    "params": {
        "stiffness_nmm_per_rad": JOINT.stiffness,
        "preload_deg": JOINT.preload / DEG,
        "mu_j_mm": JOINT.mu_j,
        "gamma_pos_nmm_per_rad": JOINT.gamma_pos,
        "gamma_neg_nmm_per_rad": JOINT.gamma_neg,
        "beta_pos": JOINT.beta_pos,
        "beta_neg": JOINT.beta_neg,
    },
}

#: Trajectory as (duration [s], start, end) in units of the rotation; start == end is a hold.
#: Minimum-jerk ramps of 1.5, 3 and 6 s (three speeds: viscous damping vs Coulomb friction),
#: 3 s holds at top and bottom (relaxation, T_r ~ 1.5 s); the 3 s cycle reverses at 40 % on the way down.
SEGMENTS = (
    (1.0, 0.0, 0.0),
    (1.5, 0.0, 1.0),
    (3.0, 1.0, 1.0),
    (1.5, 1.0, 0.0),
    (3.0, 0.0, 0.0),
    (3.0, 0.0, 1.0),
    (3.0, 1.0, 1.0),
    (1.8, 1.0, 0.4),
    (1.8, 0.4, 1.0),
    (3.0, 1.0, 0.0),
    (3.0, 0.0, 0.0),
    (6.0, 0.0, 1.0),
    (3.0, 1.0, 1.0),
    (6.0, 1.0, 0.0),
    (3.0, 0.0, 0.0),
)
#: Named trajectories (``--trajectory``): segments and a sentence for the README. "paper" is SEGMENTS.
#: one-speed: four 2 s up/down cycles, no hold (viscous damping and a fast relaxation look alike);
#: one-speed-holds: the same ramps with 4 s holds at top and bottom (relaxation shows in the holds);
#: two-speeds: two cycles of 2 s ramps and two of 5 s, no hold (viscous damping scales with speed).
TRAJECTORIES = {
    "paper": SEGMENTS,
    "one-speed": ((1.0, 0.0, 0.0),) + ((2.0, 0.0, 1.0), (2.0, 1.0, 0.0)) * 4,
    "one-speed-holds": ((1.0, 0.0, 0.0),) + ((2.0, 0.0, 1.0), (4.0, 1.0, 1.0), (2.0, 1.0, 0.0), (4.0, 0.0, 0.0)) * 2,
    "two-speeds": ((1.0, 0.0, 0.0),) + ((2.0, 0.0, 1.0), (2.0, 1.0, 0.0)) * 2 + ((5.0, 0.0, 1.0), (5.0, 1.0, 0.0)) * 2,
}
TRAJECTORY_TEXT = {
    "one-speed": "four cycles with minimum-jerk ramps of 2 s, one speed, no hold",
    "one-speed-holds": "two cycles with minimum-jerk ramps of 2 s and 4 s holds at the top and the bottom",
    "two-speeds": "two cycles with minimum-jerk ramps of 2 s, then two of 5 s (two speeds), no hold",
}
MIN_SAMPLES, MAX_SAMPLES = 100, 2_000_000
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*$")


def trajectory(samples: int, rotation: float, segments=SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """Uniform times t [s] over ``segments`` and the true joint angle θ_j(t) [rad], 0 → ``rotation`` [rad].

    Ramps are minimum-jerk: θ = a + (b − a)·(10u³ − 15u⁴ + 6u⁵), u = (t − t₀)/T.
    """
    dur = np.array([s[0] for s in segments])
    start = np.array([s[1] for s in segments]) * rotation
    end = np.array([s[2] for s in segments]) * rotation
    t0 = np.concatenate([[0.0], np.cumsum(dur)])
    t = np.linspace(0.0, t0[-1], samples)
    k = np.clip(np.searchsorted(t0, t, side="right") - 1, 0, len(dur) - 1)
    u = np.clip((t - t0[k]) / dur[k], 0.0, 1.0)
    shape = u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
    return t, start[k] + (end[k] - start[k]) * shape


def experiment_file(e: dict) -> str:
    """CSV name of an experiment, e.g. A_bar_Fn1.5.csv or C_tendon_routed_Fn1.5.csv."""
    return f"{e['name']}_{e['drive']}{'_routed' if e['routed'] else ''}_Fn{e['normal_load']:g}.csv"


# ---------------------------------------------------------------- validation


def _number(where: str, v, lo: float | None = None, hi: float | None = None, unit: str = "") -> float:
    """A finite int or float (not a bool, not a numeric string) in [lo, hi]; else one ParameterError."""
    finite = "must be a finite number"
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParameterError(where, v, finite, unit)
    in_range(where, v, unit=unit, limit=finite)
    limit = f"must be in [{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}]"
    return in_range(where, v, lo, hi, unit=unit, limit=limit)


def _design(design) -> dict:
    d = dict(DEFAULT_DESIGN)
    for key, v in (design or {}).items():
        if key not in DEFAULT_DESIGN:
            raise ParameterError(f"design.{key}", v, f"unknown key; known: {', '.join(DEFAULT_DESIGN)}")
        d[key] = v
    d["stiffness_nmm_per_rad"] = _number("design.stiffness_nmm_per_rad", d["stiffness_nmm_per_rad"], 1e-9)
    d["preload_deg"] = _number("design.preload_deg", d["preload_deg"], -90.0, 360.0)
    d["pulley_radius_mm"] = _number("design.pulley_radius_mm", d["pulley_radius_mm"], 1e-9)
    return d


#: The copy of the joint's manifest a campaign of a built joint names.
JOINT_FILE = "joint.json"


def _joint(path, design, rotation_deg) -> tuple[str | None, Any, Any]:
    """The joint manifest at ``path`` (None: no joint): its text, ``design`` over the joint's own (campaign JSON
    names) and its bearing friction table; the bench's ``rotation_deg`` must lie in the joint's range."""
    from rjcad.design.rebuild import joint_params
    from rjcad.io.manifest import Manifest
    from rjcad.io.untrusted import parse_json, read_text
    from rjcad.physics.bearing_table import friction_table

    if path is None:
        return None, design, None
    text = read_text(path, kind="JSON")
    man = Manifest.from_json(parse_json(text, str(path)), source=path)
    p = joint_params(man, f"joint {path}")
    built = {
        "stiffness_nmm_per_rad": man.joints[0].joint_stiffness_nmm_per_rad or p.stiffness,
        "preload_deg": p.preload / DEG,
        "pulley_radius_mm": p.moment_arm,
    }
    if _number("rotation", rotation_deg, unit="deg") > p.rotation / DEG + 1e-9:
        raise ParameterError("rotation", rotation_deg, f"must be <= {p.rotation / DEG:g}, the joint's range", "deg")
    return text, {**built, **(design or {})}, friction_table(p)


def _effects(effects) -> tuple[str, ...]:
    if isinstance(effects, str):
        effects = [effects]
    chosen = {cat.effect(str(e)).id for e in effects}
    return tuple(e.id for e in cat.CATALOGUE if e.id in chosen)  # catalogue order: same set, same files


def _true_params(design: dict, effects: tuple[str, ...], params) -> dict:
    """JSON-named true values: stiffness/preload always, plus every parameter of the chosen effects."""
    values = {"stiffness_nmm_per_rad": design["stiffness_nmm_per_rad"], "preload_deg": design["preload_deg"]}
    for eid in effects:
        values.update(cat.EFFECTS[eid].typical(design))
    for name, v in (params or {}).items():
        if name not in cat.PARAMS:
            raise ParameterError("param", name, f"unknown parameter; known: {', '.join(cat.PARAMS)}")
        owner = cat.PARAMS[name][0].id
        if owner not in effects:
            raise ParameterError(f"param {name}", v, f"belongs to effect {owner}, which is not among the effects")
        values[name] = _number(name, v)
    for eid in effects:
        e = cat.EFFECTS[eid]
        lo, hi = e.bounds(design)
        for p, a, b in zip(e.params, lo, hi):
            _number(p.name, values[p.name], a, b)
    order = [p.name for e in cat.CATALOGUE for p in e.params]
    return {n: float(values[n]) for n in order if n in values}


def _noise(noise) -> dict:
    out = dict(DEFAULT_NOISE)
    for key, v in (noise or {}).items():
        if key not in DEFAULT_NOISE:
            raise ParameterError("noise", key, f"unknown column; known: {', '.join(DEFAULT_NOISE)}")
        out[key] = _number(f"noise {key}", v, 0.0)
    return out


def _experiments(experiments) -> list[dict]:
    if isinstance(experiments, str):
        if experiments != "paper":
            raise ParameterError("experiments", experiments, "must be 'paper' or a list of experiments")
        experiments = PAPER_EXPERIMENTS
    out, names = [], set()
    for i, e in enumerate(experiments):
        where = f"experiment {i + 1}"
        if not isinstance(e, dict):
            raise ParameterError(where, e, "must be a dict {name, drive, normal_load, routed}")
        unknown = set(e) - {"name", "drive", "normal_load", "routed"}
        if unknown:
            raise ParameterError(
                f"{where}.{sorted(unknown)[0]}",
                e[sorted(unknown)[0]],
                "unknown key; known: name, drive, normal_load, routed",
            )
        name = e.get("name")
        if not isinstance(name, str) or not _NAME.match(name) or name in names:
            raise ParameterError(f"{where}.name", name, "must be a unique name of letters, digits, _ or -")
        names.add(name)
        drive = e.get("drive", "bar")
        if drive not in ("bar", "tendon"):
            raise ParameterError(f"{where}.drive", drive, "must be 'bar' or 'tendon'")
        routed = e.get("routed", False)
        if not isinstance(routed, bool) or (routed and drive != "tendon"):
            raise ParameterError(f"{where}.routed", routed, "must be true or false, and true only for a tendon drive")
        load = _number(f"{where}.normal_load", e.get("normal_load", 0.0), 0.0, unit="N")
        ex = {"name": name, "drive": drive, "normal_load": load, "routed": routed}
        out.append(
            {
                "name": name,
                "file": experiment_file(ex),
                "drive": drive,
                "normal_load_n": load,
                "routed": routed,
                "quantity": Setup(drive).quantity,
            }
        )
    if not out:
        raise ParameterError("experiments", 0, "needs at least one experiment")
    return out


# ---------------------------------------------------------------- writing


def _csv(t, theta_deg, y, quantity: str) -> str:
    yf = "{:.6f}" if quantity == "tendon_force_n" else "{:.5f}"
    fmt = "{:.5f},{:.5f}," + yf
    rows = [fmt.format(a, b, c) for a, b, c in zip(t.tolist(), theta_deg.tolist(), y.tolist())]
    return f"t_s,theta_deg,{quantity}\n" + "\n".join(rows) + "\n"


def _toml(truth: dict) -> str:
    d = truth["design"]
    lines = [
        "# SYNTHETIC campaign generated by `rjcad bench`: simulated from rjcad's joint model, NOT measured.",
        f"# effects: {', '.join(truth['effects']) or 'none (the design model alone)'}; seed {truth['seed']}; "
        f"noise σ: " + ", ".join(f"{k} {v:g}" for k, v in truth["noise"].items()),
        "# The true parameters are in truth.json; see README.md.",
        "",
        "[design]",
        f"stiffness_nmm_per_rad = {d['stiffness_nmm_per_rad']!r}",
        f"preload_deg = {d['preload_deg']!r}",
        f"pulley_radius_mm = {d['pulley_radius_mm']!r}",
    ]
    if "joint" in truth:
        lines.append(f"joint = \"{truth['joint']['file']}\"  # the joint's manifest: its bearing's geometry")
    for e in truth["experiments"]:
        lines += [
            "",
            f"# {e['name']}: {e['drive']} drive{', routed' if e['routed'] else ''}, F_n = {e['normal_load_n']:g} N",
            "[[experiment]]",
            f'file = "{e["file"]}"',
            f'drive = "{e["drive"]}"',
            f"normal_load_n = {e['normal_load_n']!r}",
            f"routed = {'true' if e['routed'] else 'false'}",
        ]
    return "\n".join(lines) + "\n"


def _command(truth: dict) -> str:
    """A command line that regenerates the campaign (None when the CLI cannot express it)."""
    if truth["design"] != DEFAULT_DESIGN or [
        {k: e[k] for k in ("name", "drive", "routed")} | {"normal_load": e["normal_load_n"]}
        for e in truth["experiments"]
    ] != [dict(e) for e in PAPER_EXPERIMENTS]:
        return ""
    args = ["rjcad bench"]
    if _is_paper(truth):
        args.append("--paper")
    else:
        if truth["effects"]:
            args.append(f"--effects {','.join(truth['effects'])}")
        args += [f"--param {k}={v!r}" for k, v in truth["params"].items() if cat.PARAMS[k][0].id in truth["effects"]]
    if truth["noise"] != DEFAULT_NOISE:
        args.append("--noise " + ",".join(f"{k}={v!r}" for k, v in truth["noise"].items()))
    if truth["trajectory"].get("name", "paper") != "paper":
        args.append(f"--trajectory {truth['trajectory']['name']}")
    args += [
        f"--seed {truth['seed']}",
        f"--samples {truth['samples']}",
        f"--rotation {truth['rotation_deg']!r}",
        "--out DIR",
    ]
    return " ".join(args)


def _is_paper(truth: dict) -> bool:
    return (
        truth["design"] == PAPER_PRESET["design"]
        and tuple(truth["effects"]) == PAPER_PRESET["effects"]
        and truth["params"] == PAPER_PRESET["params"]
    )


def _readme(truth: dict) -> str:
    d, tr = truth["design"], truth["trajectory"]
    units = {"torque_nmm": "N·mm", "tendon_force_n": "N", "theta_deg": "deg"}
    out = [
        "# SYNTHETIC campaign: generated, not measured",
        "",
        "**These data are synthetic.** `rjcad bench` generated them from rjcad's joint model "
        "(`rjcad/physics/joint.py`, paper Eq. 3–7) with known parameters and added Gaussian noise. "
        "No joint was printed or measured. Use them to test identification (`truth.json` holds the answer), "
        "never as evidence about a real joint.",
        "",
        "## True model",
        "",
        f"Design: stiffness {d['stiffness_nmm_per_rad']:g} N·mm/rad, preload {d['preload_deg']:g}°, "
        f"pulley radius {d['pulley_radius_mm']:g} mm."
        + (
            f" The joint is the one `{truth['joint']['file']}` records (a copy of `{truth['joint']['source']}`): "
            "its tendon runs load its bearing, whose friction per unit μ comes from its geometry "
            "(`rjcad/physics/bearing_table.py`)."
            if "joint" in truth
            else ""
        ),
        "",
        f"Effects: {', '.join(f'`{e}`' for e in truth['effects']) or 'none: the data are the design model plus noise'}."
        " Effects not listed are absent (neutral).",
        "",
        "| parameter | true value |",
        "|---|---|",
    ]
    out += [f"| `{k}` | {v:g} |" for k, v in truth["params"].items()]
    out += [
        "",
        "## Noise",
        "",
        f"Independent Gaussian noise on every sample, numpy `default_rng({truth['seed']})`: "
        + ", ".join(f"`{k}` σ = {v:g} {units[k]}" for k, v in truth["noise"].items())
        + ". The measured angle is the true angle plus noise; the measured torque or force is the model's "
        "value at the true angle plus noise.",
        "",
        "## Experiments",
        "",
        "| file | drive | F_n (N) | routed | column |",
        "|---|---|---|---|---|",
    ]
    out += [
        f"| `{e['file']}` | {e['drive']} | {e['normal_load_n']:g} | {'yes' if e['routed'] else 'no'} | "
        f"`{e['quantity']}` |"
        for e in truth["experiments"]
    ]
    ramps = sorted({s[0] for s in SEGMENTS if s[1] != s[2] and abs(s[2] - s[1]) == 1.0})
    name = tr.get("name", "paper")
    shape = TRAJECTORY_TEXT.get(name) or (
        f"three cycles with minimum-jerk ramps of {', '.join(f'{r:g}' for r in ramps)} s (three speeds) and 3 s "
        "holds at the top and the bottom; the 3 s cycle reverses at 40 % of the rotation on its way down and goes up "
        "again before returning to 0"
    )
    out += [
        "",
        "## Trajectory (the same in every experiment)",
        "",
        f"{truth['samples']} samples at {tr['sample_rate_hz']:.4g} Hz over {tr['duration_s']:g} s; "
        f"rotation 0 → {truth['rotation_deg']:g}° from rest. A {SEGMENTS[0][0]:g} s hold at 0, then {shape}. "
        "The motion direction is held through holds.",
    ]
    out += _readme_slack(truth)
    cmd = _command(truth)
    out += ["", "## Regenerate", ""]
    if cmd:
        out += ["```", cmd, "```", "", "The same seed gives byte-identical files."]
    else:
        out += [
            "With `rjcad.identify.bench.write_campaign` and the design, effects, parameters, noise, seed, "
            "samples, rotation and experiments in `truth.json`. The same seed gives byte-identical files."
        ]
    if _is_paper(truth):
        out += ["", "`make paper-campaign` regenerates `examples/paper_campaign` (seed 7)."]
    return "\n".join(out) + "\n"


def _readme_slack(truth: dict) -> list[str]:
    """The README section on experiments where the model's tendon goes slack while releasing (none: [])."""
    slack = [e for e in truth["experiments"] if e.get("slack_release_fraction", 0) > 0]
    if not slack:
        return []
    out = [
        "",
        "## Slack tendon (a model prediction a real bench could not show)",
        "",
        "The model predicts a slack tendon (actuator force 0) while releasing in "
        + ", ".join(f"{e['name']} ({100 * e['slack_release_fraction']:.0f} % of the release samples)" for e in slack)
        + "; release samples are those moving back towards rest or held after such a move. There the spring "
        "torque is below the friction that resists the return (μ_j·F_n + γ⁻·θ), so the spring alone cannot "
        "bring the joint back and the tendon would have to push. A real tendon cannot push: a real bench would "
        "show the joint sticking, not this trajectory. The samples are kept because the chosen parameters say "
        "so. In them the measured force is pure noise around 0.",
    ]
    if _is_paper(truth):
        v, fn = truth["params"], max(e["normal_load_n"] for e in slack)
        limit = v["mu_j_mm"] * fn / (v["stiffness_nmm_per_rad"] - v["gamma_neg_nmm_per_rad"]) / DEG
        out[-1] += (
            f" With the paper's own values and F_n = {fn:g} N, (K_s − γ⁻)·θ < μ_j·F_n for every "
            f"spring deformation θ below {limit:.0f}°, and this campaign reaches only "
            f"{v['preload_deg'] + truth['rotation_deg']:g}°: the spring never wins while releasing. "
            "This is one of the paper-notes' critiques (shared/paper-notes.md, \"What the paper's own "
            'numbers get wrong").'
        )
    return out


def write_campaign(
    out_dir,
    effects=(),
    params=None,
    *,
    design=None,
    seed=0,
    noise=None,
    samples=3000,
    rotation_deg=90.0,
    experiments="paper",
    trajectory_name="paper",
    joint=None,
) -> dict:
    """Write a SYNTHETIC campaign (campaign.toml, one CSV per experiment, truth.json, README.md); return the truth.

    Everything is validated and simulated before anything is written. ``params`` (JSON names)
    override the chosen effects' typical values; ``noise`` σ per column (torque_nmm [N·mm],
    tendon_force_n [N], theta_deg [deg]); ``rotation_deg`` [deg]; ``trajectory_name`` one of TRAJECTORIES.
    ``joint``: a joint's manifest (rjcad joint's JSON); the campaign then names a copy of it (joint.json), its
    design defaults to that joint's, and its tendon drives load that joint's bearing (effect bearing_friction).
    """
    if trajectory_name not in TRAJECTORIES:
        raise ParameterError("trajectory", trajectory_name, f"unknown; known: {', '.join(TRAJECTORIES)}")
    segments = TRAJECTORIES[trajectory_name]
    joint_text, design, bearing = _joint(joint, design, rotation_deg)
    design = _design(design)
    effects = _effects(effects)
    if bearing is None and any(cat.EFFECTS[e].needs == "bearing" for e in effects):
        raise ParameterError(
            "effects", "bearing_friction", "needs the joint's geometry: give its manifest (--manifest)"
        )
    values = _true_params(design, effects, params)
    noise = _noise(noise)
    exps = _experiments(experiments)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ParameterError("seed", seed, "must be an integer >= 0")
    if isinstance(samples, bool) or not isinstance(samples, int) or not MIN_SAMPLES <= samples <= MAX_SAMPLES:
        raise ParameterError("samples", samples, f"must be an integer in [{MIN_SAMPLES}, {MAX_SAMPLES}]")
    rotation_deg = _number("rotation", rotation_deg, unit="deg")
    in_range("rotation", rotation_deg, 0.0, 360.0, lo_open=True, unit="deg", limit="must be in (0, 360]")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise RjcadError(f"{out}: exists and is not a directory")

    model = JointModel(pulley_radius=design["pulley_radius_mm"], **cat.model_kwargs(values))
    t, theta = trajectory(samples, rotation_deg * DEG, segments)
    direction = motion_direction(theta)
    rng = np.random.default_rng(seed)
    files: dict[str, str] = {}
    for e in exps:
        setup = Setup(e["drive"], e["normal_load_n"], e["routed"], bearing=bearing if e["drive"] == "tendon" else None)
        y_true = simulate(model, setup, theta, t=t)
        theta_meas = np.degrees(theta) + rng.normal(0.0, noise["theta_deg"], samples)
        y = y_true + rng.normal(0.0, noise[e["quantity"]], samples)
        if e["drive"] == "tendon":
            rel = direction < 0
            e["slack_fraction"] = float(np.mean(y_true <= 0.0))
            e["slack_release_fraction"] = float(np.mean(y_true[rel] <= 0.0)) if rel.any() else 0.0
        files[e["file"]] = _csv(t, theta_meas, y, e["quantity"])
    truth = {
        "synthetic": True,
        "generator": "rjcad bench",
        "note": "SYNTHETIC data simulated from rjcad's joint model (rjcad/physics/joint.py), not measured",
        "design": design,
        "effects": list(effects),
        "params": values,
        "noise": noise,
        "seed": seed,
        "samples": samples,
        "rotation_deg": rotation_deg,
        "trajectory": {
            "duration_s": float(t[-1]),
            "sample_rate_hz": (samples - 1) / float(t[-1]),
            "ramp": "minimum-jerk",
            "segments_s_start_end": [list(s) for s in segments],
            **({"name": trajectory_name} if trajectory_name != "paper" else {}),
        },
        "experiments": exps,
    }
    if joint_text is not None:
        truth["joint"] = {"file": JOINT_FILE, "source": str(joint)}
        files[JOINT_FILE] = joint_text
    files["truth.json"] = json.dumps(truth, indent=2) + "\n"
    files["README.md"] = _readme(truth)
    files["campaign.toml"] = _toml(truth)
    write_set(out, files)
    return truth
