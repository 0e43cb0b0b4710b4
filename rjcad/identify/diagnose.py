"""Residual diagnostics that point to a physical cause.

On the valid samples of one experiment, the residual r = y − ŷ (quantity units) is regressed on
[1, θ_j, θ_j², s, s·θ_j] (s = motion direction, θ_j rad): the s-terms are the half-width of the
hysteresis band and its growth with angle, the others the offset, slope and curvature of its
centre line. The part left over is then regressed on θ̇ (damping), and each hold's drift is read.
"""

from __future__ import annotations

import numpy as np

from rjcad.identify.fit import Prepared
from rjcad.identify.signal import runs


def angle_direction_fit(p: Prepared, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares fit of r on [1, θ_j, θ_j², s, s·θ_j] over the valid samples: (coefficients, design matrix)."""
    ok = p.valid
    th, s = p.motion.theta[ok], p.motion.direction[ok]
    X = np.column_stack([np.ones_like(th), th, th**2, s, s * th])
    coef, *_ = np.linalg.lstsq(X, r[ok], rcond=None)
    return coef, X


def diagnose(p: Prepared, r: np.ndarray) -> dict:
    """Band, centre line, velocity and hold features of residual ``r`` (full length, quantity units)."""
    m, ok = p.motion, p.valid
    th, v = m.theta[ok], m.velocity[ok]
    rr = r[ok]
    out = {"quantity": p.exp.quantity, "noise": p.sigma, "rmse": float(np.sqrt(np.mean(rr**2))) if len(rr) else 0.0}
    if len(rr) < 10:
        return out | {"hints": []}
    lo, hi = float(th.min()), float(th.max())
    coef, X = angle_direction_fit(p, r)
    band = [float(coef[3] + coef[4] * lo), float(coef[3] + coef[4] * hi)]
    centre = X[:, :3] @ coef[:3]
    left = rr - X @ coef
    moving = np.abs(v) > 0.05 * (np.percentile(np.abs(v), 95) + 1e-12)
    vel_slope = 0.0
    if moving.sum() > 10:
        vm = v[moving]
        vel_slope = float(np.dot(vm, left[moving]) / max(np.dot(vm, vm), 1e-300))
    drifts = _hold_drifts(p, r)
    out.update(
        {
            "band_halfwidth": band,  # at the smallest and largest angle
            "centre_offset": float(centre[np.argmin(th)]),  # centre line at the smallest angle
            "centre_change": float(centre[np.argmax(th)] - centre[np.argmin(th)]),
            "centre_curvature": float(coef[2] * (hi - lo) ** 2 / 4),  # sag of the centre line mid-range
            "velocity_slope": vel_slope,  # residual per rad/s
            "velocity_effect": float(vel_slope * np.percentile(np.abs(v), 95)),
            "hold_drift": drifts,  # change of r over each hold
            "angle_range_rad": [lo, hi],
        }
    )
    out["hints"] = _hints(out, p)
    return out


def _hold_drifts(p: Prepared, r: np.ndarray) -> list[float]:
    """For each hold, mean r over its last fifth minus over its first fifth, signed by the preceding motion."""
    out = []
    for a, b in runs(p.motion.hold & p.valid):
        k = max((b - a) // 5, 1)
        if b - a >= 10:
            out.append(float((r[b - k : b].mean() - r[a : a + k].mean()) * p.motion.direction[a]))
    return out


def _hints(d: dict, p: Prepared) -> list[dict]:
    """Which catalogue effects the features point to, with the evidence in words."""
    q = "N·mm" if p.exp.quantity == "torque_nmm" else "N"
    floor = max(2 * p.sigma, 0.01 * p.span)
    hints = []
    b0, b1 = d["band_halfwidth"]
    if max(abs(b0), abs(b1)) > floor:
        grows = abs(b1 - b0) > 0.3 * max(abs(b0), abs(b1))
        if grows and p.exp.drive == "tendon":
            ids = ["tendon_pin_friction", "capstan_path"] if p.exp.routed else ["tendon_pin_friction"]
            hints.append(
                {
                    "effects": ids,
                    "evidence": f"the residual splits by direction into a band that grows "
                    f"with angle ({b0:.3g} → {b1:.3g} {q} half-width)",
                }
            )
        else:
            if p.exp.normal_load > 0:
                ids = ["coulomb_pin"]
            else:  # no transverse load: only the tendon's own load or rate effects can open a band
                ids = ["tendon_pin_friction"] if p.exp.drive == "tendon" else ["viscous", "relaxation"]
            hints.append(
                {
                    "effects": ids,
                    "evidence": f"the residual splits by direction into a band "
                    f"{'about constant' if not grows else 'changing'} in angle "
                    f"({b0:.3g} → {b1:.3g} {q} half-width)",
                }
            )
    if abs(d["centre_curvature"]) > floor:
        hints.append(
            {
                "effects": ["stiffening"],
                "evidence": f"the centre line bends ({d['centre_curvature']:.3g} {q} "
                "mid-range sag): the torque grows faster than linearly",
            }
        )
    if abs(d["centre_offset"]) > floor or abs(d["centre_change"]) > floor:
        hints.append(
            {
                "effects": ["spring_calibration"],
                "evidence": f"the centre line is offset ({d['centre_offset']:.3g} "
                f"{q}) and tilted ({d['centre_change']:+.3g} {q} "
                "across the range): stiffness or preload differ",
            }
        )
    if abs(d["velocity_effect"]) > floor:
        hints.append(
            {
                "effects": ["viscous"],
                "evidence": f"the residual follows the velocity ({d['velocity_slope']:.3g} "
                f"{q} per rad/s, {d['velocity_effect']:.3g} {q} at speed)",
            }
        )
    drifts = d["hold_drift"]
    # a drift is a difference of two means over a fifth of a hold each: its noise is far below σ
    n_hold = int((p.motion.hold & p.valid).sum())
    k = max(n_hold // max(5 * len(drifts), 1), 1)
    drift_floor = max(3 * p.sigma * (2 / k) ** 0.5 / max(len(drifts), 1) ** 0.5, 0.01 * p.span)
    if drifts and abs(float(np.median(drifts))) > drift_floor:
        hints.append(
            {
                "effects": ["relaxation"],
                "evidence": f"the residual drifts during holds (median "
                f"{float(np.median(drifts)):+.3g} {q} per hold, against "
                "the preceding motion): the torque relaxes",
            }
        )
    return hints
