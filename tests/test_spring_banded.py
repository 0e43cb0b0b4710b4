"""rjcad.spring.banded: LAPACK's banded solve (scipy.linalg.lapack.dgbsv), checked against dense solves and
against scipy.linalg.solve_banded, which must agree bit for bit."""

import numpy as np
import pytest

from rjcad.spring import banded


def random_band(rng, n, lower, upper):
    """A random n×n banded matrix (diagonally weighted, so well conditioned), dense and in band storage."""
    A = np.zeros((n, n))
    for k in range(-lower, upper + 1):
        A += np.diag(rng.normal(size=n - abs(k)), k)
    A += np.diag(np.full(n, 4.0 + lower + upper))
    ab = banded.band_storage(n, lower, upper)
    for j in range(n):
        for i in range(max(0, j - upper), min(n, j + lower + 1)):
            ab[lower + upper + i - j, j] = A[i, j]
    return A, ab


@pytest.mark.parametrize("n, lower, upper", [(1, 0, 0), (7, 1, 1), (60, 5, 5), (33, 2, 4)])
def test_banded_solve_equals_the_dense_solve(n, lower, upper):
    rng = np.random.default_rng(n)
    A, ab = random_band(rng, n, lower, upper)
    b = rng.normal(size=n)
    x = banded.solve(ab.copy(), b, lower, upper)
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-12)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-12, atol=1e-14)


def test_the_banded_solve_and_scipy_solve_banded_agree_bit_for_bit():
    from scipy.linalg import solve_banded

    rng = np.random.default_rng(3)
    _, ab = random_band(rng, 90, 5, 5)
    b = rng.normal(size=90)
    assert np.array_equal(banded.solve(ab.copy(), b, 5, 5), solve_banded((5, 5), ab[5:], b, check_finite=False))


def test_a_singular_band_raises_linalg_error():
    ab = banded.band_storage(4, 1, 1)
    ab[2] = [1.0, 0.0, 1.0, 1.0]  # a zero on the diagonal with nothing below it to pivot on
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        banded.solve(ab, np.ones(4), 1, 1)
