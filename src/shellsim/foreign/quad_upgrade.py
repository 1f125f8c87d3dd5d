"""Lower-order shell elements made 9-node quads: 4- and 8-node quads directly, triangles
(with the quads beside them) by splitting every element into quads first. New nodes lie on
the surface the given nodes describe rather than on its chords (a cylinder meshed with
flat facets keeps its curvature), and a set of given nodes is lifted to the new nodes it
spans."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Where adjacent element normals at a node differ by more than this, the surface has a
#: crease there: the edges at the node stay straight (a normal averaged across a crease is
#: no normal of the surface).
CREASE_COS = np.cos(np.radians(30.0))


@dataclass(frozen=True)
class Refined:
    """Elements of a mesh made from coarser or lower-order ones, with new nodes.

    x : (n', 3) node positions, the given nodes first in their order.
    conn : (ne', k) node indices of the new elements (9-node quads in gmsh/VTK order:
        corners, mid-edges, centre; or 4-node quads from :func:`split`).
    edge_ends : (m, 2) the two given nodes each new mid-edge node lies between, in order
        (numbered n .. n + m - 1).
    centre_corners : (c,) list of the given nodes each new centre node (numbered
        n + m .. n + m + c - 1) lies amid.
    """

    x: np.ndarray
    conn: np.ndarray
    edge_ends: np.ndarray
    centre_corners: list[np.ndarray]

    def lift(self, nodes: np.ndarray) -> np.ndarray:
        """The given ``nodes`` with the new nodes they span: a mid-edge node whose two ends
        are given, a centre node whose corners all are. (k,) -> sorted (k',)."""
        member = np.zeros(len(self.x), dtype=bool)
        member[nodes] = True
        first = len(self.x) - len(self.edge_ends) - len(self.centre_corners)
        member[first + np.flatnonzero(member[self.edge_ends].all(axis=1))] = True
        inside = [all(member[c]) for c in self.centre_corners]
        member[first + len(self.edge_ends) + np.flatnonzero(inside)] = True
        return np.flatnonzero(member)


def upgrade(x: np.ndarray, quads: np.ndarray) -> Refined:
    """quad9 elements from quads (ne, 4) or (ne, 8) of nodes at ``x`` (n, 3).

    Mid-edge nodes a 4-node quad lacks lie on the cubic Hermite curve between the edge's
    corners whose tangents there are the chord projected on the tangent planes of the
    averaged nodal normals (the chord midpoint on a flat mesh or across a crease); every
    centre node is where the 8-node (serendipity) interpolation puts it, exact on any
    quadratic surface.
    """
    corners = quads[:, :4]
    if quads.shape[1] == 8:
        mids, edge_ends, extra = quads[:, 4:8], np.zeros((0, 2), dtype=np.int64), np.zeros((0, 3))
    else:
        edge_ends, index = _edges(corners)
        mids = len(x) + index
        extra = _hermite_midpoints(x, [corners], edge_ends)
    x = np.concatenate([x, extra])
    centres = len(x) + np.arange(len(quads))
    conn = np.column_stack([corners, mids, centres])
    centre_x = 0.5 * x[mids].sum(axis=1) - 0.25 * x[corners].sum(axis=1)
    return Refined(np.concatenate([x, centre_x]), conn, edge_ends, list(corners))


def split(x: np.ndarray, triangles: np.ndarray, quads: np.ndarray) -> tuple[Refined, np.ndarray]:
    """4-node quads from triangles (nt, 3) and quads (nq, 4): every element split at its
    edges' midpoints and its centre, a triangle into three quads and a quad into four, so
    that neighbours still share their edges. The new nodes are placed as :func:`upgrade`
    places them (a triangle's centre where the 6-node triangle puts it).

    Returns the refined mesh (its conn (3 nt + 4 nq, 4)) and each new quad's parent:
    its index in the triangles, then the quads.
    """
    edge_ends, index = _edges(triangles, quads)
    tri_mids, quad_mids = len(x) + index[:len(triangles) * 3].reshape(-1, 3), len(x) + index[len(triangles) * 3:].reshape(-1, 4)
    x = np.concatenate([x, _hermite_midpoints(x, [triangles, quads], edge_ends)])
    first = len(x)
    tri_centre = (4 * x[tri_mids].sum(axis=1) - x[triangles].sum(axis=1)) / 9
    quad_centre = 0.5 * x[quad_mids].sum(axis=1) - 0.25 * x[quads].sum(axis=1)
    g = first + np.arange(len(triangles))
    c = first + len(triangles) + np.arange(len(quads))
    children = [np.stack([triangles[:, k], tri_mids[:, k], g, tri_mids[:, k - 1]], axis=1) for k in range(3)]
    children += [np.stack([quads[:, k], quad_mids[:, k], c, quad_mids[:, k - 1]], axis=1) for k in range(4)]
    parent = np.concatenate([np.arange(len(triangles))] * 3 + [len(triangles) + np.arange(len(quads))] * 4)
    conn = np.concatenate(children)
    order = np.argsort(parent, kind="stable")  # an element's pieces side by side
    refined = Refined(np.concatenate([x, tri_centre, quad_centre]), conn[order], edge_ends,
                      list(triangles) + list(quads))
    return refined, parent[order]


def _edges(*polygons: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct edges (m, 2) of polygons of several sizes, and for each polygon's k-th
    edge (from its k-th corner to the next) the edge's index, all polygons' in turn."""
    pairs = np.concatenate([np.stack([p, np.roll(p, -1, axis=1)], axis=-1).reshape(-1, 2) for p in polygons])
    edge_ends, index = np.unique(np.sort(pairs, axis=1), axis=0, return_inverse=True)
    index = index.reshape(-1)
    return edge_ends, index.reshape(-1, polygons[0].shape[1]) if len(polygons) == 1 else index


def _hermite_midpoints(x: np.ndarray, polygons: list[np.ndarray], edge_ends: np.ndarray) -> np.ndarray:
    """Midpoints (m, 3) of the Hermite curves over the edges ``edge_ends`` (m, 2) of the
    surface the ``polygons`` (each (k, corners)) describe."""
    total = np.zeros_like(x)
    normals = []
    for p in polygons:  # each facet's normal weighted by its angle at the node: a triangle cut either way gives the same
        n, angle = _corner_normals(x, p)
        normals.append(n)
        np.add.at(total, p, n * angle[..., None])
    length = np.linalg.norm(total, axis=1, keepdims=True)
    averaged = np.divide(total, length, out=np.zeros_like(total), where=length > 0)
    smooth = np.ones(len(x), dtype=bool)
    for p, n in zip(polygons, normals):
        np.logical_and.at(smooth, p, np.einsum("eki,eki->ek", n, averaged[p]) >= CREASE_COS)
    a, b = x[edge_ends[:, 0]], x[edge_ends[:, 1]]
    na, nb = averaged[edge_ends[:, 0]], averaged[edge_ends[:, 1]]
    chord = b - a
    ta = chord - np.einsum("mi,mi->m", chord, na)[:, None] * na
    tb = chord - np.einsum("mi,mi->m", chord, nb)[:, None] * nb
    curved = smooth[edge_ends].all(axis=1)[:, None]
    return 0.5 * (a + b) + np.where(curved, 0.125 * (ta - tb), 0.0)


def _corner_normals(x: np.ndarray, polygons: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (ne, k, 3) of polygons at their corners (right-hand rule over the
    corner order, Abaqus' positive normal) and the polygons' angles there (ne, k) (rad)."""
    p = x[polygons]
    ahead, behind = np.roll(p, -1, axis=1) - p, np.roll(p, 1, axis=1) - p
    n = np.cross(ahead, behind)
    cos = np.einsum("eki,eki->ek", ahead, behind) / (np.linalg.norm(ahead, axis=-1) * np.linalg.norm(behind, axis=-1))
    return n / np.linalg.norm(n, axis=-1, keepdims=True), np.arccos(np.clip(cos, -1.0, 1.0))
