"""A joint bench written for the tests, apart from rjcad's model: a campaign whose data hold one effect outside
rjcad's catalogue.

The joint is driven through a triangle of angles with holds at both ends; the measured quantity is the spring's
torque K(t, d)·(θ + θ₀) (bar) or that torque over the pulley radius (tendon, no friction), with Gaussian noise on
the angle and on the quantity. The hidden effects: ``drift`` (K from (1 + size) to (1 − size) over each run),
``direction`` (K·(1 + size·d), d = +1 while the angle grows, −1 while it falls, held through a hold) and
``backlash`` (a play of ``size`` degrees between the spring and the measured link).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

K, PRELOAD_DEG, PULLEY_MM = 5.2, 70.0, 6.0
NOISE = {"theta_deg": 0.1, "torque_nmm": 0.1, "tendon_force_n": 0.02}


def path(cycles: int = 4, rise_s: float = 4.0, hold_s: float = 1.5, top_deg: float = 90.0, samples: int = 3000):
    """(t [s], true angle [deg], d): up, hold, down, hold, ``cycles`` times."""
    period = 2 * (rise_s + hold_s)
    t = np.linspace(0.0, cycles * period, samples)
    u = np.mod(t, period)
    up, top, down = u < rise_s, (u >= rise_s) & (u < rise_s + hold_s), (u >= rise_s + hold_s) & (u < period - hold_s)
    theta = np.where(up, u / rise_s, np.where(top, 1.0, np.where(down, 1.0 - (u - rise_s - hold_s) / rise_s, 0.0)))
    d = np.where(up | top, 1.0, -1.0)
    return t, top_deg * theta, d


def play(theta_deg, width_deg: float):
    """The angle the spring sees through a backlash of ``width_deg`` between it and the measured link (a play
    operator: it follows only once the link has taken up the play) [deg]."""
    out = np.empty_like(theta_deg)
    s = theta_deg[0] - width_deg / 2
    for i, x in enumerate(theta_deg):
        s = min(max(s, x - width_deg / 2), x + width_deg / 2)
        out[i] = s
    return out


def torque(effect: str, size: float, t, theta_deg, d):
    """The spring's torque with the hidden effect [N·mm]; for ``backlash``, ``size`` is the play [deg]."""
    if effect == "backlash":
        return K * np.radians(play(theta_deg, size) + PRELOAD_DEG)
    factor = {"drift": 1.0 + size * (1.0 - 2.0 * t / t[-1]), "direction": 1.0 + size * d, "none": 1.0}[effect]
    return K * factor * np.radians(theta_deg + PRELOAD_DEG)


def write(
    folder: Path,
    effect: str,
    size: float = 0.05,
    seed: int = 0,
    stiffness: float = K,
    viscous: float = 0.0,
    theta_noise_deg: float = NOISE["theta_deg"],
) -> Path:
    """A bar and a tendon experiment with ``effect`` hidden in them; returns the campaign TOML's path. The design
    says K; the joint has ``stiffness`` and a damping torque ``viscous``·θ̇ [N·mm·s/rad] (catalogue effects, made
    here by this bench's own code)."""
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    toml = [
        f"# written by tests/hidden_bench.py: hidden effect {effect} ({size:g})",
        "[design]",
        f"stiffness_nmm_per_rad = {K}",
        f"preload_deg = {PRELOAD_DEG}",
        f"pulley_radius_mm = {PULLEY_MM}",
    ]
    for name, drive, quantity in (("bar", "bar", "torque_nmm"), ("tendon", "tendon", "tendon_force_n")):
        t, theta, d = path()
        omega = np.gradient(np.radians(theta), t)
        tau = torque(effect, size, t, theta, d) * stiffness / K + viscous * omega
        y = tau / (1.0 if drive == "bar" else PULLEY_MM)
        theta_m = theta + rng.normal(0.0, theta_noise_deg, len(t))
        y_m = y + rng.normal(0.0, NOISE[quantity], len(t))
        rows = [f"t_s,theta_deg,{quantity}"] + [f"{a:.5f},{b:.5f},{c:.6f}" for a, b, c in zip(t, theta_m, y_m)]
        (folder / f"{name}.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
        toml += ["", "[[experiment]]", f'file = "{name}.csv"', f'drive = "{drive}"', "normal_load_n = 0.0"]
        toml.append("routed = false")
    out = folder / "campaign.toml"
    out.write_text("\n".join(toml) + "\n", encoding="utf-8")
    return out


def stiffness_drift_coefficient(size: float) -> float:
    """The truth in the proposal's terms: K changes by −2·size over a run (c of ``c·s·τ``)."""
    return -2.0 * size


assert math.isclose(stiffness_drift_coefficient(0.05), -0.1)
