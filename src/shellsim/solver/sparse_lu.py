"""The sparse LU factors that the static solver's corrections solve with.

The tangent's pattern is symmetric (an element couples its nodes both ways, a contact
pair too) and its values nearly so (but for follower loads and the differences' round-off),
so its columns are first ordered for the symmetric pattern (minimum degree on A^T + A) and
factorised on the diagonal, as LDL^T codes do, after scaling the matrix symmetrically to
a unit diagonal (translations and rotations of a thin shell differ in stiffness by orders
of magnitude). Where a state is far from equilibrium and the tangent strongly indefinite,
pivots on the diagonal can be poor: a probe solve then leaves a residual, and the factors
are formed again the general way (COLAMD, pivoting freely). A threshold pivot in place of
the probe cost more: on a diverging Newton step it pivoted off the diagonal and multiplied
the factors by 8-13 (0.04 s to 1-2 s a factorisation).

Measured on the pinched hemisphere's tangent (21,666 unknowns, 1.7 M entries): the
general way 0.90 s and 20.5 M entries in the factors; on the diagonal 0.20-0.23 s and 5.4 M.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: A probe solve leaving more than this share of its right-hand side calls for pivoting.
PROBE_TOLERANCE = 1e-8


class SymmetricPatternLU:
    """LU factors of a square sparse matrix (n, n) whose pattern is symmetric. Raises
    RuntimeError when the matrix is singular (SuperLU's "Factor is exactly singular")."""

    def __init__(self, matrix: sp.spmatrix):
        scaled = sp.csc_matrix(matrix, copy=True)
        diagonal = np.abs(scaled.diagonal())
        self._scale = 1.0 / np.sqrt(np.where(diagonal > 0.0, diagonal, 1.0))
        columns = np.repeat(np.arange(scaled.shape[1]), np.diff(scaled.indptr))
        scaled.data *= self._scale[scaled.indices] * self._scale[columns]
        #: whether the factors pivoted off the diagonal (the probe failed)
        self.pivoted = False
        try:
            self._lu = spla.splu(scaled, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                 options={"SymmetricMode": True})
            probe = np.random.default_rng(0).standard_normal(scaled.shape[0])
            good = np.linalg.norm(scaled @ self._lu.solve(probe) - probe) <= PROBE_TOLERANCE * np.linalg.norm(probe)
        except RuntimeError:  # a zero pivot on the diagonal
            good = False
        if not good:
            self.pivoted = True
            self._lu = spla.splu(scaled, permc_spec="COLAMD")

    @property
    def negative_pivots(self) -> int | None:
        """The count of negative pivots, which is the count of negative eigenvalues of a
        symmetric matrix (Sylvester's law of inertia: the symmetric scaling and the ordering
        keep it, and diagonal pivoting makes U = D L^T); None when the factors pivoted off
        the diagonal, which mixes the rows."""
        if self.pivoted or not np.array_equal(self._lu.perm_r, self._lu.perm_c):
            return None
        return int(np.count_nonzero(self._lu.U.diagonal() < 0.0))

    @property
    def entries(self) -> int:
        """The entries stored in the factors, L's and U's (the fill, with the matrix's own)."""
        return self._lu.L.nnz + self._lu.U.nnz

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """x (n,) with matrix @ x = rhs (n,)."""
        return self._scale * self._lu.solve(self._scale * rhs)
