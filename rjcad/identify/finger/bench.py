"""Synthetic whole-finger campaigns (``rjcad bench --finger``): pull/release records simulated from the finger
model with chosen effects, and noise. The data are SYNTHETIC.

Three experiments, each with its own orientation (so link weight has something to act on):
A: two full pulls, finger horizontal palm up, the second 2.7× faster (ramps of 4 and 1.5 s); B: a pull that turns
back at 40 % of the stroke and closes again, palm down; C: pulls with holds at full and half stroke, tip down.
Minimum-jerk ramps.
Columns: t_s, tendon_mm, tendon_force_n (unless ``tension=False``), theta1_deg … thetaN_deg.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from rjcad import DEG
from rjcad.errors import ParameterError, RjcadError
from rjcad.identify.finger.catalogue import actuator_tension, catalogue, model_of
from rjcad.identify.finger.data import ORIENTATIONS, as_designed, design_from_file
from rjcad.io.outputs import write_set
from rjcad.paper import FINGER
from rjcad.physics.finger import simulate_angles

DEFAULT_NOISE = {"theta_deg": 0.3, "tendon_force_n": 0.02, "tendon_mm": 0.005}
#: (name, orientation, segments as (duration s, start, end) in units of the stroke)
EXPERIMENTS = (
    ("A_pulls", "horizontal-palm-up", ((1.0, 0, 0), (4.0, 0, 1), (4.0, 1, 0), (1.0, 0, 0), (1.5, 0, 1), (1.5, 1, 0))),
    (
        "B_turns",
        "horizontal-palm-down",
        ((1.0, 0, 0), (4.0, 0, 1), (2.5, 1, 0.4), (2.5, 0.4, 1), (4.0, 1, 0), (1.0, 0, 0), (4.0, 0, 1), (4.0, 1, 0)),
    ),
    (
        "C_holds",
        "vertical-tip-down",
        (
            (1.0, 0, 0),
            (4.0, 0, 1),
            (2.0, 1, 1),
            (2.0, 1, 0.5),
            (2.0, 0.5, 0.5),
            (2.0, 0.5, 0),
            (1.0, 0, 0),
            (4.0, 0, 1),
            (4.0, 1, 0),
        ),
    ),
)
#: Per-joint factors of the typical sizes: each joint differs, as printed joints do.
K_FACTORS = (0.85, 0.92, 0.78, 0.88, 0.95, 0.83)
ARM_FACTORS = (1.1, 1.3, 1.5, 1.2, 1.4, 1.25)
FRICTION = (1.5, 1.0, 0.7, 1.2, 0.9, 0.6)
VISCOUS = (0.6, 0.4, 0.3, 0.5, 0.35, 0.45)
CUBIC = (0.15, 0.2, 0.1, 0.12, 0.18, 0.14)


def path(samples: int, stroke: float, segments) -> tuple[np.ndarray, np.ndarray]:
    """Uniform t [s] and the tendon displacement [mm], minimum-jerk ramps between the segments' ends."""
    dur = np.array([s[0] for s in segments])
    a = np.array([s[1] for s in segments]) * stroke
    b = np.array([s[2] for s in segments]) * stroke
    t0 = np.r_[0.0, np.cumsum(dur)]
    t = np.linspace(0.0, t0[-1], samples)
    k = np.clip(np.searchsorted(t0, t, side="right") - 1, 0, len(dur) - 1)
    u = np.clip((t - t0[k]) / dur[k], 0.0, 1.0)
    return t, a[k] + (b[k] - a[k]) * u**3 * (10 - 15 * u + 6 * u**2)


def _pulling(td: np.ndarray) -> np.ndarray:
    """True while the tendon is pulled; a hold keeps the direction of the move before it."""
    d = np.sign(np.diff(td, prepend=td[0]))
    idx = np.where(d != 0, np.arange(len(d)), 0)
    np.maximum.accumulate(idx, out=idx)
    return np.where(d[idx] != 0, d[idx] > 0, True)


def typical(effects, design) -> dict[str, float]:
    """Every catalogue parameter: neutral, or for the chosen effects a realistic size (per joint: they differ)."""
    cat = {e.id: e for e in catalogue(design)}
    vals: dict[str, float] = {}
    for e in cat.values():
        vals.update(e.neutral(None))
    for eid in effects:
        vals.update(cat[eid].typical(None))
    for j in range(1, design.n + 1):
        i = (j - 1) % len(K_FACTORS)
        if "spring_calibration" in effects:
            vals[f"stiffness_nmm_per_rad_j{j}"] = K_FACTORS[i] * design.stiffness[j - 1]
        if "moment_arm" in effects:
            vals[f"tendon_moment_arm_mm_j{j}"] = ARM_FACTORS[i] * design.moment_arm[j - 1]
        if "coulomb_pin" in effects:
            vals[f"friction_nmm_j{j}"] = FRICTION[i]
        if "viscous" in effects:
            vals[f"viscous_nmm_s_per_rad_j{j}"] = VISCOUS[i]
        if "stiffening" in effects:
            vals[f"cubic_nmm_per_rad3_j{j}"] = CUBIC[i]
    return vals


def _template_text(d: dict) -> str:
    lines = [f"{k} = {json.dumps(v)}" for k, v in d.items() if not isinstance(v, (dict, list))]
    lines += ["", "[defaults]"] + [f"{k} = {json.dumps(v)}" for k, v in d.get("defaults", {}).items()]
    for j in d.get("joint", []):
        lines += ["", "[[joint]]"] + [f"{k} = {json.dumps(v)}" for k, v in j.items()]
    return "\n".join(lines) + "\n"


def _check_options(out: Path, samples, noise, stroke) -> None:
    """Refuse a bad sample count, noise column or level, stroke, or an output path that is a file."""
    if isinstance(samples, bool) or not isinstance(samples, int) or not 100 <= samples <= 200_000:
        raise ParameterError("samples", samples, "must be an integer in [100, 200000]")
    for k, v in (noise or {}).items():
        if k not in DEFAULT_NOISE:
            raise ParameterError("noise", k, f"unknown column; known: {', '.join(DEFAULT_NOISE)}")
        if not (isinstance(v, (int, float)) and 0 <= v < 1e3):
            raise ParameterError(f"noise {k}", v, "must be a number in [0, 1000)")
    if not 0 < stroke <= 1000:
        raise ParameterError("stroke", stroke, "must be in (0, 1000] mm")
    if out.exists() and not out.is_dir():
        raise RjcadError(f"{out}: exists and is not a directory")


def write_finger_campaign(
    out_dir,
    effects=(),
    params=None,
    *,
    finger=None,
    seed=0,
    noise=None,
    samples=3000,
    stroke=FINGER.stroke,
    tension=True,
) -> dict:
    """Write campaign.toml, finger.(toml|json), one CSV per experiment, truth.json and README.md; return the truth.

    ``finger``: a finger manifest (.json) or template (.toml); None: the default finger (templates/finger.toml).
    """
    out = Path(out_dir)
    _check_options(out, samples, noise, stroke)
    if finger is None:
        from rjcad.io.templates import DEFAULT_FINGER
        from rjcad.physics.finger import model_from_template

        finger_name, finger_bytes = "finger.toml", _template_text(DEFAULT_FINGER).encode()
        design = as_designed(model_from_template(DEFAULT_FINGER), finger_name).model
    else:
        from rjcad.io.untrusted import read_bytes

        src = Path(finger)
        finger_name, finger_bytes = "finger" + src.suffix.lower(), read_bytes(src, "text", f"--source: {finger}")
        design = design_from_file(src, finger, "--source").model
    cat = {e.id: e for e in catalogue(design)}
    unknown = [e for e in effects if e not in cat]
    if unknown:
        raise ParameterError("effects", unknown[0], f"unknown; known: {', '.join(cat)}")
    values = typical(effects, design)
    for k, v in (params or {}).items():
        if k not in values:
            raise ParameterError("param", k, "unknown; known: " + ", ".join(values))
        values[k] = float(v)
    sig = dict(DEFAULT_NOISE, **(noise or {}))
    rng = np.random.default_rng(seed)
    campaign_toml = f'finger = "{finger_name}"\n'
    files: dict[str, bytes | str] = {finger_name: finger_bytes, "campaign.toml": campaign_toml}
    exps = []
    for name, orient, segs in EXPERIMENTS:
        t, td = path(samples, stroke, segs)
        theta, T = simulate_angles(model_of(values, design, ORIENTATIONS[orient]), td, t)
        pulling = _pulling(td)
        cols = {"t_s": t, "tendon_mm": td + rng.normal(0, sig["tendon_mm"], samples)}
        if tension:
            cols["tendon_force_n"] = actuator_tension(values, T, pulling) + rng.normal(
                0, sig["tendon_force_n"], samples
            )
        for i in range(design.n):
            cols[f"theta{i + 1}_deg"] = theta[:, i] / DEG + rng.normal(0, sig["theta_deg"], samples)
        header = ",".join(cols)
        body = "\n".join(",".join(f"{v:.6f}" for v in row) for row in zip(*cols.values()))
        files[f"{name}.csv"] = header + "\n" + body + "\n"
        campaign_toml += f'\n[[experiment]]\nfile = "{name}.csv"\ndrive = "finger"\norientation = "{orient}"\n'
        exps.append({"file": f"{name}.csv", "orientation": orient})
    files["campaign.toml"] = campaign_toml
    truth = {
        "synthetic": True,
        "generator": "rjcad bench --finger",
        "note": "SYNTHETIC data simulated from rjcad's finger model (rjcad/physics/finger.py), not measured",
        "finger": finger_name,
        "effects": list(effects),
        "params": {k: v for k, v in values.items() if any(k in cat[e].param_names for e in effects)},
        "noise": sig,
        "seed": seed,
        "samples": samples,
        "stroke_mm": stroke,
        "tension": tension,
        "experiments": exps,
    }
    files["truth.json"] = json.dumps(truth, indent=2) + "\n"
    files["README.md"] = _readme(effects, sig, seed, samples, stroke)
    write_set(out, files)
    return truth


def _readme(effects, sig, seed, samples, stroke) -> str:
    """The campaign's README.md: SYNTHETIC, what made it, its effects and noise, the experiments."""
    return (
        "# SYNTHETIC whole-finger campaign\n\nSimulated by `rjcad bench --finger` from rjcad's finger "
        "model, not measured. Effects in the truth: "
        + (", ".join(f"`{e}`" for e in effects) or "none (the design model)")
        + f"; noise σ: {sig}; seed {seed}; {samples} samples per experiment; stroke {stroke:g} mm."
        "\n\nExperiments: A two full pulls (palm up; the second 2.7× faster), B a pull that turns back at 40 % and closes "
        "again (palm down), C pulls with holds at full and half stroke (tip down).\n"
    )
