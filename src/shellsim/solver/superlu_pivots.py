"""The pivots of scipy's SuperLU factors (U's diagonal), read from SuperLU's own store.

``SuperLU.U`` converts both factors to CSC matrices and keeps them with the factors: 12
bytes per factor entry, more than SuperLU's supernodal storage of them (about 10), so a
static solve's stability check, which needs only the pivots' signs, held the factors
twice over (a 10^5-element scene, 10 GB of factors, 12 GB more). The pivots lie in L's
supernodal store (SuperLU's ``SCformat``): column j of the supernode starting at column
f holds its rows f, f + 1, ... first, so U_jj is that column's entry j - f.

The store is reached through the layout of scipy's ``SuperLUObject`` and SuperLU's
``SuperMatrix`` and ``SCformat`` (scipy/sparse/linalg/_dsolve/_superluobject.h and
SuperLU's supermatrix.h). Everything that layout implies is checked before the store is
read (the object's shape, each factor's storage, element and matrix kinds and size, and
the entry counts against ``SuperLU.nnz``), and once against ``SuperLU.U`` on a small
matrix; where any check fails, ``SuperLU.U`` is used.
"""

from __future__ import annotations

import ctypes
from functools import cache

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: SuperLU's enumerations (supermatrix.h): storage SLU_NC, SLU_SC; element SLU_D; matrix
#: SLU_TRLU (unit lower, L), SLU_TRU (upper, U).
_NC, _SC, _DOUBLE, _TRLU, _TRU = 0, 3, 1, 1, 4


class _SuperMatrix(ctypes.Structure):
    _fields_ = [("Stype", ctypes.c_int), ("Dtype", ctypes.c_int), ("Mtype", ctypes.c_int),
                ("nrow", ctypes.c_int), ("ncol", ctypes.c_int), ("Store", ctypes.c_void_p)]


class _SuperLUObject(ctypes.Structure):
    _fields_ = [("refcount", ctypes.c_ssize_t), ("type", ctypes.c_void_p), ("m", ctypes.c_ssize_t),
                ("n", ctypes.c_ssize_t), ("L", _SuperMatrix), ("U", _SuperMatrix)]


class _SCformat(ctypes.Structure):
    _fields_ = [("nnz", ctypes.c_int), ("nsuper", ctypes.c_int), ("nzval", ctypes.c_void_p),
                ("nzval_colptr", ctypes.POINTER(ctypes.c_int)), ("rowind", ctypes.POINTER(ctypes.c_int)),
                ("rowind_colptr", ctypes.POINTER(ctypes.c_int)), ("col_to_sup", ctypes.POINTER(ctypes.c_int)),
                ("sup_to_col", ctypes.POINTER(ctypes.c_int))]


class _NCformat(ctypes.Structure):
    _fields_ = [("nnz", ctypes.c_int), ("nzval", ctypes.c_void_p), ("rowind", ctypes.POINTER(ctypes.c_int)),
                ("colptr", ctypes.POINTER(ctypes.c_int))]


def pivots(lu: spla.SuperLU) -> np.ndarray:
    """U's diagonal (n,) of real factors ``lu`` (a copy)."""
    if store_readable():
        read = _read_pivots(lu)
        if read is not None:
            return read
    return lu.U.diagonal()


def _read_pivots(lu: spla.SuperLU) -> np.ndarray | None:
    """U's diagonal read from the store, or None where the layout is not the one expected."""
    if type(lu).__basicsize__ < ctypes.sizeof(_SuperLUObject):
        return None
    view = _SuperLUObject.from_address(id(lu))
    n = lu.shape[0]
    factors = (view.L, view.U)
    if ((view.m, view.n) != lu.shape or any((f.nrow, f.ncol, f.Dtype) != (n, n, _DOUBLE) for f in factors)
            or (view.L.Stype, view.L.Mtype, view.U.Stype, view.U.Mtype) != (_SC, _TRLU, _NC, _TRU)
            or not view.L.Store or not view.U.Store):
        return None
    store = _SCformat.from_address(view.L.Store)
    if store.nnz + _NCformat.from_address(view.U.Store).nnz != lu.nnz or not 0 < store.nsuper + 1 <= n:
        return None
    column_start = np.ctypeslib.as_array(store.nzval_colptr, (n + 1,))
    supernode = np.ctypeslib.as_array(store.col_to_sup, (n,))
    first_column = np.ctypeslib.as_array(store.sup_to_col, (store.nsuper + 2,))
    values = np.ctypeslib.as_array(ctypes.cast(store.nzval, ctypes.POINTER(ctypes.c_double)), (column_start[n],))
    return values[column_start[:-1] + np.arange(n) - first_column[supernode]].copy()


@cache
def store_readable() -> bool:
    """Whether the store reads as ``SuperLU.U`` says, on a small indefinite matrix with
    supernodes (checked once a process)."""
    n = 60
    rng = np.random.default_rng(0)
    a = sp.random(n, n, density=0.1, random_state=1)
    a = sp.csc_matrix(a + a.T + sp.diags(rng.uniform(-3.0, 3.0, n)) + sp.eye(n, k=1) + sp.eye(n, k=-1))
    lu = spla.splu(a, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    read = _read_pivots(lu)
    return read is not None and np.array_equal(read, lu.U.diagonal())
