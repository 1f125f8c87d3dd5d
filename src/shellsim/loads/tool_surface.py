"""The shape of a rigid tool read from a triangulated surface (a stent, a catheter, a
balloon: STL, OBJ, PLY, VTP, OFF), for :mod:`shellsim.loads.rigid_tool`: its triangles
with their pseudo-normals, and the signed distance of a point from it, compiled.

The distance is the one to the nearest point of the nearest triangle; its sign is that of
the offset against the pseudo-normal of the feature the nearest point lies on: the
face's normal inside a triangle, the sum of the two faces' normals on an edge, the
faces' normals weighted by their angles at a vertex (Baerentzen & Aanaes 2005, IEEE
TVCG 11:243-253), which gives the right side everywhere, at edges and corners too, on a
consistently oriented surface. The tool only translates, so the triangles and their
search grid (:func:`shellsim.loads.contact_search.fill_grid`) are made once, in the
file's frame, and a point is taken into that frame instead.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numba import njit

from ..array_copy import copy_into
from ..errors import MeshError
from ..mesh_reading import facet_normals, read_triangles
from .contact_search import cell_faces, fill_grid, near_box

#: Where a triangle's nearest point lies, the row of its pseudo-normal: the face, its
#: vertices a, b, c, its edges ab, bc, ca.
FACE, VERTICES, EDGES = 0, (1, 2, 3), (4, 5, 6)


def read_tool(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The triangles (T, 3, 3) of the surface file ``path`` (corners a, b, c) and their
    pseudo-normals (T, 7, 3) (rows: :data:`FACE`, :data:`VERTICES`, :data:`EDGES`; the
    face's unit normal, the others unnormalised, only their sign against an offset
    counts). Triangles without area are dropped: nothing can touch them. MeshError for a
    surface whose triangles are not consistently oriented, or that has an edge shared
    by more than two of them: it has no inside and outside."""
    points, triangles = read_triangles(path)
    corners = points[triangles]
    normal = facet_normals(points, triangles)
    size = np.linalg.norm(normal, axis=1)
    kept = size > 1e-12 * size.max(initial=0.0)
    if not kept.any():
        raise MeshError(f"surface file '{path}' has no triangle with an area")
    triangles, corners, normal = triangles[kept], corners[kept], normal[kept] / size[kept, None]
    edges = triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 3, 2)
    undirected, where, count = np.unique(np.sort(edges.reshape(-1, 2), axis=1), axis=0, return_inverse=True,
                                         return_counts=True)
    where = where.reshape(-1, 3)
    if count.max() > 2:
        a, b = undirected[np.argmax(count)]
        raise MeshError(f"surface file '{path}': the edge between points {a} and {b} is shared by {count.max()} "
                        "triangles; a rigid tool's surface must have an inside and an outside")
    _, directed = np.unique(edges.reshape(-1, 2), axis=0, return_counts=True)
    if directed.max() > 1:
        raise MeshError(f"surface file '{path}': its triangles are not consistently oriented (neighbours run "
                        "through a shared edge the same way); orient them all alike, e.g. with a mesh "
                        "tool's 'orient faces' or 'fix normals'")
    pseudo = np.zeros((len(triangles), 7, 3))
    pseudo[:, FACE] = normal
    edge_sums = np.zeros((len(undirected), 3))
    np.add.at(edge_sums, where.ravel(), np.repeat(normal, 3, axis=0))
    pseudo[:, EDGES[0]:] = edge_sums[where]
    vertex_sums = np.zeros((triangles.max() + 1, 3))
    for k in range(3):
        after, before = corners[:, (k + 1) % 3] - corners[:, k], corners[:, (k + 2) % 3] - corners[:, k]
        cosine = np.einsum("ij,ij->i", after, before) / (np.linalg.norm(after, axis=1) * np.linalg.norm(before, axis=1))
        np.add.at(vertex_sums, triangles[:, k], np.arccos(np.clip(cosine, -1.0, 1.0))[:, None] * normal)
    pseudo[:, VERTICES[0]:EDGES[0]] = vertex_sums[triangles]
    return corners, pseudo


def search_grid(corners: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The bucket grid of the triangles (T, 3, 3), each listed where its box grown by
    ``reach`` lies: (boxes (T, 6), start (2 T + 1,), entries (8 T,), frame (4,) the
    cell width and the grid's origin)."""
    count = len(corners)
    boxes = np.concatenate([corners.min(axis=1), corners.max(axis=1)], axis=1)
    start, entries = np.zeros(2 * count + 1, dtype=np.int64), np.zeros(8 * count, dtype=np.int64)
    width, origin = fill_grid(np.full(count, reach), (boxes, start, entries))
    return boxes, start, entries, np.concatenate([[width], origin])


@njit(cache=True, inline="always")
def _nearest_on_triangle(p, a, b, c):
    """(row, q0, q1, q2): the point q of the triangle a, b, c (3,) nearest to p (3,) and
    the row of the pseudo-normal of where it lies (Ericson, Real-Time Collision
    Detection, 5.1.5)."""
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    ac0, ac1, ac2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    ap0, ap1, ap2 = p[0] - a[0], p[1] - a[1], p[2] - a[2]
    d1 = ab0 * ap0 + ab1 * ap1 + ab2 * ap2
    d2 = ac0 * ap0 + ac1 * ap1 + ac2 * ap2
    if d1 <= 0.0 and d2 <= 0.0:
        return VERTICES[0], a[0], a[1], a[2]
    bp0, bp1, bp2 = p[0] - b[0], p[1] - b[1], p[2] - b[2]
    d3 = ab0 * bp0 + ab1 * bp1 + ab2 * bp2
    d4 = ac0 * bp0 + ac1 * bp1 + ac2 * bp2
    if d3 >= 0.0 and d4 <= d3:
        return VERTICES[1], b[0], b[1], b[2]
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return EDGES[0], a[0] + v * ab0, a[1] + v * ab1, a[2] + v * ab2
    cp0, cp1, cp2 = p[0] - c[0], p[1] - c[1], p[2] - c[2]
    d5 = ab0 * cp0 + ab1 * cp1 + ab2 * cp2
    d6 = ac0 * cp0 + ac1 * cp1 + ac2 * cp2
    if d6 >= 0.0 and d5 <= d6:
        return VERTICES[2], c[0], c[1], c[2]
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return EDGES[2], a[0] + w * ac0, a[1] + w * ac1, a[2] + w * ac2
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return EDGES[1], b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])
    total = 1.0 / (va + vb + vc)
    v, w = vb * total, vc * total
    return FACE, a[0] + v * ab0 + w * ac0, a[1] + v * ab1 + w * ac1, a[2] + v * ab2 + w * ac2


@njit(cache=True, inline="always")
def signed_distance(tool, group, p, normal):
    """The signed distance of p (3,, in the file's frame) from the surface ``tool`` = (corners
    (T, 3, 3), pseudo (T, 7, 3), owner (T,), boxes (T, 6), start, entries, frame (4,)
    cell width and origin, reach): positive on the side its normals face, over the
    triangles whose owner is ``group``; the unit normal there (from the surface to p's
    side of it, turned to the positive side) into ``normal`` (3,). A point farther than
    ``reach`` from every triangle is at +inf (normal 0)."""
    corners, pseudo, owner, boxes, start, entries, frame, reach = tool
    nearest, row, where = np.inf, -1, 0
    if frame[0] == 0.0:  # no grid yet: the tool is not in place before the springs are set
        normal[:] = 0.0
        return np.inf
    first, stop = cell_faces(p, frame[0], frame[1:], start)
    for entry in range(first, stop):
        t = entries[entry]
        if owner[t] != group or not near_box(p, boxes, t, reach):
            continue
        feature, q0, q1, q2 = _nearest_on_triangle(p, corners[t, 0], corners[t, 1], corners[t, 2])
        squared = (p[0] - q0) ** 2 + (p[1] - q1) ** 2 + (p[2] - q2) ** 2
        if squared < nearest:
            nearest, row, where = squared, t, feature
            normal[0], normal[1], normal[2] = p[0] - q0, p[1] - q1, p[2] - q2
    if row < 0 or nearest > reach * reach:
        normal[:] = 0.0
        return np.inf
    distance = np.sqrt(nearest)
    if distance == 0.0:  # on the surface: the face's normal
        copy_into(pseudo[row, FACE], normal)
        return 0.0
    side = 1.0 if normal[0] * pseudo[row, where, 0] + normal[1] * pseudo[row, where, 1] \
        + normal[2] * pseudo[row, where, 2] >= 0.0 else -1.0
    for i in range(3):
        normal[i] *= side / distance
    return side * distance
