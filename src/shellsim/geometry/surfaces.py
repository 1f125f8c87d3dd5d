"""Triangulated surfaces (STL, OBJ, PLY, VTP, OFF: anything meshio reads as triangles),
e.g. a vessel from segmentation, remeshed with gmsh into 9-node quadrilaterals.

The triangles become one discrete gmsh surface, which ``classifySurfaces`` splits at
sharp ridges into patches gmsh can reparametrise (``createGeometry``). Those are meshed
with triangles, recombined and split into quads (the frontal-Delaunay and blossom full-quad
algorithms, which give the same mesh on every run; the quasi-structured algorithm does
not). Every node is then moved onto the plane of the nearest facet, the second-order
ones from straight edges: gmsh places the split's new corners on the chords, and its own
second-order placement through the reparametrisation can land a node across a patch's
seam, folding its element.
The surface's open boundary loops (a vessel's ends) become edge sets, named by the deck
(``boundaries``: the loop nearest each point) or ``open_1``, ``open_2``, ... along the
surface's longest extent.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError, place
from ..mesh import EDGES, NamedSet
from ..mesh_reading import read_triangles
from .gmsh_extract import extract

#: Dihedral angle above which gmsh splits the surface into patches (degrees): a ridge
#: sharper than this stays a ridge.
RIDGE_DEG = 40.0
#: Name prefix of the open boundary loops the deck does not name.
LOOP_PREFIX = "open_"


def remesh(gmsh: Any, path: Path, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Quad9 nodes (n, 3) and connectivity (ne, 9) of the surface in ``path`` remeshed
    with elements of about ``size``, inside a gmsh session."""
    points, triangles = read_triangles(path)
    triangles = clean_facets(points, triangles, path)
    surface = gmsh.model.addDiscreteEntity(2)
    gmsh.model.mesh.addNodes(2, surface, np.arange(1, len(points) + 1), points.ravel())
    gmsh.model.mesh.addElementsByType(surface, 2, [], (triangles + 1).ravel())
    for key, value in (("Mesh.MeshSizeMin", size), ("Mesh.MeshSizeMax", size),
                       ("Mesh.Algorithm", 8), ("Mesh.RecombinationAlgorithm", 3),
                       ("Mesh.MeshSizeFromCurvature", 0), ("Mesh.SecondOrderLinear", 1)):
        gmsh.option.setNumber(key, value)
    try:
        gmsh.model.mesh.classifySurfaces(np.radians(RIDGE_DEG), True, True, np.pi)
        gmsh.model.mesh.createGeometry()
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
    except Exception as error:  # gmsh raises a bare Exception with its last error
        raise MeshError(f"surface file '{path}' could not be remeshed with geometry.element_size = {size:g}: "
                        f"{error}; a self-intersecting or non-manifold surface cannot be, and a size far "
                        "from the triangles' may need changing") from None
    x, conn, _, _ = extract(gmsh, f"surface file '{path}'")
    return onto_surface(points, triangles, x), conn


def clean_facets(points: np.ndarray, triangles: np.ndarray, path: Path) -> np.ndarray:
    """The facets (m', 3) of ``triangles`` (m, 3) on ``points`` (n, 3, coincident points
    merged) that gmsh can take: those with a corner twice (collapsed to an edge or a point)
    and repeats of another facet dropped, as segmentation leaves them. Raises MeshError
    for an edge shared by more than two facets (a non-manifold surface), naming where."""
    triangles = triangles[(triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2])
                          & (triangles[:, 0] != triangles[:, 2])]
    _, first = np.unique(np.sort(triangles, axis=1), axis=0, return_index=True)
    triangles = triangles[np.sort(first)]
    edges = np.sort(triangles[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)
    unique_edges, count = np.unique(edges, axis=0, return_counts=True)
    shared = unique_edges[count > 2]
    if len(shared):
        places = ", ".join(place(points[edge].mean(axis=0)) for edge in shared[:3])
        raise MeshError(f"surface file '{path}' is not a surface: {len(shared)} edge(s) are shared by more than two "
                        f"facets, e.g. near {places}; mend it (e.g. in MeshLab: Select non-manifold edges) first")
    return triangles


def onto_surface(points: np.ndarray, triangles: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """``nodes`` (k, 3) moved along the normal onto the plane of the triangle (of
    ``points`` (n, 3), ``triangles`` (m, 3)) whose centre is nearest."""
    from scipy.spatial import cKDTree

    corners = points[triangles]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = np.linalg.norm(normals, axis=1)
    corners, normals = corners[area > 0], normals[area > 0] / area[area > 0, None]  # slivers have no plane
    _, nearest = cKDTree(corners.mean(axis=1)).query(nodes)
    height = np.einsum("ki,ki->k", nodes - corners[nearest, 0], normals[nearest])
    return nodes - height[:, None] * normals[nearest]


def boundary_loops(x: np.ndarray, conn: np.ndarray, names: dict[str, tuple[float, float, float]],
                   path: Path) -> dict[str, NamedSet]:
    """The mesh's open boundary loops as edge sets: each of ``names`` takes the loop
    nearest its point, the rest are ``open_1``, ``open_2``, ... ordered along the
    surface's longest extent."""
    loops = _loops(conn)
    centres = np.array([x[np.unique(edges)].mean(axis=0) for edges in loops]).reshape(-1, 3)
    named: dict[str, np.ndarray] = {}
    taken: dict[int, str] = {}
    for name, point in names.items():
        if not loops:
            raise MeshError(f"geometry.boundaries.{name}: surface file '{path}' is closed; it has no open boundary")
        nearest = [min(np.linalg.norm(x[np.unique(edges)] - point, axis=1)) for edges in loops]
        loop = int(np.argmin(nearest))
        across = float(np.ptp(x[np.unique(loops[loop])], axis=0).max())
        if nearest[loop] > across:  # a point inside or on a loop is at most its width from it
            raise MeshError(f"geometry.boundaries.{name} = {place(point)} is {nearest[loop]:.4g} from the nearest "
                            f"boundary loop of '{path}' (near {place(centres[loop])}, {across:.4g} across): give a "
                            "point on the loop or at its centre, in the surface's units")
        if loop in taken:
            raise MeshError(f"geometry.boundaries.{name} = {place(point)} and geometry.boundaries.{taken[loop]} "
                            f"find the same boundary loop, near {place(centres[loop])}")
        taken[loop] = name
        named[name] = loops[loop]
    axis = int(np.argmax(np.ptp(x, axis=0)))
    rest = sorted((i for i in range(len(loops)) if i not in taken), key=lambda i: centres[i, axis])
    named |= {f"{LOOP_PREFIX}{k}": loops[i] for k, i in enumerate(rest, start=1)}
    return {name: NamedSet("edge", np.unique(edges), edges=edges) for name, edges in named.items()}


def _loops(conn: np.ndarray) -> list[np.ndarray]:
    """Element edges used by one element only, as (corner, mid-side, corner) triples (k, 3),
    grouped into connected loops."""
    edges = conn[:, EDGES].reshape(-1, 3)
    key = np.sort(edges[:, [0, 2]], axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    free = edges[first[counts == 1]]
    parent = {int(n): int(n) for n in free[:, [0, 2]].ravel()}

    def root(node: int) -> int:
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    for a, _, b in free:
        parent[root(int(a))] = root(int(b))
    groups: dict[int, list[int]] = {}
    for row, (a, _, _) in enumerate(free):
        groups.setdefault(root(int(a)), []).append(row)
    return [free[rows] for rows in groups.values()]
