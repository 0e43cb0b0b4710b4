"""Gaps between the coils of a deformed spiral: the distance from each node to the nearest part of the rod's
centreline that is not its own neighbourhood (|arc angle| ≥ π apart), on the rod model's cubic element shapes.

Pure numpy; lengths in mm, angles in rad. Used by ``rjcad.spring.rod.node_gaps``.
"""

from __future__ import annotations

import math

import numpy as np


def curve_distance(P, X, tang, seg):
    """Distance from points P (M, 2) to the cubic (Hermite) shape of elements ``seg`` (M,)."""
    A, B = X[seg], X[seg + 1]
    d = B - A
    ln = np.hypot(d[:, 0], d[:, 1])
    e1 = d / ln[:, None]
    e2 = np.stack([-e1[:, 1], e1[:, 0]], axis=1)
    beta = np.arctan2(d[:, 1], d[:, 0])
    pa = np.arctan2(np.sin(tang[seg] - beta), np.cos(tang[seg] - beta))
    pb = np.arctan2(np.sin(tang[seg + 1] - beta), np.cos(tang[seg + 1] - beta))
    x = np.clip(((P - A) * e1).sum(1) / ln, 0.0, 1.0)
    for it in range(3):  # Newton on the foot point of the cubic v(ξ) = l[pa ξ(1−ξ)² − pb ξ²(1−ξ)]
        v = ln * (pa * x * (1 - x) ** 2 - pb * x**2 * (1 - x))
        C = A + (x * ln)[:, None] * e1 + v[:, None] * e2
        if it == 2:
            return np.hypot(*(P - C).T)
        dv = ln * (pa * (1 - x) * (1 - 3 * x) - pb * x * (2 - 3 * x))
        dC = ln[:, None] * e1 + dv[:, None] * e2
        x = np.clip(x + ((P - C) * dC).sum(1) / (dC * dC).sum(1), 0.0, 1.0)


def nearest_nodes(P, X, aP=None, aX=None, chunk: int = 1 << 22):
    """Per point of P: index of the nearest node of X, skipping nodes with |aP − aX| < π; and whether one was left.

    Brute force over all pairs in blocks of about ``chunk`` pairs (a spring has a few hundred nodes: 0.1–1 ms a
    call, and no k-d tree, whose import costs more than every query of a design).
    """
    j = np.zeros(len(P), dtype=int)
    found = np.ones(len(P), dtype=bool)
    step = max(1, chunk // max(1, len(X)))
    xx = np.einsum("ij,ij->i", X, X)
    for s in range(0, len(P), step):
        p = P[s : s + step]
        d2 = np.einsum("ij,ij->i", p, p)[:, None] + xx[None, :] - 2.0 * (p @ X.T)  # |p − x|², to rounding
        if aP is not None:
            d2[np.abs(aP[s : s + step, None] - aX[None, :]) < math.pi] = np.inf
        j[s : s + step] = np.argmin(d2, axis=1)
        found[s : s + step] = np.isfinite(d2.min(axis=1))
    return j, found


def nearest_gap(P, X, tang, aP=None, aX=None):
    """Per point of P: distance to the curve through X, skipping nodes with |aP − aX| < π (inf if none is left)."""
    j, found = nearest_nodes(P, X, aP, aX)
    lost = ~found
    best = np.full(len(P), np.inf)
    for seg in (j - 1, j):
        best = np.minimum(best, curve_distance(P, X, tang, np.clip(seg, 0, len(X) - 2)))
    return np.where(lost, np.inf, best)
