"""The static solver's sparse LU: solves on the diagonal when that is sound, pivots when a
probe solve shows it is not, and says when a matrix is singular."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from shellsim.solver import sparse_lu
from shellsim.solver.sparse_lu import SymmetricPatternLU
from shellsim.solver.superlu_pivots import store_readable, pivots


def laplacian(n: int) -> sp.csc_matrix:
    """The 2D five-point Laplacian on an n x n grid (n^2, n^2): symmetric positive definite."""
    line = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    return sp.csc_matrix(sp.kronsum(line, line))


def test_a_definite_matrix_with_rows_of_very_different_scale_is_solved_on_the_diagonal():
    """Rows and columns scaled by 1e-6..1e6 (translations against rotations): the scaling
    makes the diagonal pivots sound, no pivoting needed, and each row's residual is round-off
    of that row's scale."""
    rows = 10.0 ** np.random.default_rng(0).uniform(-6, 6, 400)
    a = sp.csc_matrix(sp.diags(rows) @ laplacian(20) @ sp.diags(rows))
    b = rows * np.random.default_rng(1).standard_normal(400)
    lu = SymmetricPatternLU(a)
    assert not lu.pivoted
    assert np.linalg.norm((a @ lu.solve(b) - b) / rows) <= 1e-12 * np.linalg.norm(b / rows)


def test_tiny_pivots_on_the_diagonal_are_pivoted_around():
    """Pairs [[1e-10, 1], [1, 1e-10]] beside a Laplacian (well conditioned, strongly
    indefinite): on its diagonal the factors would grow by 1e20; the probe sees it and the
    general factors solve it."""
    pair = sp.csc_matrix([[1e-10, 1.0], [1.0, 1e-10]])
    a = sp.csc_matrix(sp.block_diag([laplacian(6)] + [pair] * 10))
    x = np.random.default_rng(2).standard_normal(a.shape[0])
    lu = SymmetricPatternLU(a)
    assert lu.pivoted
    assert np.allclose(lu.solve(a @ x), x, rtol=1e-10, atol=1e-12)


def test_a_singular_matrix_is_reported():
    """The Laplacian with a row and column of zeros but for its diagonal taken away: singular."""
    a = laplacian(5).tolil()
    a[7, :] = 0.0
    a[:, 7] = 0.0
    with pytest.raises(RuntimeError, match="singular"):
        SymmetricPatternLU(sp.csc_matrix(a))


def indefinite(n: int, shift: float) -> sp.csc_matrix:
    """The n x n grid's Laplacian less ``shift`` on its diagonal: symmetric, with as many
    negative eigenvalues as the Laplacian has below the shift."""
    return sp.csc_matrix(laplacian(n) - shift * sp.eye(n * n))


@pytest.mark.parametrize("shift", [0.0, 0.9, 3.3, 5.1])
def test_negative_pivots_count_the_negative_eigenvalues(shift):
    """Sylvester's law of inertia on the diagonal factors, the pivots read from SuperLU's own
    store: the count of eigenvalues below the shift, from numpy's dense eigenvalues."""
    a = indefinite(12, shift)
    lu = SymmetricPatternLU(a)
    assert not lu.pivoted
    assert lu.negative_pivots == np.count_nonzero(np.linalg.eigvalsh(a.toarray()) < 0.0)


def test_the_pivots_are_read_from_the_store_as_scipys_copy_of_u_holds_them():
    """The store is readable on this scipy (else every stability check would copy both
    factors), and what it gives is U's diagonal to the bit, on a matrix of many supernodes."""
    assert store_readable()
    a = sp.csc_matrix(indefinite(30, 2.2) + sp.random(900, 900, density=0.002, random_state=3))
    lu = spla.splu(a, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    assert np.array_equal(pivots(lu), lu.U.diagonal())


def test_unsound_pivots_whose_pivoted_factors_would_not_fit_are_refused(monkeypatch):
    """The tiny pivots' matrix with no memory to pivot in: refused, saying why, where the
    general way would have been taken."""
    monkeypatch.setattr(sparse_lu, "available_bytes", lambda: 1000.0)
    pair = sp.csc_matrix([[1e-10, 1.0], [1.0, 1e-10]])
    with pytest.raises(sparse_lu.FactorsTooLarge, match="pivoted factors could need .* where 1 kB is available"):
        SymmetricPatternLU(sp.csc_matrix(sp.block_diag([laplacian(6)] + [pair] * 10)))


def test_a_matrix_too_large_for_superlus_first_guess_is_factorised_by_its_ilu_dropping_nothing(monkeypatch):
    """Where 20 times the entries would overflow SuperLU's 32-bit first guess (here made so
    by a first guess of 10^9), the incomplete LU dropping nothing stands in: the same
    solution to round-off, the same pivots' signs, and (with no memory) the same refusal."""
    a = indefinite(20, 3.3)
    x = np.random.default_rng(4).standard_normal(a.shape[0])
    complete = SymmetricPatternLU(a)
    monkeypatch.setattr(sparse_lu, "FIRST_GUESS", 10**9)
    large = SymmetricPatternLU(a)
    assert not large.pivoted and large.entries <= 1.05 * complete.entries  # (7,533 and 7,344)
    assert np.linalg.norm(large.solve(a @ x) - x) <= 1e-10 * np.linalg.norm(x)
    assert large.negative_pivots == complete.negative_pivots > 0
