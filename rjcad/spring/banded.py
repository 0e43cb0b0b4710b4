"""Banded linear solve for the rod model: LAPACK's dgbsv (LU with partial pivoting) without importing scipy.linalg.

``import scipy.linalg`` costs about 0.25 s (its package pulls in the array-API layer and every decomposition), a
quarter of `rjcad spring`'s time budget, for one routine. SciPy's f2py LAPACK module is loaded here on its own,
from the installed SciPy; where that is not possible (another SciPy layout), ``scipy.linalg.solve_banded`` is used.
Both call the same LAPACK routine on the same storage, so the result is the same bit for bit.
"""

from __future__ import annotations

import functools
import importlib.machinery
import importlib.util
from pathlib import Path

import numpy as np


@functools.lru_cache(maxsize=1)
def _dgbsv():
    """SciPy's f2py wrapper of LAPACK dgbsv, loaded without the scipy.linalg package; None if not found."""
    try:
        spec = importlib.util.find_spec("scipy")
        if spec is None or spec.origin is None:
            return None
        folder = Path(spec.origin).parent / "linalg"
        for suffix in importlib.machinery.EXTENSION_SUFFIXES:
            path = folder / f"_flapack{suffix}"
            if path.is_file():
                loader = importlib.machinery.ExtensionFileLoader("_flapack", str(path))
                module = importlib.util.module_from_spec(importlib.util.spec_from_loader("_flapack", loader))
                loader.exec_module(module)
                return module.dgbsv
    except (ImportError, OSError, AttributeError):
        pass
    return None


def band_storage(n: int, lower: int, upper: int) -> np.ndarray:
    """Zeroed LAPACK band storage for an n×n matrix (``lower`` + ``upper`` bands): the matrix goes in rows
    ``lower:`` as a[lower + upper + i − j, j] = A[i, j]; the first ``lower`` rows are the LU's fill-in."""
    return np.zeros((2 * lower + upper + 1, n))


def solve(ab: np.ndarray, b: np.ndarray, lower: int, upper: int) -> np.ndarray:
    """x with A·x = b, A in ``band_storage`` layout (overwritten). Raises numpy's LinAlgError if A is singular."""
    gbsv = _dgbsv()
    if gbsv is None:
        from scipy.linalg import solve_banded

        return solve_banded((lower, upper), ab[lower:], b, check_finite=False)
    _, _, x, info = gbsv(lower, upper, ab, b, overwrite_ab=1, overwrite_b=0)
    if info > 0:
        raise np.linalg.LinAlgError(f"singular matrix: zero pivot in row {info}")
    if info < 0:
        raise ValueError(f"illegal value in argument {-info} of dgbsv")
    return x
