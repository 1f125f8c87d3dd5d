"""Where the element blocks of the static tangent go in its sparse matrix (CSC).

The tangent holds the free rows and every column, free then prescribed (numbered by
:func:`.unknowns.unknowns`). Its structure is worked out node by node, not entry by entry
(sorting the 2,025 entries of each element took a sixth of a small static solve): each
column of a node holds the free rows of the nodes it shares an element with, in those
nodes' order, since the free unknowns are numbered node by node.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from .unknowns import Unknowns


class TangentPattern(NamedTuple):
    """The CSC structure of the tangent (n_free, size): indices (nnz,), indptr (size + 1,);
    and for the element blocks k (ne, 45, 45), each entry's place ``slots`` (ne * 2025,)
    among its nnz stored values, or nnz for an entry that lands in no stored value (a
    fixed row or column, or a prescribed row)."""

    indices: np.ndarray
    indptr: np.ndarray
    slots: np.ndarray
    shape: tuple[int, int]

    def assemble(self, k: np.ndarray) -> sp.csc_matrix:
        """The sum of the element blocks k (ne, 45, 45) in the nodes' frames as a matrix;
        the entries that land nowhere are summed into one value past the last and left."""
        nnz = len(self.indices)
        data = np.bincount(self.slots, weights=k.reshape(-1), minlength=nnz + 1)[:nnz]
        return sp.csc_matrix((data, self.indices, self.indptr), shape=self.shape)


def free_columns(tangent: sp.csc_matrix, n_free: int) -> sp.csc_matrix:
    """The free columns (n_free, n_free) of a tangent (n_free, size) in CSC, the free
    columns first: a matrix on the tangent's own arrays (a slice would copy them)."""
    end = tangent.indptr[n_free]
    return sp.csc_matrix((tangent.data[:end], tangent.indices[:end], tangent.indptr[:n_free + 1]),
                         shape=(n_free, n_free))


#: Elements whose entries are placed at once: the (ne, 9, 5, 9, 5) places of all of them
#: would be worked out in 8-byte integers, three arrays of them at a time (at 10^4 elements
#: 0.9 GB held up, more than the tangent itself).
ELEMENT_CHUNK = 2048
#: The sparse tangent's entries whose rows are worked out at once.
ENTRY_CHUNK = 1 << 22


def tangent_pattern(conn: np.ndarray, u: Unknowns) -> TangentPattern:
    """The :class:`TangentPattern` of a mesh's elements conn (ne, 9) over unknowns ``u``."""
    n = len(u.index)
    free = (u.index >= 0) & (u.index < u.n_free)  # (n, 5)
    free_rows = free.sum(axis=1)
    first_row = np.where(free, u.index, u.n_free).min(axis=1)  # each node's first free unknown
    # node pairs (column node, row node) that share an element, by column node, then row node
    pair_keys, pair_of = np.unique(conn[:, None, :] * n + conn[:, :, None], return_inverse=True)
    pair_of = pair_of.reshape(len(conn), 9, 9)  # (ne, row node, column node)
    column_node, row_node = np.divmod(pair_keys, n)
    pair_rows = free_rows[row_node]
    pair_start = np.cumsum(pair_rows) - pair_rows  # where each pair's rows start in all pairs' rows
    first_pair = np.searchsorted(column_node, np.arange(n)).clip(max=len(pair_keys) - 1)  # each node's
    offset = pair_start - pair_start[first_pair[column_node]]  # the pair's rows' place in its columns
    column_length = np.bincount(column_node, weights=pair_rows, minlength=n).astype(np.int64)
    known = u.index >= 0  # the columns: every unknown, free or prescribed, by its number
    node_of_column = np.empty(u.size, dtype=np.int64)
    node_of_column[u.index[known]] = np.nonzero(known)[0]
    lengths = column_length[node_of_column]
    indptr = np.zeros(u.size + 1, dtype=np.int64)
    np.cumsum(lengths, out=indptr[1:])
    nnz = int(indptr[-1])
    index_type = np.int32 if nnz < np.iinfo(np.int32).max else np.int64
    # every column of a node holds that node's rows: all_rows, by column node
    all_rows = np.repeat(first_row[row_node] - pair_start, pair_rows) + np.arange(pair_rows.sum())
    rows_less_start = pair_start[first_pair[node_of_column]] - indptr[:-1]  # a column's rows in all_rows
    indices = np.empty(nnz, dtype=index_type)
    # a run of columns of about ENTRY_CHUNK entries at a time: nnz-long temporaries were 5 GB
    # at 10^5 elements
    starts = np.searchsorted(indptr, np.arange(0, nnz, ENTRY_CHUNK), side="right") - 1  # each run's first column
    bounds = np.unique(np.append(starts, u.size))
    for first, stop in zip(bounds[:-1], bounds[1:]):
        start, end = indptr[first], indptr[stop]
        indices[start:end] = all_rows[np.repeat(rows_less_start[first:stop], lengths[first:stop])
                                      + np.arange(start, end)]
    # each element entry (e, row node, its slot, column node, its slot): its column's start,
    # its row node's offset there, its row's rank among that node's
    slots = np.empty((len(conn), 9, 5, 9, 5), dtype=index_type)
    for first in range(0, len(conn), ELEMENT_CHUNK):
        chunk = slice(first, first + ELEMENT_CHUNK)
        index = u.index[conn[chunk]]  # (m, 9, 5)
        column_start = indptr[np.maximum(index, 0)]
        rank = index - first_row[conn[chunk]][:, :, None]
        places = column_start[:, None, None] + offset[pair_of[chunk]][:, :, None, :, None] + rank[:, :, :, None, None]
        used = ((index >= 0) & (index < u.n_free))[:, :, :, None, None] & known[conn[chunk]][:, None, None]
        slots[chunk] = np.where(used, places, nnz)
    return TangentPattern(indices, indptr.astype(index_type), slots.reshape(-1),
                          (u.n_free, u.size))
