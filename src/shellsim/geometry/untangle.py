"""Mending a remeshed surface where gmsh left a few bad quadrilaterals: the slivers and
folds it makes along the seams of a closed tube's reparametrisation, at some element sizes
and not at others. Their corners, and those a ring around them, are smoothed (each moved
toward the mean of its neighbours along element edges, then back onto the surface) until
every corner angle of every element is well inside (0, 180) degrees, as mesh generators
untangle a mesh by local Laplacian smoothing; the mid-side and centre nodes are then put
back between the corners, on the surface.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..mesh import EDGES

#: The smallest sine of a corner angle an element may keep (about 17.5 degrees: below it a
#: wall as thick as the elements are wide folds at its faces).
SHARPEST = 0.3
#: Smoothing sweeps before the mesh is handed on as it is (the checks that follow name
#: what is still folded).
SWEEPS = 60


def bad_elements(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Elements (indices) of the quad9 mesh ``x`` (n, 3), ``conn`` (ne, 9) that are bad: a
    corner angle whose sine, signed against the element's own normal (the cross product
    of its diagonals), is below SHARPEST (a sliver or a dart), or a normal that most of
    its edge neighbours' oppose (a fold: gmsh's folded triangle split into three quads is
    well shaped in itself, and turned over against the surface around it)."""
    corners = x[conn[:, :4]]  # (ne, 4, 3)
    normal = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    ahead = np.roll(corners, -1, axis=1) - corners
    behind = np.roll(corners, 1, axis=1) - corners
    sine = np.einsum("eci,ei->ec", np.cross(ahead, behind), normal)
    sine /= np.maximum(np.linalg.norm(ahead, axis=2) * np.linalg.norm(behind, axis=2), 1e-300)
    return np.flatnonzero((sine.min(axis=1) < SHARPEST) | (_agreement(conn, normal) < 0.0))


def _agreement(conn: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """(ne,) each element's normal against its edge neighbours', summed: the dot products,
    negated where the shared edge runs the same way in both (their numbering turns
    opposite ways, so their normals are opposite where the surface is not folded)."""
    quads = conn[:, :4]
    starts, ends = quads.ravel(), np.roll(quads, -1, axis=1).ravel()
    element = np.repeat(np.arange(len(conn)), 4)
    key = np.sort(np.column_stack([starts, ends]), axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, starts, element = key[order], starts[order], element[order]
    pair = np.flatnonzero(np.all(key[1:] == key[:-1], axis=1))  # rows pair, pair + 1 share an edge
    a, b = element[pair], element[pair + 1]
    turn = np.where(starts[pair] == starts[pair + 1], -1.0, 1.0)
    dot = turn * np.einsum("ki,ki->k", normal[a], normal[b])
    total = np.zeros(len(conn))
    np.add.at(total, a, dot)
    np.add.at(total, b, dot)
    return total


def untangled(x: np.ndarray, conn: np.ndarray, onto: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """``x`` (n, 3) with the corners near bad elements smoothed until none is bad (or
    SWEEPS are spent), each smoothed node put back by ``onto`` (k, 3) -> (k, 3) (the
    surface), and the higher-order nodes of the elements moved put back between their
    corners. Corners on the open boundary stay."""
    bad = bad_elements(x, conn)
    if not len(bad):
        return x
    x = x.copy()
    quads = conn[:, :4]
    pairs = np.concatenate([quads[:, [0, 1]], quads[:, [1, 2]], quads[:, [2, 3]], quads[:, [3, 0]]])
    pairs = np.unique(np.sort(pairs, axis=1), axis=0)
    ends = np.concatenate([pairs, pairs[:, ::-1]])
    # each corner's neighbours along element edges, each row summing to one (their mean)
    degree = np.bincount(ends[:, 0], minlength=len(x))
    mean = sp.csr_matrix((1.0 / degree[ends[:, 0]], (ends[:, 0], ends[:, 1])), shape=(len(x), len(x)))
    edges = conn[:, EDGES].reshape(-1, 3)
    key, counts = np.unique(np.sort(edges[:, [0, 2]], axis=1), axis=0, return_counts=True)
    boundary = np.unique(key[counts == 1])
    moved = np.zeros(len(x), dtype=bool)
    for _ in range(SWEEPS):
        near = np.unique(quads[bad])
        near = np.unique(quads[np.isin(quads, near).any(axis=1)])  # a ring around them
        near = np.setdiff1d(near, boundary)
        x[near] = onto(mean[near] @ x)
        moved[near] = True
        bad = bad_elements(x, conn)
        if not len(bad):
            break
    touched = np.flatnonzero(moved[quads].any(axis=1))
    _between_corners(x, conn[touched], onto)
    return x


def _between_corners(x: np.ndarray, conn: np.ndarray, onto: Callable[[np.ndarray], np.ndarray]) -> None:
    """The mid-side nodes (4-7) of ``conn``'s elements at their edges' middles and the
    centre node (8) at the corners' mean, each put back by ``onto``, in place."""
    corners = conn[:, :4]
    middles = 0.5 * (x[corners] + x[np.roll(corners, -1, axis=1)])  # (k, 4, 3): edges 0-1, 1-2, 2-3, 3-0
    x[conn[:, 4:8].ravel()] = onto(middles.reshape(-1, 3))
    x[conn[:, 8]] = onto(x[corners].mean(axis=1))
