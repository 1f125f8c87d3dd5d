"""4- and 8-node shell quadrilaterals made 9-node ones, the new nodes placed on the surface
the corners describe rather than on their chords (a cylinder meshed with 4-node quads
then keeps its curvature), and a set of corner nodes lifted to the new nodes it spans."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Where adjacent element normals at a node differ by more than this, the surface has a
#: crease there: the edges at the node stay straight (a normal averaged across a crease is
#: no normal of the surface).
CREASE_COS = np.cos(np.radians(30.0))


@dataclass(frozen=True)
class Upgraded:
    """A quad9 mesh made from lower-order quads.

    x : (n9, 3) node positions, the given nodes first in their order.
    conn : (ne, 9) node indices, gmsh/VTK order (corners, mid-edges, centre).
    edge_ends : (m, 2) the corner nodes of each new mid-edge node (numbered n .. n + m - 1).
    centre_of : (ne,) each element's centre node.
    """

    x: np.ndarray
    conn: np.ndarray
    edge_ends: np.ndarray
    centre_of: np.ndarray

    def lift(self, nodes: np.ndarray) -> np.ndarray:
        """The given nodes with the new nodes they span: a mid-edge node whose two corners
        are given, a centre node whose four corners are. (k,) -> sorted (k',)."""
        member = np.zeros(len(self.x), dtype=bool)
        member[nodes] = True
        first_new = len(self.x) - len(self.edge_ends) - len(self.centre_of)
        edge_nodes = first_new + np.flatnonzero(member[self.edge_ends].all(axis=1))
        member[edge_nodes] = True
        centres = self.centre_of[member[self.conn[:, :4]].all(axis=1)]
        member[centres] = True
        return np.flatnonzero(member)


def upgrade(x: np.ndarray, quads: np.ndarray) -> Upgraded:
    """quad9 elements from quads (ne, 4) or (ne, 8) of nodes at ``x`` (n, 3).

    Mid-edge nodes a 4-node quad lacks lie on the cubic Hermite curve between the edge's
    corners whose tangents at them are the chord projected onto the tangent planes of the
    averaged nodal normals (the chord midpoint on a flat mesh or across a crease); every
    centre node is where the 8-node (serendipity) interpolation puts it, exact on any
    quadratic surface.
    """
    ne = len(quads)
    corners = quads[:, :4]
    if quads.shape[1] == 8:
        mids, edge_ends, extra = quads[:, 4:8], np.zeros((0, 2), dtype=np.int64), np.zeros((0, 3))
    else:
        pairs = np.stack([corners, np.roll(corners, -1, axis=1)], axis=-1).reshape(-1, 2)
        edge_ends, index = np.unique(np.sort(pairs, axis=1), axis=0, return_inverse=True)
        mids = len(x) + index.reshape(ne, 4)
        extra = _edge_midpoints(x, corners, edge_ends)
    x = np.concatenate([x, extra])
    centre_of = len(x) + np.arange(ne)
    centres = 0.5 * x[mids].sum(axis=1) - 0.25 * x[corners].sum(axis=1)
    conn = np.column_stack([corners, mids, centre_of])
    return Upgraded(np.concatenate([x, centres]), conn, edge_ends, centre_of)


def _edge_midpoints(x: np.ndarray, corners: np.ndarray, edge_ends: np.ndarray) -> np.ndarray:
    """Midpoints (m, 3) of the Hermite curves over the edges ``edge_ends`` (m, 2)."""
    normals = _corner_normals(x, corners)  # (ne, 4, 3) unit
    total = np.zeros_like(x)
    np.add.at(total, corners, normals)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    averaged = np.divide(total, length, out=np.zeros_like(total), where=length > 0)
    smooth = np.ones(len(x), dtype=bool)
    np.logical_and.at(smooth, corners, np.einsum("eki,eki->ek", normals, averaged[corners]) >= CREASE_COS)
    a, b = x[edge_ends[:, 0]], x[edge_ends[:, 1]]
    na, nb = averaged[edge_ends[:, 0]], averaged[edge_ends[:, 1]]
    chord = b - a
    ta = chord - np.einsum("mi,mi->m", chord, na)[:, None] * na
    tb = chord - np.einsum("mi,mi->m", chord, nb)[:, None] * nb
    curved = smooth[edge_ends].all(axis=1)[:, None]
    return 0.5 * (a + b) + np.where(curved, 0.125 * (ta - tb), 0.0)


def _corner_normals(x: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Unit normals (ne, 4, 3) of bilinear quads at their corners (right-hand rule over the
    corner order, Abaqus' positive normal)."""
    p = x[corners]
    forward = np.roll(p, -1, axis=1) - p
    backward = np.roll(p, 1, axis=1) - p
    n = np.cross(forward, backward)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)

