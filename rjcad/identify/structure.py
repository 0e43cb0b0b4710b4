"""What a residual still follows: tests of its structure against time, direction, angle, tension and reversals.

On one experiment's valid samples, the residual r is regressed on each group of regressors in :data:`GROUPS`
(with an intercept), stepwise: the largest structure found is taken out first and the other groups are tested
on what is left, beyond it (correlated groups, e.g. direction and angle × direction, are not reported twice
for one cause). The statistic is the share of the variance left that a group explains, R².
Its null distribution is made by shifting r circularly against the regressors (SHIFTS shifts, each at least a
tenth of the record): a shift keeps the residual's own autocorrelation and breaks any tie to the regressors, so
the p-value stays honest for smoothed, correlated residuals where an F-test's would not. A structure is
reported when p ≤ P_FOUND and its fitted part's RMS is at least SIZE_FOUND × the noise σ; its size is that RMS
[quantity units] and its ratio to σ.
"""

from __future__ import annotations

import numpy as np

from rjcad.identify.fit import Prepared

#: Circular shifts of the null distribution (the smallest p-value that can be stated is 1/(SHIFTS + 1)).
SHIFTS = 199
#: A structure is reported at p ≤ this ...
P_FOUND = 0.01
#: ... and when its fitted part's RMS is at least this many noise σ.
SIZE_FOUND = 0.3

#: Group name → (words, regressors from (τ = t/T − ½, d = ±1 direction, θ [rad], ŷ the prediction, k samples
#: since the last reversal)).
GROUPS = {
    "time": ("time over the run (drift, warm-up)", lambda c: [c["tau"], c["tau"] ** 2]),
    "direction": ("direction of motion", lambda c: [c["d"]]),
    "angle": ("angle", lambda c: [c["theta"], c["theta"] ** 2]),
    "angle_x_direction": (
        "angle × direction (a slope that changes sign with the motion: a stiffness that differs by direction)",
        lambda c: [c["theta"] * c["d"]],
    ),
    "load": ("the predicted load (a term proportional to the tension or torque)", lambda c: [c["y"], c["y"] * c["d"]]),
    "reversals": (
        "the samples just after each reversal (a flat step there: a dead band)",
        lambda c: [c["d"] * np.exp(-c["since"] / c["k"])],
    ),
}


def _since_reversal(n: int, reversals: np.ndarray) -> np.ndarray:
    """Samples since the last reversal (since the start before the first)."""
    marks = np.zeros(n, dtype=bool)
    marks[reversals[(reversals >= 0) & (reversals < n)]] = True
    last = np.maximum.accumulate(np.where(marks, np.arange(n), 0))
    return (np.arange(n) - last).astype(float)


def _basis(X: np.ndarray) -> np.ndarray | None:
    """Orthonormal basis (n, k) of the centred columns of ``X``, or None when they are degenerate."""
    Xc = X - X.mean(axis=0)
    if not np.all(np.isfinite(Xc)):
        return None
    q, r = np.linalg.qr(Xc)
    keep = np.abs(np.diag(r)) > 1e-9 * max(float(np.abs(r).max()), 1e-300)
    return q[:, keep] if keep.all() else None


def structure(p: Prepared, r: np.ndarray, y_hat: np.ndarray, seed: int = 0, t: np.ndarray | None = None) -> list[dict]:
    """The groups of :data:`GROUPS` the residual ``r`` (full length) follows on the valid samples, in the order they
    were found, then the tests of the rest on what is left: ``against``, ``words``, ``p_value``, ``size`` (RMS
    of the fitted part, quantity units), ``size_over_noise``, ``found``. ``t``: the series' times when they are
    not its experiment's (a finger's channel holds a subset of the record's samples)."""
    ok = p.valid
    n_ok = int(ok.sum())
    if n_ok < 50:
        return []
    t = p.exp.t if t is None else t
    span = float(t[-1] - t[0]) or 1.0
    cols = {
        "tau": ((t - t[0]) / span - 0.5)[ok],
        "d": p.motion.direction[ok].astype(float),
        "theta": p.motion.theta[ok],
        "y": y_hat[ok],
        "since": _since_reversal(len(t), p.motion.reversals)[ok],
        "k": max(p.motion.window, 1),
    }
    rr = r[ok] - r[ok].mean()
    rng = np.random.default_rng(seed)
    lo = max(n_ok // 10, 1)
    shifts = rng.integers(lo, max(n_ok - lo, lo + 1), SHIFTS)
    roll = (np.arange(n_ok)[:, None] - shifts[None, :]) % n_ok  # column j: a residual shifted by shifts[j]
    bases = {}
    for name, (_, make) in GROUPS.items():
        q = _basis(np.column_stack(make(cols)))
        if q is not None:
            bases[name] = q
    out: list[dict] = []
    taken = np.zeros((n_ok, 0))
    while bases:
        ss = float(rr @ rr)
        if ss <= 0:
            break
        rolled = rr[roll]
        tests = {}
        for name, q in bases.items():
            q = _basis(q - taken @ (taken.T @ q)) if taken.shape[1] else q  # beyond the structures found before
            if q is None:
                continue
            stat = float(np.sum((q.T @ rr) ** 2)) / ss  # share of the variance left (a shift keeps Σr²)
            null = np.sum((q.T @ rolled) ** 2, axis=0) / ss
            size = float(np.sqrt(stat * ss / n_ok))
            p_value = float((1 + np.sum(null >= stat)) / (SHIFTS + 1))
            tests[name] = (p_value, size, q)
        strong = [n for n, (pv, size, _) in tests.items() if pv <= P_FOUND and size / p.sigma >= SIZE_FOUND]
        pick = max(strong, key=lambda n: tests[n][1]) if strong else None
        for name in [pick] if pick else list(tests):
            pv, size, q = tests[name]
            out.append(
                {
                    "against": name,
                    "words": GROUPS[name][0],
                    "p_value": pv,
                    "size": size,
                    "size_over_noise": size / p.sigma,
                    "found": name == pick,
                }
            )
        if pick is None:
            break
        q = tests[pick][2]
        rr = rr - q @ (q.T @ rr)
        taken = np.column_stack([taken, q])
        del bases[pick]
    return out
