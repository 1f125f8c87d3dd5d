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
gmsh's mesh of a closed tube has slivers and folds along the seams of its
reparametrisation at some sizes: they are smoothed out (:mod:`.untangle`), and where some
stay the size is nudged, then the mesh is made by splitting every element of a mesh twice
as coarse into four (``ATTEMPTS``). gmsh runs in a child process, so a Ctrl-C or SIGTERM
stops it at once, and a size that would make an absurd number of elements (one in other
units than the surface's) is refused before it starts.
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
from ..mesh_reading import facet_normals, read_triangles
from .gmsh_extract import extract
from .untangle import bad_elements, untangled

#: Dihedral angle above which gmsh splits the surface into patches (degrees): a ridge
#: sharper than this stays a ridge.
RIDGE_DEG = 40.0
#: Name prefix of the open boundary loops the deck does not name.
LOOP_PREFIX = "open_"
#: Elements per square of the element size that the remeshing makes (1.2 to 1.4 on the
#: shipped carotid); the most elements a surface is remeshed into, and the count a
#: suggested size aims at when that is exceeded.
ELEMENTS_PER_SQUARE = 1.3
MOST_ELEMENTS, SUGGESTED_ELEMENTS = 1_000_000, 10_000
#: The meshes tried in turn until one has no bad element: (split, share of the element
#: size), full quads at the size and nudged from it, then split from twice the size.
NUDGES = (1.0, 0.97, 1.03, 0.94, 1.06, 0.91, 1.09)
ATTEMPTS = tuple((False, n) for n in NUDGES) + tuple((True, n) for n in NUDGES)


def remesh(path: Path, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Quad9 nodes (n, 3) and connectivity (ne, 9) of the surface in ``path`` remeshed
    with elements of about ``size``, by gmsh in a child process (a stop ends it at once).
    Raises MeshError for a surface that cannot be remeshed, one smaller than ``size``, or
    one whose area at ``size`` would make more than MOST_ELEMENTS elements (a size in
    other units than the surface's)."""
    points, triangles = read_triangles(path)
    triangles = clean_facets(points, triangles, path)
    area = float(np.linalg.norm(facet_normals(points, triangles), axis=1).sum() / 2)
    expected, across = ELEMENTS_PER_SQUARE * area / size**2, float(np.ptp(points, axis=0).max())
    if size > across:
        raise MeshError(f"geometry.element_size = {size:g} is larger than surface file '{path}' ({across:.4g} "
                        "across): is the size in the surface's units?")
    if expected > MOST_ELEMENTS:
        suggested = np.sqrt(ELEMENTS_PER_SQUARE * area / SUGGESTED_ELEMENTS)
        raise MeshError(f"geometry.element_size = {size:g} would remesh surface file '{path}' (area {area:.4g}, "
                        f"{across:.4g} across) into about {expected:.3g} elements, more than "
                        f"{MOST_ELEMENTS:,}: is the size in the surface's units? About {suggested:.3g} gives "
                        f"{SUGGESTED_ELEMENTS:,}")
    from .child import in_child

    return in_child(_remesh_in_gmsh, points, triangles, size, path)


def _remesh_in_gmsh(points: np.ndarray, triangles: np.ndarray, size: float, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """:func:`remesh`'s gmsh sessions (ATTEMPTS): the size first, then nudged by each of
    NUDGES in turn while the mesh keeps bad elements its mending could not mend (gmsh's meshes
    differ from size to size, and a bad element at one is seldom at the next), then the
    same with every element split into four from twice the size (no element then has
    three corners on an open end, which recombination leaves there at some sizes with a
    straight angle no mending can open); the first mesh with no bad element, else the
    one with fewest, for the checks that follow to name."""
    from .session import gmsh_session

    best, failure, planes = None, None, FacetPlanes(points, triangles)
    for split, nudge in ATTEMPTS:
        try:
            with gmsh_session(name="surface") as gmsh:
                x, conn = _quads(gmsh, points, triangles, planes, size * nudge, path, split)
        except MeshError as error:
            failure = failure or error
            continue
        bad = len(bad_elements(x, conn))
        if best is None or bad < best[0]:
            best = (bad, x, conn)
        if not bad:
            break
    if best is None:
        raise failure
    return best[1], best[2]


def _quads(gmsh: Any, points: np.ndarray, triangles: np.ndarray, planes: FacetPlanes, size: float, path: Path,
           split: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Quad9 nodes and connectivity of the facets remeshed in the gmsh session ``gmsh``,
    the nodes put on the facets' ``planes``; ``split``: recombined at twice the size and
    every element split into four (gmsh's subdivision), else recombined into full quads
    at the size."""
    surface = gmsh.model.addDiscreteEntity(2)
    gmsh.model.mesh.addNodes(2, surface, np.arange(1, len(points) + 1), points.ravel())
    gmsh.model.mesh.addElementsByType(surface, 2, [], (triangles + 1).ravel())
    coarse = 2.0 * size if split else size
    for key, value in (("Mesh.MeshSizeMin", coarse), ("Mesh.MeshSizeMax", coarse),
                       ("Mesh.Algorithm", 8), ("Mesh.RecombinationAlgorithm", 1 if split else 3),
                       ("Mesh.SubdivisionAlgorithm", 1 if split else 0),
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
    return untangled(planes(x), conn, planes), conn


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


class FacetPlanes:
    """The planes of a surface's facets (``points`` (n, 3), ``triangles`` (m, 3)), looked
    up by their centres, built once for every projection onto them."""

    def __init__(self, points: np.ndarray, triangles: np.ndarray):
        from scipy.spatial import cKDTree

        normals = facet_normals(points, triangles)
        area = np.linalg.norm(normals, axis=1)
        has_plane = area > 0  # slivers have none
        self.origins = points[triangles[has_plane, 0]]
        self.normals = normals[has_plane] / area[has_plane, None]
        self.tree = cKDTree(points[triangles[has_plane]].mean(axis=1))

    def __call__(self, nodes: np.ndarray) -> np.ndarray:
        """``nodes`` (k, 3) moved along the normal onto the plane of the facet whose centre
        is nearest."""
        _, nearest = self.tree.query(nodes)
        height = np.einsum("ki,ki->k", nodes - self.origins[nearest], self.normals[nearest])
        return nodes - height[:, None] * self.normals[nearest]


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
