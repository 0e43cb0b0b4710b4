"""Parameter uncertainty of a least-squares fit from its Jacobian: pure numpy (no plotting, no CAD), shared by
the paper-finger fits (``rjcad.physics.paper_finger``) and the finger endpoint critique
(``rjcad.identify.finger.endpoint``)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike


def parameter_std(
    jac: ArrayLike, x: np.ndarray, lb: np.ndarray, ub: np.ndarray, names: Sequence[str]
) -> tuple[np.ndarray, list[str]]:
    """1σ of each fitted parameter from (JᵀJ)⁻¹ over the identified ones (NaN otherwise), and why not.

    Why not: "at its bound" (the fit pushed it onto a bound: the data reject the values inside, and the
    Gaussian interval does not apply), "no effect" (the end angles do not depend on it: its Jacobian column is
    ~0), "trades off with X" (it loads on a null direction of the free columns with X: fewer informative
    angles than parameters).
    """
    jac = np.asarray(jac, dtype=float)
    norms = np.linalg.norm(jac, axis=0)
    span = np.where(np.isfinite(ub - lb), ub - lb, 1.0)
    on_bound = (x - lb <= 1e-4 * span) | (ub - x <= 1e-4 * span)
    no_effect = norms <= 1e-6 * max(norms.max(), 1e-300)
    free = ~no_effect & ~on_bound
    std = np.full(len(x), np.nan)
    why = ["at its bound" if b else "no effect" if z else "" for b, z in zip(on_bound, no_effect)]
    if free.any():
        # SVD of the free columns: a parameter that loads on a (near-)null direction trades off with
        # others without changing the fit (fewer informative angles than parameters): not identified
        _, sv, vt = np.linalg.svd(jac[:, free], full_matrices=True)
        sv = np.concatenate([sv, np.zeros(vt.shape[0] - len(sv))])
        null = sv <= 1e-6 * sv.max()
        loads = np.abs(vt[null].T) > 1e-3 if null.any() else np.zeros((vt.shape[0], 0), bool)
        ident = ~loads.any(axis=1)
        var = (vt[~null].T ** 2) @ (1.0 / sv[~null] ** 2)
        idx = np.flatnonzero(free)
        std[idx[ident]] = np.sqrt(var[ident])
        for a in np.flatnonzero(~ident):
            partners = [names[idx[b]] for b in range(len(idx)) if b != a and (loads[a] & loads[b]).any()]
            why[idx[a]] = "trades off with " + (", ".join(partners) if partners else "the others")
    return std, why
