"""What a mesh file must satisfy before anything numerical touches it.

Every defect found is listed, each with a count, the first few ids and where they are, so
one message tells the whole story. Ids count from 1 in the file's own order: nodes as the
file lists them, elements as its 9-node quadrilaterals follow one another.
"""

from __future__ import annotations

import numpy as np

from ..errors import id_list, place
from ..mesh import element_areas

#: How far a file's director may be from unit length and still be normalised silently.
DIRECTOR_LENGTH_TOLERANCE = 1e-3
#: An element whose area is below this fraction of its diameter squared has collapsed.
COLLAPSED_AREA = 1e-10

#: How to get 9-node quadrilaterals out of gmsh, for a file that holds other elements.
GMSH_QUAD9 = ("make 9-node quadrilaterals with gmsh: recombine the surfaces and mesh to second order, "
              "complete (gmsh -2 -order 2 -setnumber Mesh.RecombineAll 1 -setnumber Mesh.SecondOrderIncomplete 0 "
              "-setnumber Mesh.Algorithm 8 FILE.geo -o FILE.msh)")


def missing_nodes_problem(cell_type: str, cells: np.ndarray, n_points: int) -> list[str]:
    """Cells (m, k) of one type that name a node the file does not have."""
    outside = np.flatnonzero(((cells < 0) | (cells >= n_points)).reshape(len(cells), -1).any(axis=1))
    if not len(outside):
        return []
    return [f"{len(outside)} {cell_type} cell(s) name nodes the file does not have (it has {n_points}): "
            f"cells {id_list(outside + 1)} of that type"]


def repeated_node_problem(conn: np.ndarray) -> list[str]:
    """Elements (ne, 9) that name one node twice."""
    ordered = np.sort(conn, axis=1)
    repeated = np.flatnonzero((ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
    if not len(repeated):
        return []
    e = repeated[0]
    twice = np.unique(ordered[e][1:][ordered[e][1:] == ordered[e][:-1]]) + 1
    return [f"{len(repeated)} element(s) repeat a node (a collapsed element): elements "
            f"{id_list(repeated + 1)}; element {e + 1} names node {id_list(twice)} twice"]


def point_data_problems(x: np.ndarray, director: np.ndarray | None, thickness: np.ndarray | None,
                        node_ids: np.ndarray) -> list[str]:
    """Non-finite coordinates, directors or thicknesses; non-positive thicknesses; directors
    far from unit length. x (n, 3), director (n, 3), thickness (n,), node_ids (n,) 1-based."""
    problems = []

    def nodes(bad: np.ndarray, what: str) -> None:
        if bad.any():
            first = x[np.argmax(bad)]
            where = f", the first at {place(first)}" if np.isfinite(first).all() else ""
            problems.append(f"{int(bad.sum())} node(s) have {what}: nodes {id_list(node_ids[bad])}{where}")

    finite_x = np.isfinite(x).all(axis=1)
    nodes(~finite_x, "a coordinate that is not a finite number")
    if thickness is not None:
        nodes(~np.isfinite(thickness), "a 'thickness' that is not a finite number")
        nodes(np.isfinite(thickness) & (thickness <= 0), "a 'thickness' that is not positive")
    if director is not None:
        finite = np.isfinite(director).all(axis=1)
        nodes(~finite, "a 'director' that is not a finite vector")
        length = np.linalg.norm(np.where(finite[:, None], director, 1.0), axis=1)
        nodes(finite & (np.abs(length - 1) > DIRECTOR_LENGTH_TOLERANCE),
              f"a 'director' that is not a unit vector (length off 1 by more than {DIRECTOR_LENGTH_TOLERANCE:g})")
    return problems


def collapsed_problem(x: np.ndarray, conn: np.ndarray) -> list[str]:
    """Elements whose mid-surface area is (numerically) zero: x (n, 3), conn (ne, 9)."""
    nodes = x[conn]
    diameter = np.linalg.norm(nodes.max(axis=1) - nodes.min(axis=1), axis=1)
    bad = np.flatnonzero(element_areas(x, conn) <= COLLAPSED_AREA * diameter**2)
    if not len(bad):
        return []
    return [f"{len(bad)} element(s) have zero area: elements {id_list(bad + 1)}, the first "
            f"at {place(x[conn[bad[0]]].mean(axis=0))}"]

