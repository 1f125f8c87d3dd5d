"""The unknowns of a static solve: the 5 DOF per node with the supports eliminated.

Each node's translations are taken in a frame of its own (its columns: the directions its
supports leave free, then its prescribed axes, then the fixed rest), so a symmetry plane
at any angle removes exactly one unknown. Rotations are the two fibre-frame increments of
:func:`shellsim.element.frames.rotate_director`, each free or fixed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..bundles import Model
from ..model import orthonormal

#: Columns of a node's row in :attr:`Unknowns.index`: three translations in the node's
#: frame, then the two rotations.
SLOTS = 5


@dataclass(frozen=True)
class Unknowns:
    """frames (n, 3, 3): each node's translation directions as columns; index (n, 5): the
    number of each node DOF among the unknowns, free ones 0..n_free-1, prescribed ones
    n_free..n_free+n_known-1 (in the order of ``model.constraints.prescribed``), -1 fixed."""

    frames: np.ndarray
    index: np.ndarray
    n_free: int
    n_known: int

    @property
    def size(self) -> int:
        return self.n_free + self.n_known

    def to_local(self, f: np.ndarray, fr: np.ndarray) -> np.ndarray:
        """Nodal forces f (n, 3) and fr (n, 2) as (n, 5) in the nodes' frames."""
        return np.concatenate([np.einsum("nij,ni->nj", self.frames, f), fr], axis=1)

    def gather(self, local: np.ndarray) -> np.ndarray:
        """The unknowns' entries (size,) of a nodal (n, 5) array."""
        out = np.zeros(self.size)
        used = self.index >= 0
        out[self.index[used]] = local[used]
        return out

    def scatter(self, values: np.ndarray) -> np.ndarray:
        """A nodal (n, 5) array from the unknowns' values (size,), 0 where fixed."""
        local = np.zeros(self.index.shape)
        used = self.index >= 0
        local[used] = values[self.index[used]]
        return local


def unknowns(model: Model) -> Unknowns:
    """The :class:`Unknowns` of ``model``'s supports."""
    n = model.n_nodes
    constraints = model.constraints
    prescribed_axes: dict[int, list[tuple[int, int]]] = {}  # node -> its (prescription, axis), in order
    for p, (node, axis) in enumerate(zip(constraints.prescribed.nodes, constraints.prescribed.axes)):
        prescribed_axes.setdefault(int(node), []).append((p, axis))
    # most nodes move freely along x, y and z: only the others' frames are worked out
    frames = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    free_translations = np.full(n, 3)
    supported = ~np.all(np.isclose(constraints.projector, np.eye(3), rtol=0.0, atol=1e-12), axis=(1, 2))
    for node in np.union1d(np.flatnonzero(supported), constraints.prescribed.nodes):
        values, vectors = np.linalg.eigh(constraints.projector[node])
        free = list(vectors[:, values > 0.5].T)
        moved = [np.eye(3)[axis] for _, axis in prescribed_axes.get(int(node), [])]
        frames[node] = np.asarray(orthonormal(free + moved + list(np.eye(3)))).T  # completed by the fixed rest
        free_translations[node] = len(free)
    # numbered node by node: its free translations, then its free rotations
    free_rotations = constraints.rot_free > 0.5  # (n, 2)
    per_node = free_translations + free_rotations.sum(axis=1)
    first = np.cumsum(per_node) - per_node
    index = np.full((n, SLOTS), -1, dtype=np.int64)
    for k in range(3):
        index[free_translations > k, k] = (first + k)[free_translations > k]
    index[free_rotations[:, 0], 3] = (first + free_translations)[free_rotations[:, 0]]
    index[free_rotations[:, 1], 4] = (first + free_translations + free_rotations[:, 0])[free_rotations[:, 1]]
    n_free = int(per_node.sum())
    for node, moves in prescribed_axes.items():
        for k, (p, _) in enumerate(moves):
            index[node, free_translations[node] + k] = n_free + p
    return Unknowns(frames=frames, index=index, n_free=n_free, n_known=len(constraints.prescribed.nodes))
