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
On a wild iterate of its 10^4-element mesh (203,202 unknowns) the general way took 93 s
and 513 M entries (4.8 GB) against 5 s and 76 M, and left a residual of 5e-4 all the
same: such a tangent is no better pivoted. So the general way is taken only where its
factors fit the memory available and SuperLU's 32-bit indices; otherwise the tangent is
refused (:class:`FactorsTooLarge`), and a Newton step is cut back as for a singular one.

SuperLU's first guess at its factors' size is 20 times the matrix's entries (sp_ienv(6)),
a 32-bit number: past about 107 M entries (some 6.7 x 10^4 elements) it overflowed, and
SuperLU stopped with "Not enough memory to perform factorization" whatever the memory.
Such a matrix is factorised by SuperLU's incomplete LU dropping nothing (a drop tolerance
of 0 and no other rule), on the same ordering and diagonal, with a first guess that fits:
on the 5,000-element hemisphere the two took the same time, 33.2 M entries and left the
same residual (5e-10).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..memory import available_bytes, size_text
from .superlu_pivots import pivots

#: A probe solve leaving more than this share of its right-hand side calls for pivoting.
PROBE_TOLERANCE = 1e-8
#: The most the general way multiplies the factors' entries on the diagonal by, as the
#: bound its memory is judged by (measured 3.8x and 6.7x, above).
PIVOTED_GROWTH = 8
#: The factors' entries on the diagonal against the matrix's (3.2 and 4.7 measured on the
#: hemisphere's tangents above).
DIAGONAL_FILL = 5
#: Bytes a factor entry takes in SuperLU's storage (measured 9.3-10).
FACTOR_ENTRY_BYTES = 10
#: SuperLU's sizes are 32-bit numbers.
INDEX_LIMIT = 2**31 - 1
#: SuperLU's first guess at the factors' entries, in the matrix's (sp_ienv(6)).
FIRST_GUESS = 20
#: The incomplete LU's first guess where the complete one's would overflow: above the
#: fill seen (4.7-6.1), and within INDEX_LIMIT.
LARGE_FIRST_GUESS = 10


class FactorsTooLarge(RuntimeError):
    """Factors that do not fit: pivoted ones where those on the diagonal are unsound, or
    those on the diagonal themselves (SuperLU out of memory); why, in words."""


class SymmetricPatternLU:
    """LU factors of a square sparse matrix (n, n) whose pattern is symmetric. Raises
    RuntimeError when the matrix is singular (SuperLU's "Factor is exactly singular"), and
    FactorsTooLarge when the factors it needs do not fit."""

    def __init__(self, matrix: sp.spmatrix):
        matrix = sp.csc_matrix(matrix)  # no copy of a CSC matrix
        diagonal = np.abs(matrix.diagonal())
        self._scale = 1.0 / np.sqrt(np.where(diagonal > 0.0, diagonal, 1.0))
        # the scaled values on the matrix's own index arrays (a copy of those is 4 bytes an entry)
        values = self._scale[matrix.indices]
        values *= np.repeat(self._scale, np.diff(matrix.indptr))
        values *= matrix.data
        scaled = sp.csc_matrix((values, matrix.indices, matrix.indptr), shape=matrix.shape)
        #: whether the factors pivoted off the diagonal (the probe failed)
        self.pivoted = False
        self._lu = None
        try:
            self._lu = _on_the_diagonal(scaled)
            probe = np.random.default_rng(0).standard_normal(scaled.shape[0])
            good = np.linalg.norm(scaled @ self._lu.solve(probe) - probe) <= PROBE_TOLERANCE * np.linalg.norm(probe)
        except RuntimeError:  # a zero pivot on the diagonal
            good = False
        except MemoryError:
            raise FactorsTooLarge("SuperLU ran out of memory forming its factors on the diagonal") from None
        if not good:
            # bounded by the factors on the diagonal, or where they broke down by their usual fill
            entries = PIVOTED_GROWTH * (self._lu.nnz if self._lu is not None else DIAGONAL_FILL * scaled.nnz)
            self._lu = None  # the unsound factors go before the general ones are formed
            _refuse_if_unfit(entries)
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
        return int(np.count_nonzero(pivots(self._lu) < 0.0))

    @property
    def entries(self) -> int:
        """The entries stored in the factors, L's and U's (the fill, with the matrix's own)."""
        return self._lu.nnz  # SuperLU's count (``L`` and ``U`` would copy both factors)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """x (n,) with matrix @ x = rhs (n,)."""
        return self._scale * self._lu.solve(self._scale * rhs)


def _on_the_diagonal(matrix: sp.csc_matrix) -> spla.SuperLU:
    """SuperLU's factors of ``matrix`` on its diagonal, ordered for its symmetric pattern:
    the complete LU, or where its first guess would overflow the incomplete one dropping
    nothing. Raises MemoryError where even that guess cannot be held."""
    options = {"SymmetricMode": True}
    if FIRST_GUESS * matrix.nnz <= INDEX_LIMIT:
        return spla.splu(matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=options)
    guess = min(LARGE_FIRST_GUESS, INDEX_LIMIT // matrix.nnz)
    return spla.spilu(matrix, drop_tol=0.0, drop_rule="basic", fill_factor=guess, permc_spec="MMD_AT_PLUS_A",
                      diag_pivot_thresh=0.0, options=options)


def _refuse_if_unfit(entries: int) -> None:
    """Raise FactorsTooLarge when pivoted factors of up to ``entries`` entries would not fit
    the memory available or SuperLU's indices."""
    need, have = entries * FACTOR_ENTRY_BYTES, available_bytes()
    if entries > INDEX_LIMIT:
        raise FactorsTooLarge(f"its pivots on the diagonal are unsound, and pivoted factors could take up to "
                              f"{entries:,} entries, more than SuperLU's {INDEX_LIMIT:,}")
    if have is not None and need > have:
        raise FactorsTooLarge(f"its pivots on the diagonal are unsound, and pivoted factors could need "
                              f"{size_text(need)} of memory, where {size_text(have)} is available")
