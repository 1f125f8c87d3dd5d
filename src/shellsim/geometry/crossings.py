"""Where a mesh's mid-surface passes through itself: two parts meshed across each other
(two tubes that cross, a leaflet through its neighbour) are no model of anything that
could be built, and nothing a run computes tells.

Each 9-node element is taken as the 8 flat triangles of its four 2 x 2 sub-quadrilaterals;
two elements that share no node cross where an edge of one's triangles passes strictly
through a triangle of the other's (Moeller & Trumbore's test). Surfaces that only touch
(an edge on a face, parts meeting along a line) do not count. Candidate pairs are the
elements whose bounding boxes overlap, found from their centres.
"""

from __future__ import annotations

import numpy as np

from ..element.shape import NODE_RS
from ..errors import id_list, place

#: The 3 x 3 grid of an element's nodes: GRID[i, j] is the slot at r = i - 1, s = j - 1.
GRID = np.zeros((3, 3), dtype=np.int64)
GRID[NODE_RS[:, 0].astype(int) + 1, NODE_RS[:, 1].astype(int) + 1] = np.arange(9)
#: The element's 8 triangles (8, 3) and their 16 distinct edges (16, 2), as slots.
TRIANGLES = np.array([tri for i in range(2) for j in range(2) for tri in (
    (GRID[i, j], GRID[i + 1, j], GRID[i + 1, j + 1]), (GRID[i, j], GRID[i + 1, j + 1], GRID[i, j + 1]))])
EDGES = np.unique(np.sort(np.concatenate([TRIANGLES[:, [0, 1]], TRIANGLES[:, [1, 2]], TRIANGLES[:, [2, 0]]]),
                          axis=1), axis=0)
#: Pairs tested at once: (pairs, 16 edges, 8 triangles) of floats stay near 100 MB.
CHUNK = 20_000


def crossing_pairs(x: np.ndarray, conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The element pairs (k, 2) whose mid-surfaces cross, numbered from 0, and a point (k, 3)
    where each does, for nodes x (n, 3) and 9-node elements conn (ne, 9)."""
    from scipy.spatial import cKDTree

    corners = x[conn]  # (ne, 9, 3)
    low, high = corners.min(axis=1), corners.max(axis=1)
    centre = 0.5 * (low + high)
    reach = float(np.linalg.norm(high - low, axis=1).max())
    pairs = cKDTree(centre).query_pairs(reach, output_type="ndarray").reshape(-1, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    overlap = np.all((low[a] <= high[b]) & (low[b] <= high[a]), axis=1)
    shared = (conn[a][:, :, None] == conn[b][:, None, :]).any(axis=(1, 2))
    pairs = pairs[overlap & ~shared]
    found, points = [np.zeros((0, 2), dtype=np.int64)], [np.zeros((0, 3))]
    for start in range(0, len(pairs), CHUNK):
        chunk = pairs[start:start + CHUNK]
        for one, other in ((chunk[:, 0], chunk[:, 1]), (chunk[:, 1], chunk[:, 0])):
            hit, point = _edges_through_triangles(corners[one], corners[other])
            found.append(chunk[hit])
            points.append(point)
    pairs, points = np.concatenate(found), np.concatenate(points)
    pairs, first = np.unique(pairs, axis=0, return_index=True)
    return pairs, points[first]


def _edges_through_triangles(edge_nodes: np.ndarray, triangle_nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Whether an edge of the first elements' triangles (p, 9, 3) passes strictly through a
    triangle of the second's (p, 9, 3), per pair (p,), and a crossing point of each that
    does (k, 3)."""
    start = edge_nodes[:, EDGES[:, 0]][:, :, None]  # (p, 16, 1, 3)
    along = edge_nodes[:, EDGES[:, 1]][:, :, None] - start
    v0 = triangle_nodes[:, TRIANGLES[:, 0]][:, None]  # (p, 1, 8, 3)
    e1 = triangle_nodes[:, TRIANGLES[:, 1]][:, None] - v0
    e2 = triangle_nodes[:, TRIANGLES[:, 2]][:, None] - v0
    p = np.cross(along, e2)
    det = np.einsum("...i,...i", e1, p)
    scale = np.linalg.norm(e1, axis=-1) * np.linalg.norm(e2, axis=-1) * np.linalg.norm(along, axis=-1)
    usable = np.abs(det) > 1e-9 * scale  # an edge not in the triangle's plane
    inverse = np.divide(1.0, det, out=np.zeros_like(det), where=usable)
    to_start = start - v0
    u = np.einsum("...i,...i", to_start, p) * inverse
    q = np.cross(to_start, e1)
    v = np.einsum("...i,...i", along, q) * inverse
    s = np.einsum("...i,...i", e2, q) * inverse  # the crossing's place along the edge
    margin = 1e-9
    through = usable & (u > margin) & (v > margin) & (u + v < 1.0 - margin) & (s > margin) & (s < 1.0 - margin)
    hit = through.any(axis=(1, 2))
    pair, edge, triangle = np.nonzero(through[hit])
    first = np.unique(pair, return_index=True)[1]
    pair, edge, triangle = pair[first], edge[first], triangle[first]
    point = (start[hit][pair, edge, 0] + s[hit][pair, edge, triangle][:, None] * along[hit][pair, edge, 0])
    return hit, point


def crossing_problem(x: np.ndarray, conn: np.ndarray) -> str | None:
    """A sentence naming where the mid-surface of a mesh (nodes x (n, 3), elements conn
    (ne, 9)) passes through itself, ids from 1; None where it does not."""
    pairs, points = crossing_pairs(x, conn)
    if not len(pairs):
        return None
    elements = np.unique(pairs)
    return (f"the mid-surface passes through itself: {len(pairs)} pair(s) of elements that share no node cross, "
            f"the first elements {pairs[0, 0] + 1} and {pairs[0, 1] + 1} at {place(points[0])}; "
            f"{len(elements)} element(s) in all: {id_list(elements + 1)}. Parts meshed across each other "
            "are no model of a real structure and no contact can part them: move or trim one")
