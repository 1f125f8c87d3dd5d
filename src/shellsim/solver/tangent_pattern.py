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
    and for the element blocks k (ne, 45, 45), the flat positions ``entries`` of those that
    land in it and their places ``slots`` (both (m,)) among its nnz stored values."""

    indices: np.ndarray
    indptr: np.ndarray
    entries: np.ndarray
    slots: np.ndarray
    shape: tuple[int, int]

    def assemble(self, k: np.ndarray) -> sp.csc_matrix:
        """The sum of the element blocks k (ne, 45, 45) in the nodes' frames as a matrix."""
        data = np.bincount(self.slots, weights=k.ravel()[self.entries], minlength=len(self.indices))
        return sp.csc_matrix((data, self.indices, self.indptr), shape=self.shape)


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
    all_rows = np.repeat(first_row[row_node] - pair_start, pair_rows) + np.arange(pair_rows.sum())
    within = np.arange(indptr[-1]) - np.repeat(indptr[:-1], lengths)
    indices = all_rows[np.repeat(pair_start[first_pair[node_of_column]], lengths) + within]
    # each element entry (e, row node, its slot, column node, its slot): its column's start,
    # its row node's offset there, its row's rank among that node's
    index = u.index[conn]  # (ne, 9, 5)
    column_start = indptr[np.maximum(index, 0)]
    rank = index - first_row[conn][:, :, None]
    slots = column_start[:, None, None] + offset[pair_of][:, :, None, :, None] + rank[:, :, :, None, None]
    used = ((index >= 0) & (index < u.n_free))[:, :, :, None, None] & known[conn][:, None, None]
    entries = np.flatnonzero(used)
    return TangentPattern(indices.astype(np.int32), indptr.astype(np.int32), entries, slots.ravel()[entries],
                          (u.n_free, u.size))
