"""Banded linear solve for the rod model: LAPACK's dgbsv (LU with partial pivoting), through SciPy's public
``scipy.linalg.lapack`` wrapper.

SciPy is imported on the first solve (``import scipy.linalg``: about 0.25 s), so a command that never runs the
rod model does not pay for it.
"""

from __future__ import annotations

import numpy as np


def band_storage(n: int, lower: int, upper: int) -> np.ndarray:
    """Zeroed LAPACK band storage for an n×n matrix (``lower`` + ``upper`` bands): the matrix goes in rows
    ``lower:`` as a[lower + upper + i − j, j] = A[i, j]; the first ``lower`` rows are the LU's fill-in."""
    return np.zeros((2 * lower + upper + 1, n))


def solve(ab: np.ndarray, b: np.ndarray, lower: int, upper: int) -> np.ndarray:
    """x with A·x = b, A in ``band_storage`` layout (overwritten). Raises numpy's LinAlgError if A is singular."""
    from scipy.linalg.lapack import dgbsv

    _, _, x, info = dgbsv(lower, upper, ab, b, overwrite_ab=1, overwrite_b=0)
    if info > 0:
        raise np.linalg.LinAlgError(f"singular matrix: zero pivot in row {info}")
    if info < 0:
        raise ValueError(f"illegal value in argument {-info} of dgbsv")
    return x
