"""The dense Newton matrices' LU factorisations (cpp/include/rigidfem/dense_lu.hpp): the real one (column loops
below 48 unknowns, Eigen's blocked LU from there) and the complex one kept in real and imaginary parts, against
NumPy's LAPACK solves of the same systems and their transposes."""

import numpy as np
import pytest

from rigidfem._core import _bench


def _system(n, seed, shift=0.0):
    rng = np.random.default_rng(seed)
    S = rng.normal(size=(n, n)) + 1j * rng.normal(size=(n, n)) + shift * np.eye(n)
    b = rng.normal(size=n) + 1j * rng.normal(size=n)
    return S, b


def _close(x, reference, S):
    """x within ε cond(S) (times a margin) of the reference, relative to its size."""
    bound = 1e3 * np.finfo(float).eps * np.linalg.cond(S)
    assert np.linalg.norm(x - reference) <= bound * np.linalg.norm(reference)


@pytest.mark.parametrize("n", [1, 2, 3, 7, 21, 47, 48, 60])
@pytest.mark.parametrize("seed", [0, 1])
def test_solves_and_transposed_solves_equal_lapack(n, seed):
    S, b = _system(n, seed)
    x, xt, z, zt, u, uc = _bench.dense_lu_solutions(S, b)
    _close(x, np.linalg.solve(S.real, b.real), S.real)
    _close(xt, np.linalg.solve(S.real.T, b.real), S.real)
    _close(z, np.linalg.solve(S, b), S)
    _close(zt, np.linalg.solve(S.T, b), S)  # the transpose, not the adjoint
    # the pivots' product is the determinant up to its sign (the row swaps')
    for pivots, matrix in ((u, S.real), (uc, S)):
        assert np.isclose(np.prod(np.abs(pivots)), abs(np.linalg.det(matrix)), rtol=1e-9)


def test_pivoting_swaps_rows_where_the_diagonal_is_zero():
    # no LU without row swaps: S[0, 0] = 0, and the second column's largest entry below its diagonal
    S = np.array([[0.0, 2.0, 1.0], [1.0, 1e-12, 3.0], [4.0, 5.0, 6.0]]) * (1 + 0.5j)
    b = np.array([1.0, 2.0, 3.0]) + 1j * np.array([0.5, -1.0, 2.0])
    x, xt, z, zt, _, _ = _bench.dense_lu_solutions(S, b)
    _close(x, np.linalg.solve(S.real, b.real), S.real)
    _close(xt, np.linalg.solve(S.real.T, b.real), S.real)
    _close(z, np.linalg.solve(S, b), S)
    _close(zt, np.linalg.solve(S.T, b), S)


@pytest.mark.parametrize("n", [5, 21, 60])
def test_a_singular_matrix_leaves_a_pivot_at_round_off(n):
    # what the Newton matrix's regularity test reads: the pivots' spread far below 1e-8 (the real and complex
    # paths, and the blocked one at n = 60)
    S, b = _system(n, 3)
    S[:, -1] = S[:, 0] - 2.0 * S[:, 1]  # rank n - 1
    *_, u, uc = _bench.dense_lu_solutions(S, b)
    for pivots in (np.abs(u), np.abs(uc.real) + np.abs(uc.imag)):
        assert pivots.min() / pivots.max() < 1e-12
    Z = np.zeros((n, n), complex)  # every pivot exactly zero: no division by it, no NaN in the factors
    *_, u, uc = _bench.dense_lu_solutions(Z, b)
    assert np.all(u == 0) and np.all(uc == 0)


@pytest.mark.parametrize("scale", [1.0, 1j, 3.0 - 0.5j])
def test_the_pivot_is_the_largest_entry_not_the_first(scale):
    # [[1e-17, 1], [1, 1]]: eliminated with the 1e-17 as pivot, the solution's error is of order 1; the largest
    # entry of the column (by |re| + |im| for the complex one) keeps it at round-off
    S = np.array([[1e-17, 1.0], [1.0, 1.0]]) * scale
    b = np.array([1.0, 2.0]) * scale
    x, xt, z, zt, u, uc = _bench.dense_lu_solutions(S, b)
    if scale == 1.0:
        _close(x, np.linalg.solve(S.real, b.real), S.real)
        _close(xt, np.linalg.solve(S.real.T, b.real), S.real)
        assert abs(u[0]) == 1.0
    _close(z, np.linalg.solve(S, b), S)
    _close(zt, np.linalg.solve(S.T, b), S)
    assert abs(uc[0]) == pytest.approx(abs(scale))


def test_bad_shapes_are_refused():
    with pytest.raises(ValueError, match="^S: expected a square matrix, got 2 x 3"):
        _bench.dense_lu_solutions(np.ones((2, 3)), np.ones(2))
    with pytest.raises(ValueError, match=r"^b: expected 3 values \(S's rows\), got 5"):
        _bench.dense_lu_solutions(np.eye(3), np.ones(5))
