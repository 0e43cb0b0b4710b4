"""Errors in variables: the viscous term's velocity is estimated from a noisy angle, which biases c low.

The viscous regressor is v̂ = v + u, u the angle noise through the derivative kernel (σ_v per sample,
``Motion.velocity_sigma``). Least squares then solves (X̂ᵀX̂)β̂ = X̂ᵀy with E[X̂ᵀX̂] = XᵀX + D,
D = diag(…, Σᵢ (sᵢ·σ_v/σ_y)², …) on the viscous coefficient (sᵢ = ∂ŷᵢ/∂(c·v̂ᵢ): 1 for a bar, β/r on a
taut tendon, 0 where it is slack), so β̂ ≈ (XᵀX + D)⁻¹XᵀXβ: attenuated towards zero.
The corrected estimate (corrected least squares, linearised at the fit, whitened units):

    β = β̂ + (J̃ᵀJ̃ − D)⁻¹·D·β̂,   J̃ the whitened residual Jacobian of the fit.

The velocity's own smoothing bias (θ‴·w²) is not noise and is not corrected here.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rjcad.identify.catalogue import model_kwargs
from rjcad.identify.fit import FitResult, Problem
from rjcad.physics.joint import JointModel, simulate

VISCOUS = "viscous_nmm_s_per_rad"
#: The correction is applied only while the noise's share of the regressor's power stays below this:
#: beyond it the velocity is mostly noise and the corrected estimate would be unstable.
MAX_NOISE_SHARE = 0.5


def noise_power(values: dict[str, float], prob: Problem) -> float:
    """D: Σ over experiments and fitted samples of (sᵢ·σ_v/σ_y)², the velocity noise's whitened power."""
    total = 0.0
    for p in prob.prepared:
        if p.motion.velocity_sigma <= 0:
            continue
        m = JointModel(pulley_radius=p.exp.pulley_radius, **model_kwargs({**values, VISCOUS: 1.0}))
        args = (m, p.exp.setup, p.motion.theta)
        kw: dict[str, Any] = {"t": p.exp.t, "direction": p.motion.direction}
        s = simulate(*args, **kw, velocity_=p.motion.velocity + 1.0) - simulate(
            *args, **kw, velocity_=p.motion.velocity
        )
        total += float(np.sum((s[p.valid] * p.motion.velocity_sigma / p.sigma) ** 2))
    return total


def correct_viscous(fr: FitResult, prob: Problem, lower, upper) -> tuple[FitResult, str | None]:
    """``fr`` with the viscous coefficient (and the parameters correlated with it) corrected; a note or None."""
    if VISCOUS not in fr.names or fr.jac.shape[0] == 0:
        return fr, None
    i = fr.names.index(VISCOUS)
    d = noise_power(fr.values, prob)
    a = fr.jac.T @ fr.jac
    if d <= 0:
        return fr, None
    if d >= MAX_NOISE_SHARE * a[i, i]:
        return fr, (
            f"the velocity is mostly angle noise ({100 * d / a[i, i]:.0f} % of its power): "
            f"viscous_nmm_s_per_rad = {fr.values[VISCOUS]:.4g} is biased low and was not corrected"
        )
    a[i, i] -= d
    x = fr.x + np.linalg.solve(a, d * fr.x[i] * np.eye(len(fr.names))[i])
    x = np.clip(x, np.asarray(lower, float), np.asarray(upper, float))
    vals = prob.values(fr.names, x)
    bic, rss, ns = prob.bic(vals, len(fr.names))
    cost = 0.5 * sum(float(np.sum(q**2)) for q in prob.residuals(vals))
    share = 100 * d / (a[i, i] + d)
    out = FitResult(fr.names, vals, x, fr.jac, rss, ns, bic, cost)
    return out, (
        f"viscous_nmm_s_per_rad corrected for the angle noise in its velocity (errors in variables): "
        f"{fr.values[VISCOUS]:.4g} → {vals[VISCOUS]:.4g} (noise {share:.1f} % of the velocity's power)"
    )
