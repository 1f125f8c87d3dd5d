"""The shell mesh as flat arrays, and the geometric facts derived from it: consistent
element orientation, nodal directors, Jacobians, area, named points.

Node order inside an element is the thesis' (:mod:`shellsim.element.shape`).
"""

from __future__ import annotations

import functools
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from .element.shape import EDGES, NODE_RS, gauss_rule, gauss_rule_2d, shape, shape_derivatives
from .errors import MeshError, id_list, place

#: Node permutation that reverses an element's orientation (swaps r and s).
FLIP = np.array([0, 3, 2, 1, 7, 6, 5, 4, 8])
#: The shell's faces by name, as thickness coordinates.
FACES = {"bottom": -1, "mid": 0, "top": 1}


@dataclass(frozen=True)
class NamedSet:
    """Nodes of a named set and, for edge and surface sets, the pieces they are made of.

    kind : 'surface', 'edge', 'point' or 'line' (cable elements).
    nodes : (k,) int — sorted node indices.
    elements : (m,) int — element indices (surface sets; of ``Mesh.lines`` for line sets).
    edges : (m, 3) int — element edges as (corner, mid-side, corner) node triples (edge sets).
    """

    kind: str
    nodes: np.ndarray
    elements: np.ndarray | None = None
    edges: np.ndarray | None = None


@dataclass(frozen=True)
class Mesh:
    """A shell mesh of 9-node quadrilaterals.

    x : (n_nodes, 3) float — mid-surface node positions.
    conn : (n_elements, 9) int — node indices per element, thesis order.
    director : (n_nodes, 3) float — unit nodal directors.
    thickness : (n_nodes,) float — nodal fibre lengths h_a.
    sets : name -> NamedSet.
    cell_vectors : name -> (n_elements, 3) float — per-element vectors a mesh file carries
        (e.g. fibre directions).
    point_fields, cell_fields : name -> (n_nodes,) or (n_elements,) float — scalar fields a
        mesh file carries (e.g. a wall-pressure map for a mapped pressure).
    lines : (n_lines, 2) int — the two nodes of each cable element (:mod:`shellsim.loads.cable`);
        their nodes may belong to no shell element.
    """

    x: np.ndarray
    conn: np.ndarray
    director: np.ndarray
    thickness: np.ndarray
    sets: dict[str, NamedSet] = field(default_factory=dict)
    cell_vectors: dict[str, np.ndarray] = field(default_factory=dict)
    point_fields: dict[str, np.ndarray] = field(default_factory=dict)
    cell_fields: dict[str, np.ndarray] = field(default_factory=dict)
    lines: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))

    @property
    def n_nodes(self) -> int:
        return len(self.x)

    @property
    def n_elements(self) -> int:
        return len(self.conn)


#: The mesh fields that hold a model file's number of each node (0 for a node shellsim
#: added: a mid-edge or centre node) and of each element; a run writes them in every frame.
SOURCE_NODE, SOURCE_ELEMENT = "source_node", "source_element"


@dataclass(frozen=True)
class ImportedMesh:
    """What a file gives: x (n, 3), conn (ne, 9), sets, optional director (n, 3) and
    thickness (n,), per-element vectors (ne, 3) and scalar fields per node (n,) and per
    element (ne,) by name; lines (L, 2) its cable elements (their nodes may be on no shell)."""

    x: np.ndarray
    conn: np.ndarray
    sets: dict[str, NamedSet]
    director: np.ndarray | None
    thickness: np.ndarray | None
    cell_vectors: dict[str, np.ndarray]
    point_fields: dict[str, np.ndarray]
    cell_fields: dict[str, np.ndarray]
    lines: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))


def tangents(x: np.ndarray, conn: np.ndarray, rs: np.ndarray) -> np.ndarray:
    """Surface tangents g_r = dx/dr, g_s = dx/ds at natural points ``rs``.

    Shapes: x (n, 3), conn (ne, 9), rs (q, 2) -> (ne, q, 2, 3).
    """
    return np.einsum("qad,eai->eqdi", shape_derivatives(rs), x[conn])


def element_normals(x: np.ndarray, conn: np.ndarray, rs: np.ndarray) -> np.ndarray:
    """Unnormalised normals g_r x g_s at ``rs``: (ne, q, 3); their length is the area density."""
    g = tangents(x, conn, rs)
    return np.cross(g[:, :, 0], g[:, :, 1])


def node_areas(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """(n,) each node's share of the mid-surface through x (n, 3), int N_a dA, by the 3 x 3
    rule: the area a uniform pressure's consistent load gives the node."""
    rs, weights = gauss_rule_2d(3)
    areas = np.zeros(len(x))
    np.add.at(areas, conn, (np.linalg.norm(element_normals(x, conn, rs), axis=-1) * weights) @ shape(rs))
    return areas


def orient_consistently(x: np.ndarray, conn: np.ndarray, preferred: np.ndarray | None) -> np.ndarray:
    """Connectivity with every element ordered so that neighbours agree on the normal.

    Neighbours sharing an edge must walk it in opposite directions; walking the element
    graph breadth-first flips those that do not. In each connected piece the first element
    is the one whose normal lines up best with its ``preferred`` direction (ne, 3), if
    given, and it is turned to agree with it. Returns a new (ne, 9) array.
    """
    conn = conn.copy()
    n_el = len(conn)
    centre_normal = element_normals(x, conn, np.zeros((1, 2)))[:, 0]
    alignment = np.zeros(n_el)
    if preferred is not None:
        h = preferred
        alignment = np.einsum("ei,ei->e", centre_normal, h) / (
            np.linalg.norm(centre_normal, axis=1) * np.linalg.norm(h, axis=1) + 1e-300
        )
    by_edge: dict[tuple[int, int], list[int]] = {}
    for e, nodes in enumerate(conn):
        for a, _, b in EDGES:
            by_edge.setdefault((min(nodes[a], nodes[b]), max(nodes[a], nodes[b])), []).append(e)
    flipped = np.zeros(n_el, dtype=bool)
    seen = np.zeros(n_el, dtype=bool)
    for seed in np.argsort(-np.abs(alignment)):
        if seen[seed]:
            continue
        seen[seed] = True
        if alignment[seed] < 0:
            conn[seed] = conn[seed][FLIP]
            flipped[seed] = True
        queue = deque([seed])
        while queue:
            e = queue.popleft()
            walked = {(conn[e][a], conn[e][b]) for a, _, b in EDGES}
            for a, _, b in EDGES:
                key = (min(conn[e][a], conn[e][b]), max(conn[e][a], conn[e][b]))
                for other in by_edge[key]:
                    if seen[other]:
                        continue
                    seen[other] = True
                    other_walks = {(conn[other][p], conn[other][q]) for p, _, q in EDGES}
                    if walked & other_walks:
                        conn[other] = conn[other][FLIP]
                    queue.append(other)
    return conn


def averaged_directors(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Unit directors: the mean of the unit normals of the elements meeting at each node,
    each evaluated at the node itself. Shapes: (n, 3), (ne, 9) -> (n, 3)."""
    normals = element_normals(x, conn, NODE_RS)  # (ne, 9 node positions, 3)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    total = np.zeros_like(x)
    np.add.at(total, conn, normals)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    if np.any(length < 1e-12):
        raise MeshError("a node's element normals cancel out (the mesh folds back on itself)")
    return total / length


def combine_surface_normals(reference: np.ndarray, pieces: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """Unit directors from exact surface normals given per surface patch.

    Each patch's normals are signed to agree with ``reference`` (n, 3), the directors of the
    oriented elements, then averaged where patches meet. Nodes on no patch keep
    ``reference``. ``pieces``: list of (nodes (k,), normals (k, 3)).
    """
    total = np.zeros_like(reference)
    for nodes, normals in pieces:
        sign = np.sign(np.einsum("ki,ki->k", normals, reference[nodes]))
        np.add.at(total, nodes, sign[:, None] * normals)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    return np.where(length > 1e-12, total / np.maximum(length, 1e-300), reference)


def jacobian_determinants(mesh: Mesh, n_inplane: int = 3, n_thick: int = 2) -> np.ndarray:
    """det of the 3D Jacobian at the Gauss points of the mesh as built: (ne, n_inplane**2, n_thick);
    see :func:`body_jacobians`."""
    return body_jacobians(mesh.x, mesh.conn, mesh.director, mesh.thickness, n_inplane, n_thick)


def body_jacobians(x: np.ndarray, conn: np.ndarray, director: np.ndarray, thickness: np.ndarray,
                   n_inplane: int = 3, n_thick: int = 2) -> np.ndarray:
    """det of the 3D Jacobian [dx/dr, dx/ds, dx/dt] of the shell body at the Gauss points,
    x(r, s, t) = sum_a N_a (x_a + t h_a/2 d_a), for any shape of it (initial or current).

    Shapes: x (n, 3), conn (ne, 9), director (n, 3), thickness (n,) -> (ne, n_inplane**2, n_thick).
    """
    N, dNr, dNs, t = _body_points(n_inplane, n_thick)
    layers = [layer_geometry(x, director, thickness, conn, N, dNr, dNs, tk)[1] for tk in t]
    return np.stack([np.linalg.det(jacobian) for jacobian in layers], axis=-1)


@functools.cache
def _body_points(n_inplane: int, n_thick: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The shape functions N, dN/dr, dN/ds (q, 9) at the in-plane Gauss points and the
    thickness coordinates (n_thick,) of :func:`body_jacobians`, read-only: formed once,
    as every critical-step estimate checks the elements' Jacobians (on a 30-element flap
    forming them again took 0.4 ms of a 5.8 ms estimate)."""
    rs, _ = gauss_rule_2d(n_inplane)
    t, _ = gauss_rule(n_thick)
    dn = shape_derivatives(rs)  # (q, 9, 2)
    points = (shape(rs), np.ascontiguousarray(dn[:, :, 0]), np.ascontiguousarray(dn[:, :, 1]), t)
    for array in points:
        array.setflags(write=False)
    return points


def layer_geometry(x: np.ndarray, d: np.ndarray, h: np.ndarray, conn: np.ndarray, N, dNr, dNs,
                   t: float) -> tuple[np.ndarray, np.ndarray]:
    """Positions (ne, q, 3) and Jacobians dy/d(r, s, t) (ne, q, 3, 3, columns) of the
    points (N, dNr, dNs: (q, 9)) on the layer at thickness coordinate t, for mid-surface
    nodes x (n, 3), directors d (n, 3) and fibre lengths h (n,)."""
    xe, fe = x[conn], (0.5 * h[:, None] * d)[conn]
    pos = xe + t * fe
    jac = np.stack([np.einsum("qa,eai->eqi", dNr, pos), np.einsum("qa,eai->eqi", dNs, pos),
                    np.einsum("qa,eai->eqi", N, fe)], axis=-1)
    return np.einsum("qa,eai->eqi", N, pos), jac


def inverse_jacobians(mesh: Mesh, N, dNr, dNs, tz) -> np.ndarray:
    """(ne, q, nt, 3, 3) inverses of dy/d(r, s, t) on the initial shape at the points
    (N, dNr, dNs: (q, 9)) of the layers tz (nt,)."""
    out = np.empty((mesh.n_elements, len(N), len(tz), 3, 3))
    for k, t in enumerate(tz):
        jacobian = layer_geometry(mesh.x, mesh.director, mesh.thickness, mesh.conn, N, dNr, dNs, t)[1]
        out[:, :, k] = np.linalg.inv(jacobian)
    return out


def check_mesh(mesh: Mesh, source: str, n_thick: int = 2) -> None:
    """Raise MeshError unless every element has 9 nodes and a positive Jacobian at every
    Gauss point (3 x 3 in-plane, ``n_thick`` through the thickness). ``source`` names where
    the mesh came from in the message (a file, a builder); elements count from 1 in its order."""
    if mesh.conn.ndim != 2 or mesh.conn.shape[1] != 9:
        raise MeshError(f"{source}: elements must have 9 nodes, got connectivity of shape {mesh.conn.shape}")
    det = jacobian_determinants(mesh, 3, n_thick)
    bad = np.unique(np.nonzero(det <= 0)[0])
    if not len(bad):
        return
    first = bad[0]
    centre = mesh.x[mesh.conn[first]].mean(axis=0)
    normal = element_normals(mesh.x, mesh.conn[first:first + 1], NODE_RS)[0]
    against = np.einsum("ai,ai->a", normal, mesh.director[mesh.conn[first]]) <= 0
    why = ("its directors point against its surface normal at nodes "
           f"{id_list(np.flatnonzero(against) + 1)} of 9" if against.any()
           else "its edges fold or a mid-side node lies outside it, or it is thicker than its curvature allows")
    raise MeshError(
        f"{source}: {len(bad)} element(s) have a non-positive Jacobian (an inverted or folded element): "
        f"elements {id_list(bad + 1)}; element {first + 1} at {place(centre)}: {why}"
    )


def element_areas(x: np.ndarray, conn: np.ndarray, n_gauss: int = 3) -> np.ndarray:
    """Mid-surface area of each element by Gauss quadrature of |g_r x g_s|: x (n, 3), conn (ne, 9) -> (ne,)."""
    rs, w = gauss_rule_2d(n_gauss)
    return np.einsum("eq,q->e", np.linalg.norm(element_normals(x, conn, rs), axis=-1), w)


def mid_surface_area(mesh: Mesh, n_gauss: int = 3) -> float:
    """Area of the mid-surface."""
    return float(element_areas(mesh.x, mesh.conn, n_gauss).sum())


def edges_within(conn: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Element edges whose three nodes all belong to ``nodes``, each once: (m, 3)."""
    member = np.zeros(max(conn.max(), np.max(nodes, initial=0)) + 1, dtype=bool)  # a cable's nodes come last
    member[nodes] = True
    triples = conn[:, EDGES].reshape(-1, 3)
    inside = triples[member[triples].all(axis=1)]
    _, first = np.unique(np.sort(inside, axis=1), axis=0, return_index=True)
    return inside[np.sort(first)]


def snap_points(x: np.ndarray, points: dict[str, tuple[float, float, float]],
                reach: float | None = None) -> dict[str, NamedSet]:
    """Named point sets at the nodes nearest the given positions.

    A position farther than ``reach`` (by default 1e-6 of the model size: the node must
    be there) from every node is an error (it would silently probe the wrong place)."""
    size = float(np.linalg.norm(x.max(axis=0) - x.min(axis=0))) or 1.0
    reach = 1e-6 * size if reach is None else reach
    sets = {}
    for name, p in points.items():
        distance = np.linalg.norm(x - np.asarray(p), axis=1)
        nearest = int(np.argmin(distance))
        if distance[nearest] > reach:
            raise MeshError(
                f"mesh.points.{name}: {list(p)} is not at a node; the nearest node is "
                f"{x[nearest].round(12).tolist()}, {distance[nearest]:.4g} away"
            )
        sets[name] = NamedSet("point", np.array([nearest]))
    return sets
