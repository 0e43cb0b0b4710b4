"""Joint fit of all experiments of a campaign with shared parameters (bounded nonlinear least squares).

Residuals are whitened per experiment by its noise σ_e (estimated from the data), so torques
[N·mm] and tendon forces [N] weigh alike. Information criterion, profiling each σ_e:
BIC = Σ_e n_e·ln(RSS_e/n_e) + k·ln N.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from rjcad.identify.catalogue import EFFECTS, model_kwargs
from rjcad.identify.data import Campaign, Experiment
from rjcad.identify.signal import Motion, analyse_motion, noise_sigma, spikes
from rjcad.physics.joint import JointModel, simulate


@dataclass(frozen=True, eq=False)
class Prepared:
    """One experiment ready for fitting: its data, its motion analysis, noise and range."""

    exp: Experiment
    motion: Motion
    sigma: float  # noise σ of the measured quantity (its units)
    span: float  # measured range (0.5–99.5 percentile) of the quantity
    folds: np.ndarray  # int per sample: held-out fold (−1: always trained on)
    outliers: np.ndarray  # bool: load-cell spikes in the quantity (left out)

    @property
    def valid(self) -> np.ndarray:
        return self.motion.valid & ~self.outliers


def prepare(campaign: Campaign, n_folds: int = 2) -> list[Prepared]:
    """Analyse each experiment's motion; held-out folds are whole cycles (cycle index mod n_folds)."""
    out = []
    for e in campaign.experiments:
        m = analyse_motion(e.t, e.theta)
        sig = noise_sigma(e.y)
        spiky = spikes(e.y, sig)
        lo, hi = np.percentile(e.y[m.valid] if m.valid.any() else e.y, [0.5, 99.5])
        span = float(hi - lo)
        sig = max(sig, 1e-6 * max(span, 1e-12), 1e-12)
        folds = m.cycle % n_folds if m.n_cycles >= n_folds else np.full(len(e.t), -1)
        out.append(Prepared(exp=e, motion=m, sigma=sig, span=span, folds=folds, outliers=spiky))
    return out


def base_values(campaign: Campaign) -> dict[str, float]:
    """Every catalogue parameter at its design or neutral value (JSON units)."""
    d = campaign.design.as_json()
    vals = {}
    for eff in EFFECTS.values():
        vals.update(eff.neutral(d))
    return vals


def predict(values: dict[str, float], p: Prepared) -> np.ndarray:
    """The model's measured quantity along the experiment's smoothed angle path."""
    m = JointModel(pulley_radius=p.exp.pulley_radius, **model_kwargs(values))
    return simulate(
        m, p.exp.setup, p.motion.theta, t=p.exp.t, direction=p.motion.direction, velocity_=p.motion.velocity
    )


@dataclass
class FitResult:
    names: tuple[str, ...]  # free parameters
    values: dict[str, float]  # all parameters (JSON units)
    x: np.ndarray
    jac: np.ndarray  # whitened residual Jacobian at x (all valid samples)
    rss: list[float]  # per experiment, in its units², valid samples
    n: list[int]
    bic: float
    cost: float

    @property
    def k(self) -> int:
        return len(self.names)

    def rmse(self) -> list[float]:
        return [math.sqrt(r / max(n, 1)) for r, n in zip(self.rss, self.n)]


class Problem:
    """The campaign's least-squares problem for a set of free parameters (others fixed)."""

    def __init__(self, campaign: Campaign, prepared: list[Prepared], fixed: dict[str, float]):
        self.campaign = campaign
        self.prepared = prepared
        self.fixed = dict(fixed)
        self.N = int(sum(int(p.valid.sum()) for p in prepared))

    def values(self, names, x) -> dict[str, float]:
        v = dict(self.fixed)
        v.update({n: float(xi) for n, xi in zip(names, x)})
        return v

    def residuals(self, values: dict[str, float], masks=None) -> list[np.ndarray]:
        """Whitened residuals (y − ŷ)/σ_e per experiment on ``masks`` (default: valid samples)."""
        out = []
        for i, p in enumerate(self.prepared):
            mask = p.valid if masks is None else masks[i]
            out.append((p.exp.y[mask] - predict(values, p)[mask]) / p.sigma)
        return out

    def bic(self, values: dict[str, float], k: int) -> tuple[float, list[float], list[int]]:
        rss, ns = [], []
        for p, r in zip(self.prepared, self.residuals(values)):
            rss.append(float(np.sum(r**2)) * p.sigma**2)
            ns.append(len(r))
        b = sum(n * math.log(max(s / n, 1e-300)) for s, n in zip(rss, ns) if n) + k * math.log(max(self.N, 2))
        return b, rss, ns

    def fit(self, names, x0, lower, upper, masks=None, max_nfev: int = 200) -> FitResult:
        """Bounded NLS (trust-region reflective) of the free ``names`` from ``x0``."""
        names = tuple(names)
        if not names:
            b, rss, ns = self.bic(self.fixed, 0)
            return FitResult(names, dict(self.fixed), np.zeros(0), np.zeros((self.N, 0)), rss, ns, b, 0.0)
        lo, hi = np.asarray(lower, float), np.asarray(upper, float)
        x0 = np.clip(np.asarray(x0, float), lo + 1e-9 * (np.abs(lo) + 1), hi - 1e-9 * (np.abs(hi) + 1))

        def fun(x):
            return np.concatenate(self.residuals(self.values(names, x), masks))

        res = least_squares(
            fun, x0, bounds=(lo, hi), method="trf", x_scale="jac", max_nfev=max_nfev, xtol=1e-10, ftol=1e-10, gtol=1e-10
        )
        vals = self.values(names, res.x)
        b, rss, ns = self.bic(vals, len(names))
        jac = res.jac if masks is None else np.zeros((0, len(names)))  # held-out fits need no Jacobian
        return FitResult(names, vals, res.x, np.asarray(jac), rss, ns, b, float(res.cost))


def _jacobian(fun, x, rel: float = 1e-6, upper=None) -> np.ndarray:
    """Forward-difference Jacobian; steps backwards where a forward step would cross ``upper``."""
    f0 = fun(x)
    J = np.empty((len(f0), len(x)))
    for j in range(len(x)):
        h = rel * max(abs(x[j]), 1.0)
        if upper is not None and x[j] + h > upper[j]:
            h = -h
        xp = x.copy()
        xp[j] += h
        J[:, j] = (fun(xp) - f0) / h
    return J


def unidentifiable(jac: np.ndarray, names, tol: float = 1e-6) -> dict[str, str]:
    """Parameters the data cannot determine: no sensitivity, or in a (near) null direction of J.

    Columns are scaled to unit norm; a singular value below ``tol``·s_max marks a null direction and
    every parameter with a component > 0.3 in it.
    """
    names = list(names)
    out: dict[str, str] = {}
    if not names:
        return out
    norms = np.linalg.norm(jac, axis=0)
    scale = max(float(norms.max()), 1e-300)
    live = [j for j in range(len(names)) if norms[j] > 1e-9 * scale]
    for j in range(len(names)):
        if j not in live:
            out[names[j]] = "the data do not depend on it"
    if len(live) >= 2:
        Jn = jac[:, live] / norms[live]
        _, s, vt = np.linalg.svd(Jn, full_matrices=False)
        for i, si in enumerate(s):
            if si < tol * s[0]:
                involved = [names[live[j]] for j in range(len(live)) if abs(vt[i, j]) > 0.3]
                for nm in involved:
                    others = [o for o in involved if o != nm]
                    out.setdefault(nm, "confounded with " + ", ".join(others) if others else "no sensitivity")
    return out


def confidence(fr: FitResult, prob: Problem) -> dict[str, tuple[float, float]]:
    """95% intervals from the Gauss–Newton covariance, s²·(JᵀJ)⁻¹, widened for residual autocorrelation.

    s² = χ²/(N − k); the widening factor is √((1+ρ)/(1−ρ)) with ρ the lag-1 autocorrelation of the residuals.
    """
    if not fr.names:
        return {}
    r = prob.residuals(fr.values)
    chi2 = sum(float(np.sum(x**2)) for x in r)
    s2 = chi2 / max(prob.N - fr.k, 1)
    rho = _lag1(r)
    infl = math.sqrt((1 + rho) / (1 - rho)) if rho > 0 else 1.0
    try:
        cov = np.linalg.pinv(fr.jac.T @ fr.jac) * s2
    except np.linalg.LinAlgError:
        return {}
    out = {}
    for j, n in enumerate(fr.names):
        half = 1.96 * math.sqrt(max(cov[j, j], 0.0)) * infl
        out[n] = (fr.values[n] - half, fr.values[n] + half)
    return out


def _lag1(res: list[np.ndarray]) -> float:
    num = den = 0.0
    for r in res:
        if len(r) > 2:
            r = r - r.mean()
            num += float(np.dot(r[1:], r[:-1]))
            den += float(np.dot(r, r))
    return min(num / den, 0.99) if den > 0 else 0.0


def param_names(effect_ids) -> tuple[str, ...]:
    """The JSON parameter names of ``effect_ids``, in catalogue order within each effect."""
    return tuple(n for e in effect_ids for n in EFFECTS[e].param_names)
