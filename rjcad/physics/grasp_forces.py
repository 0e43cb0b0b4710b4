"""The contact forces of a grasp's state when friction makes them indeterminate: the least friction that holds it.

Where a contact or a bearing sticks, its friction force may be anything within its cone or band, and the joints'
and objects' balance does not fix the split between normal and friction forces (statically indeterminate). The
minimiser's multipliers are one admissible set, usually at a cone's edge. Reported instead is the set with the
least friction: minimise Σ f_t² + Σ τ_b² over the normal forces N ≥ 0, the contacts' friction |f_t| ≤ μN, the
bearings' friction −w⁻ ≤ τ_b ≤ w⁺ and the stops' reactions s ≥ 0, subject to the balance

    ∂E/∂q + Σ a_t f_t + Σ e_i τ_b,i − Σ ∂gap/∂q N − Σ ±e_i s_i = 0

(a_t = t·(J_A − J_B): a contact's slip per dq). Where a contact or bearing slipped over the reading, its friction
is at its edge, against the slip. MuJoCo's regularised contacts pick the same kind of answer: the smallest forces.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: A reading's motion below this [mm or rad] is sticking.
SLIP = 1e-9


def least_friction(
    balance: np.ndarray,
    normals: np.ndarray,
    slips: np.ndarray,
    mu: np.ndarray,
    slip_of_contact: np.ndarray,
    bands: np.ndarray,
    band_motion: np.ndarray,
    stops: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(N, f_t, τ_b) of the least friction, or None where the solve fails.

    ``balance``: ∂E/∂q (nq,); ``normals``: ∂gap/∂q per contact (c, nq); ``slips``: a_t per contact (c, nq);
    ``mu`` (c,); ``slip_of_contact``: each contact's slip over the reading [mm] (c,); ``bands``: (w⁺, w⁻) per
    bearing row (b, 2) with its joint in column 2 (b, 3); ``band_motion``: each bearing joint's motion over the
    reading [rad] (b,); ``stops``: ±e_i columns of the joints at a stop (s, nq), sign: the reaction's direction.
    """
    from scipy.optimize import minimize

    c, b, s = len(normals), len(bands), len(stops)
    nq = len(balance)
    cols = [-normals.reshape(c, nq), slips.reshape(c, nq)]
    eb = np.zeros((b, nq))
    for r, row in enumerate(bands):
        eb[r, int(row[2])] = 1.0
    cols += [eb, -stops.reshape(s, nq)]
    M = np.vstack(cols).T  # (nq, c + c + b + s)
    nv = M.shape[1]
    friction = np.r_[np.zeros(c), np.ones(c), np.ones(b), np.zeros(s)]

    reg = friction + 1e-9

    def objective(x: np.ndarray) -> tuple[float, np.ndarray]:
        return 0.5 * float(reg @ x**2), reg * x

    # the balance's independent rows (the joints no force reaches balance already: their rows are zero)
    U, sv, _ = np.linalg.svd(M, full_matrices=False)
    rank = int(np.sum(sv > 1e-9 * max(float(sv.max(initial=0.0)), 1.0)))
    Mr, br = U[:, :rank].T @ M, U[:, :rank].T @ balance
    cons: list[dict[str, Any]] = [{"type": "eq", "fun": lambda x: Mr @ x + br, "jac": lambda x: Mr}] if rank else []
    rows: list[np.ndarray] = []
    for k in range(c):  # μN − f_t ≥ 0 and μN + f_t ≥ 0, or f_t = ±μN against a slip
        up, down = np.zeros(nv), np.zeros(nv)
        up[k], up[c + k] = mu[k], -1.0
        down[k], down[c + k] = mu[k], 1.0
        if abs(slip_of_contact[k]) > SLIP and mu[k] > 0:
            eq = up if slip_of_contact[k] > 0 else down  # f_t = +μN along a positive slip
            cons.append({"type": "eq", "fun": lambda x, e=eq: e @ x, "jac": lambda x, e=eq: e})
        else:
            rows += [up, down]
    if rows:
        A = np.asarray(rows)
        cons.append({"type": "ineq", "fun": lambda x: A @ x, "jac": lambda x: A})
    bounds: list[tuple[float | None, float | None]] = [(0.0, None)] * c + [(None, None)] * c
    for r, row in enumerate(bands):
        hi, lo = float(row[0]), -float(row[1])
        if band_motion[r] > SLIP:
            lo = hi
        elif band_motion[r] < -SLIP:
            hi = lo
        bounds.append((lo, hi))
    bounds += [(0.0, None)] * s
    x0 = np.zeros(nv)  # the balance's least-squares solution, a start near the feasible set
    x0[:] = np.linalg.lstsq(M, -balance, rcond=None)[0]
    res = minimize(objective, x0, jac=True, method="SLSQP", bounds=bounds, constraints=cons,
                   options={"ftol": 1e-14, "maxiter": 200})  # fmt: skip
    x = res.x
    worst = max([0.0] + [float(np.max(np.abs(cn["fun"](x)))) for cn in cons if cn["type"] == "eq"])
    worst = max([worst] + [float(-np.min(cn["fun"](x))) for cn in cons if cn["type"] == "ineq"])
    if not res.success and worst > 1e-7:  # not converged, and not even admissible
        return None
    return x[:c], x[c : 2 * c], x[2 * c : 2 * c + b]
