"""Censored-normal maximum likelihood for Table I's life laws, and their leave-one-out errors.

Models: log10 N ~ Normal(μ, s), μ = a − m·log10 σ_a (+ c·x for an effect x); a run-out contributes
P(log10 N > log10 bound) (a survival, not a failure). Maximum likelihood in Olsen's parameters
(γ = β/s, τ = 1/s), where the censored-normal log-likelihood is concave, by Newton's method; the
Basquin exponent is kept m ≥ 0 (a life that grows with stress is not physical). numpy only, so
``rjcad spring`` can report a predicted life without importing scipy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from statistics import NormalDist

import numpy as np

from rjcad.life.effects import EFFECTS
from rjcad.life.table import LifeData

#: Level of the predicted-life interval and of the --min-cycles constraint (two-sided).
LEVEL = 0.9
_SQRT2 = math.sqrt(2.0)
_LOG_SQRT_2PI = 0.5 * math.log(2 * math.pi)


def _log_phi_cdf(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """log Φ(q) and the inverse Mills ratio λ = φ(q)/Φ(q) (asymptotic form far in the lower tail)."""
    q = np.asarray(q, dtype=float)
    logc = np.empty_like(q)
    lam = np.empty_like(q)
    for i, v in enumerate(q.flat):
        if v > -30:
            c = 0.5 * math.erfc(-v / _SQRT2)
            logc.flat[i] = math.log(c)
            lam.flat[i] = math.exp(-0.5 * v * v - _LOG_SQRT_2PI - logc.flat[i])
        else:  # Φ(q) ≈ φ(q)/(−q)·(1 − 1/q²)
            logc.flat[i] = -0.5 * v * v - _LOG_SQRT_2PI - math.log(-v) + math.log1p(-1 / (v * v))
            lam.flat[i] = -v / (1 - 1 / (v * v))
    return logc, lam


def _ll(theta, W, cens):
    """Log-likelihood, gradient and Hessian in Olsen's θ = (γ, τ); W rows are [x, −y]."""
    eta = W @ theta
    tau = theta[-1]
    u = ~cens
    ll = np.sum(math.log(tau) - 0.5 * eta[u] ** 2 - _LOG_SQRT_2PI) if u.any() else 0.0
    g = -(eta[u][:, None] * W[u]).sum(axis=0)
    g[-1] += u.sum() / tau
    H = -W[u].T @ W[u]
    H[-1, -1] -= u.sum() / tau**2
    if cens.any():
        logc, lam = _log_phi_cdf(eta[cens])
        ll += logc.sum()
        g += (lam[:, None] * W[cens]).sum(axis=0)
        H -= (W[cens] * (lam * (eta[cens] + lam))[:, None]).T @ W[cens]
    return float(ll), g, H


def _newton(W, cens, theta0):
    """Maximise the concave log-likelihood (damped Newton, τ kept > 0)."""
    theta = theta0.copy()
    ll, g, H = _ll(theta, W, cens)
    for _ in range(200):
        try:
            step = -np.linalg.solve(H, g)
        except np.linalg.LinAlgError:
            step = g * 1e-3
        if g @ step <= 0:  # not an ascent direction (numerical trouble): gradient step
            step = g / max(1.0, np.abs(g).max())
        lam = 1.0
        while theta[-1] + lam * step[-1] <= 1e-9:
            lam *= 0.5
        while True:
            cand = theta + lam * step
            ll_c, g_c, H_c = _ll(cand, W, cens)
            if ll_c >= ll - 1e-12 or lam < 1e-10:
                break
            lam *= 0.5
        done = abs(ll_c - ll) < 1e-12 and np.abs(lam * step).max() < 1e-9
        theta, ll, g, H = cand, ll_c, g_c, H_c
        if done or np.abs(g).max() < 1e-10:
            break
    return theta, ll


def _solve(X, y, cens, free, fixed_vals):
    """Max-likelihood β (with the entries not in ``free`` fixed at ``fixed_vals``) and s."""
    Xf = X[:, free]
    off = X[:, ~free] @ fixed_vals if (~free).any() else np.zeros(len(y))
    # τ multiplies (−y + off): fixing β_j = v is γ_j = v·τ, a change of the τ column
    W = np.column_stack([Xf, -(y - off)])
    unc = ~cens
    beta0, *_ = np.linalg.lstsq(
        Xf[unc] if unc.sum() >= Xf.shape[1] else Xf,
        (y - off)[unc] if unc.sum() >= Xf.shape[1] else (y - off),
        rcond=None,
    )
    s0 = max(float(np.std((y - off - Xf @ beta0)[unc])) if unc.any() else 0.3, 0.1)
    theta, ll = _newton(W, cens, np.concatenate([beta0 / s0, [1 / s0]]))
    beta = np.empty(X.shape[1])
    beta[free] = theta[:-1] / theta[-1]
    beta[~free] = fixed_vals
    return beta, 1 / theta[-1], ll


@dataclass
class LifeModel:
    """A fitted life law: params a, m, one coefficient per effect, and the scatter s [log10]."""

    effects: tuple[str, ...]
    stress: bool = True  # False: the variant without a stress term (m fixed at 0)
    params: dict[str, float] = field(default_factory=dict)
    cov: np.ndarray | None = None  # covariance of (a, m, c…) [log10 units]
    loglik: float = float("nan")
    n: int = 0

    @property
    def names(self) -> list[str]:
        return ["a", "m"] + [EFFECTS[e].param for e in self.effects]

    @property
    def k(self) -> int:
        """Free parameters counted by AICc: a, s, m (if the variant has a stress term), one per effect."""
        return 2 + int(self.stress) + len(self.effects)

    def design(self, d: LifeData) -> np.ndarray:
        cols = [np.ones(len(d.stress_amp)), -np.log10(d.stress_amp)] + [EFFECTS[e].feature(d) for e in self.effects]
        return np.stack(cols, axis=1)

    def beta(self) -> np.ndarray:
        return np.array([self.params[k] for k in self.names])

    def mean_log10(self, d: LifeData) -> np.ndarray:
        return self.design(d) @ self.beta()

    @property
    def aicc(self) -> float:
        """AICc = −2 ln L + 2k + 2k(k+1)/(n−k−1) (∞ when n ≤ k + 1)."""
        k, n = self.k, self.n
        return -2 * self.loglik + 2 * k + (2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else math.inf)

    def interval(self, d: LifeData, level: float = LEVEL) -> tuple[np.ndarray, np.ndarray]:
        """Prediction interval of log10 N: scatter s plus parameter uncertainty (delta method)."""
        X = self.design(d)
        mu = X @ self.beta()
        var = self.params["s"] ** 2 + (np.einsum("ij,jk,ik->i", X, self.cov, X) if self.cov is not None else 0.0)
        z = NormalDist().inv_cdf(0.5 + level / 2)
        return mu - z * np.sqrt(var), mu + z * np.sqrt(var)


def fit(
    d: LifeData,
    effects: tuple[str, ...] = (),
    fixed: dict[str, float] | None = None,
    with_cov: bool = True,
    stress: bool = True,
) -> LifeModel:
    """Maximum-likelihood fit, the run-outs as survivals; m ≥ 0 (m = 0 when ``stress`` is False);
    ``fixed`` pins parameters (profiles)."""
    model = LifeModel(tuple(effects), stress, n=d.n)
    X = model.design(d)
    y = np.log10(d.cycles)
    cens = np.asarray(d.censored, dtype=bool)
    names = model.names
    fixed = dict(fixed or {})
    if not stress:
        fixed["m"] = 0.0
    free = np.array([nm not in fixed for nm in names])
    vals = np.array([fixed[nm] for nm in names if nm in fixed], dtype=float)
    beta, s, ll = _solve(X, y, cens, free, vals)
    if free[1] and beta[1] < 0:  # the bound m ≥ 0 is active: the concave problem's optimum lies on it
        free2 = free.copy()
        free2[1] = False
        beta, s, ll = _solve(
            X, y, cens, free2, np.array([0.0 if nm == "m" else fixed[nm] for nm in names if nm == "m" or nm in fixed])
        )
    model.params = dict(zip(names, map(float, beta)))
    model.params["s"] = float(s)
    model.loglik = float(ll)
    if with_cov:
        model.cov = _covariance(X, y, cens, beta, s, free)
    return model


def _covariance(X, y, cens, beta, s, free) -> np.ndarray:
    """Covariance of β from the observed information (inverse of −Hessian in (γ, τ), delta method to β)."""
    idx = np.flatnonzero(free)
    tau = 1 / s
    W = np.column_stack([X[:, idx], -(y - X[:, ~free] @ beta[~free])])
    _, _, H = _ll(np.concatenate([beta[idx] * tau, [tau]]), W, cens)
    try:
        C = np.linalg.inv(-H)
    except np.linalg.LinAlgError:
        C = np.linalg.pinv(-H)
    p = len(idx)
    J = np.zeros((p, p + 1))  # β_j = γ_j/τ
    J[:, :p] = np.eye(p) / tau
    J[:, p] = -beta[idx] / tau
    cov = np.zeros((X.shape[1], X.shape[1]))
    cov[np.ix_(idx, idx)] = J @ C @ J.T
    return cov


def profile_interval(
    d: LifeData,
    effects: tuple[str, ...],
    param: str,
    level: float = 0.95,
    model: LifeModel | None = None,
    stress: bool = True,
) -> tuple[float, float]:
    """Profile-likelihood interval of one parameter: where 2·(ln L_max − ln L_profile) = χ²₁(level)."""
    model = model or fit(d, effects, with_cov=False, stress=stress)
    stress = model.stress
    crit = 0.5 * NormalDist().inv_cdf(0.5 + level / 2) ** 2
    best = model.params[param]
    scale = max(abs(best), model.params["s"], 0.1)

    def drop(v):
        return model.loglik - fit(d, effects, fixed={param: v}, with_cov=False, stress=stress).loglik - crit

    out = []
    for sign in (-1.0, 1.0):
        lo, step = best, scale
        hi = best + sign * step
        while drop(hi) < 0:
            if param == "m" and hi <= 0:
                break
            lo, step = hi, step * 2
            hi = best + sign * step
            if step > 1e3:
                hi = math.copysign(math.inf, sign)
                break
        if param == "m" and sign < 0 and hi <= 0 and drop(0.0) < 0:
            out.append(0.0)
            continue
        if param == "m" and sign < 0:
            hi = max(hi, 0.0)
        if math.isinf(hi):
            out.append(hi)
            continue
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if drop(mid) < 0 else (lo, mid)
        out.append(0.5 * (lo + hi))
    return out[0], out[1]


def loo(d: LifeData, effects: tuple[str, ...] = (), stress: bool = True) -> tuple[float, np.ndarray, np.ndarray]:
    """Leave-one-out: (RMSE, per-row error, per-row prediction) in log10 cycles.

    Error = prediction − observed; a run-out only counts when predicted below its bound.
    """
    err = np.zeros(d.n)
    pred = np.zeros(d.n)
    for i in range(d.n):
        m = fit(d.subset(np.arange(d.n) != i), effects, with_cov=False, stress=stress)
        pred[i] = m.mean_log10(d.subset(np.arange(d.n) == i))[0]
        obs = math.log10(d.cycles[i])
        err[i] = min(0.0, pred[i] - obs) if d.censored[i] else pred[i] - obs
    return float(np.sqrt(np.mean(err**2))), err, pred


def loo_rmse(d: LifeData, effects: tuple[str, ...] = (), stress: bool = True) -> tuple[float, np.ndarray]:
    """Leave-one-out RMSE and per-row errors [log10 cycles]."""
    r, e, _ = loo(d, effects, stress)
    return r, e
