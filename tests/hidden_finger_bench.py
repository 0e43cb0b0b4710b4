"""A whole-finger bench written for the tests, apart from rjcad's finger model: a campaign whose data hold one
effect outside rjcad's catalogue.

The finger is the default one's design (three joints, K = 5.2, 7.8, 10.4 N·mm/rad, 90° preload, 90° range, 6 mm
moment arms), frictionless with an inextensible tendon: for a tendon path p the tension T solves
Σ r_j·clip(T·r_j/K_j − θ0_j, 0, θmax_j) = p (by bisection here), each joint then sits at that clip. The hidden
effects: ``drift`` (every K from (1 + size) to (1 − size) over each run), ``direction`` (K·(1 + size·d), d = +1
while the tendon is pulled, −1 while released, held through a hold) and ``backlash`` (a play of ``size`` mm
between the actuator, whose path is recorded, and the tendon). Gaussian noise on the path, the angles and T.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

K = np.array([5.2, 7.8, 10.4])
PRELOAD = np.radians([90.0, 90.0, 90.0])
RANGE = np.radians([90.0, 90.0, 90.0])
ARM = np.array([6.0, 6.0, 6.0])
NOISE = {"theta_deg": 0.3, "tendon_force_n": 0.02, "tendon_mm": 0.005}
FINGER_TOML = (Path(__file__).parents[1] / "templates" / "finger.toml").read_text(encoding="utf-8")
#: (file, orientation, moves as (duration s, from, to) in units of the stroke): cosine ramps
MOVES = (
    (
        "up_down.csv",
        "horizontal-palm-up",
        ((1.0, 0, 0), (5.0, 0, 1), (5.0, 1, 0), (1.0, 0, 0), (2.0, 0, 1), (2.0, 1, 0)),
    ),
    ("turns.csv", "horizontal-palm-down", ((1.0, 0, 0), (5.0, 0, 1), (3.0, 1, 0.3), (3.0, 0.3, 1), (5.0, 1, 0))),
    (
        "holds.csv",
        "vertical-tip-down",
        ((1.0, 0, 0), (5.0, 0, 1), (2.0, 1, 1), (3.0, 1, 0.5), (2.0, 0.5, 0.5), (3.0, 0.5, 0)),
    ),
)


def stroke_path(moves, stroke: float, samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t [s], actuator path [mm], d): cosine ramps between the moves' ends; d = sign of the last move."""
    ends = np.cumsum([0.0] + [m[0] for m in moves])
    t = np.linspace(0.0, ends[-1], samples)
    p, d = np.empty(samples), np.empty(samples)
    last = 1.0
    for (dur, a, b), t0 in zip(moves, ends[:-1]):
        on = (t >= t0) & (t <= t0 + dur)
        u = (t[on] - t0) / dur
        p[on] = stroke * (a + (b - a) * (1.0 - np.cos(np.pi * u)) / 2.0)
        last = last if a == b else float(np.sign(b - a))
        d[on] = last
    return t, p, d


def play(x, width: float):
    """``x`` seen through a play of ``width`` (it follows only once the play is taken up)."""
    out = np.empty_like(x)
    s = x[0]
    for i, v in enumerate(x):
        s = min(max(s, v - width / 2), v + width / 2)
        out[i] = s
    return out


def closure(p, k):
    """(θ (n, 3) [rad], T [N]) for tendon path ``p`` [mm] and stiffnesses ``k`` (n, 3), by bisection on T."""
    lo, hi = np.zeros(len(p)), np.full(len(p), float(np.max(k * (RANGE + PRELOAD) / ARM)) * 2)
    for _ in range(80):
        T = (lo + hi) / 2
        th = np.clip(T[:, None] * ARM / k - PRELOAD, 0.0, RANGE)
        short = th @ ARM < p
        lo, hi = np.where(short, T, lo), np.where(short, hi, T)
    T = np.where(p > 0, (lo + hi) / 2, 0.0)
    return np.clip(T[:, None] * ARM / k - PRELOAD, 0.0, RANGE), T


def write(
    folder: Path, effect: str, size: float, seed: int = 0, joints=(1, 2, 3), samples: int = 3000, stroke: float = 25.0
) -> Path:
    """The campaign (finger.toml, campaign.toml, one CSV per move set) with ``effect`` hidden (a spring's effect in
    the springs of ``joints``); the TOML's path."""
    on = np.isin(np.arange(1, 4), joints)
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "finger.toml").write_text(FINGER_TOML, encoding="utf-8")
    toml = [f"# written by tests/hidden_finger_bench.py: hidden effect {effect} ({size:g})", 'finger = "finger.toml"']
    for name, orientation, moves in MOVES:
        t, p, d = stroke_path(moves, stroke, samples)
        tau = (t / t[-1] - 0.5)[:, None]
        change = {"drift": -2.0 * size * tau, "direction": size * d[:, None]}.get(effect, 0.0 * tau)
        k = K * (1.0 + change * on)
        theta, T = closure(play(p, size) if effect == "backlash" else p, k)
        cols = {
            "t_s": t,
            "tendon_mm": p + rng.normal(0, NOISE["tendon_mm"], samples),
            "tendon_force_n": T + rng.normal(0, NOISE["tendon_force_n"], samples),
        }
        for j in range(3):
            cols[f"theta{j + 1}_deg"] = np.degrees(theta[:, j]) + rng.normal(0, NOISE["theta_deg"], samples)
        rows = [",".join(cols)] + [",".join(f"{v:.6f}" for v in r) for r in zip(*cols.values())]
        (folder / name).write_text("\n".join(rows) + "\n", encoding="utf-8")
        toml += ["", "[[experiment]]", f'file = "{name}"', 'drive = "finger"', f'orientation = "{orientation}"']
    out = folder / "campaign.toml"
    out.write_text("\n".join(toml) + "\n", encoding="utf-8")
    return out
