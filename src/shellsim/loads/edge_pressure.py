"""Pressure on the shell's edge faces, compiled, its derivative with respect to the edge
nodes' DOFs (it turns with the shell), and its deck table."""

from __future__ import annotations

from typing import ClassVar, Literal, NamedTuple

import numpy as np
from numba import njit

from ..array_copy import copy_into
from ..curve_tables import factor
from ..element.frames import cross
from ..element.groups import gather_nodes
from ..element.shape import EDGE_DN, EDGE_N, EDGE_W, EDGES
from ..element.tangent import moved_node
from ..table_types import Name, Real
from .table import LoadTable


class EdgePressure(LoadTable):
    """Pressure on the shell's edge face along an edge set (force per unit edge length is
    ``value`` times the current thickness), normal to the edge in the shell's tangent plane;
    positive pushes into the shell, as a pressure does. Follows the deformation."""

    type: Literal["edge_pressure"]
    set: Name
    value: Real
    curve: Name | None = None
    SET_KINDS: ClassVar[tuple[str, ...]] = ("edge",)
    FEATURES: ClassVar[tuple[str, ...]] = ("edge_loads",)
    QUANTITY: ClassVar[str] = "stress"


TABLES = (EdgePressure,)


class Bundle(NamedTuple):
    """Pressure on edge faces (E,): edges (E, 3) node triples (corner, mid-side, corner),
    outward (+1 or -1, the sign that makes tangent x director point out), value
    [force/length^2], curve (index into :class:`shellsim.bundles.Curves`, -1 constant)."""

    edges: np.ndarray
    outward: np.ndarray
    value: np.ndarray
    curve: np.ndarray


def build(table: EdgePressure, scene) -> Bundle:
    """The loaded edges of one table on ``scene`` (:class:`shellsim.loads.LoadScene`)."""
    edges = scene.mesh.sets[table.set].edges.astype(np.int64)
    return Bundle(edges=edges, outward=_outward_signs(scene.mesh, edges), value=np.full(len(edges), table.value),
                  curve=np.full(len(edges), scene.curve_index(table.curve), dtype=np.int64))


def _outward_signs(mesh, edges: np.ndarray) -> np.ndarray:
    """+1 where tangent x director points away from the element owning the edge, else -1."""
    triples = mesh.conn[:, EDGES]  # (ne, 4, 3)
    owner = {frozenset(t): e for e, four in enumerate(triples.tolist()) for t in four}
    signs = np.empty(len(edges))
    for m, edge in enumerate(edges):
        e = owner[frozenset(edge.tolist())]
        tangent = mesh.x[edge[2]] - mesh.x[edge[0]]
        out = np.cross(tangent, mesh.director[edge[1]])
        signs[m] = 1.0 if out @ (mesh.x[edge[1]] - mesh.x[mesh.conn[e, 8]]) > 0 else -1.0
    return signs


@njit(cache=True)
def edge_forces(xe, de, he, outward, pressure, fe):
    """Adds the forces of a pressure [force/length^2] on one edge face to fe (3, 3): a
    force per unit edge length of p times the fibre length, normal to the edge within the
    shell, pushing in. The edge's (corner, mid-side, corner) nodes: xe, de (3, 3)
    positions and directors, he (3,) fibre lengths; outward (+1 or -1) the sign that makes
    tangent x director point out."""
    tan = np.empty(3)
    nrm = np.empty(3)
    out = np.empty(3)
    for p in range(3):
        tan[:] = 0.0
        nrm[:] = 0.0
        thick = 0.0
        for k in range(3):
            thick += EDGE_N[p, k] * he[k]
            for i in range(3):
                tan[i] += EDGE_DN[p, k] * xe[k, i]
                nrm[i] += EDGE_N[p, k] * de[k, i]
        nrm /= np.sqrt(nrm @ nrm)
        out[0], out[1], out[2] = cross(tan, nrm)
        for k in range(3):
            w = -outward * pressure * thick * EDGE_N[p, k] * EDGE_W[p]
            for i in range(3):
                fe[k, i] += w * out[i]


@njit(cache=True)
def add_forces(t, model, shape, loads, f, g):
    """f (n, 3) += the edge pressures' forces at time t on the current ``shape``
    (:func:`edge_forces`); they act on the mid-surface, so g takes nothing."""
    if loads.edges.shape[0] == 0:
        return  # no edge: nothing allocated in the time loop
    xe, de, he, fe = np.empty((3, 3)), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    for m in range(loads.edges.shape[0]):
        pressure = loads.value[m] * factor(model.curves, loads.curve[m], t)
        nodes = loads.edges[m]
        gather_nodes(shape, nodes, xe, de, he)
        for k in range(3):
            fe[k] = f[nodes[k]]  # summed in place: the nodal sums keep the order of every step
        edge_forces(xe, de, he, loads.outward[m], pressure, fe)
        for k in range(3):
            f[nodes[k]] = fe[k]


@njit(cache=True)
def add_tangent(t, model, shape, loads, step_u, step_r, k):
    """k (ne, 45, 45) -= the derivative of each loaded edge's nodal forces (its three
    nodes' x, y, z) with respect to their DOFs (five per node, order and steps as
    :mod:`shellsim.element.tangent`), by central differences, the fibre lengths held;
    into the first element holding the edge's mid-side node (which holds the whole edge)."""
    body = model.body
    xe, de, he, e1e = np.empty((3, 3)), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    fe = np.empty((3, 3))
    ke = np.empty((9, 15))
    local = np.empty(3, dtype=np.int64)
    for m in range(loads.edges.shape[0]):
        pressure = loads.value[m] * factor(model.curves, loads.curve[m], t)
        nodes = loads.edges[m]
        gather_nodes(shape, nodes, xe, de, he)
        ke[:] = 0.0
        for move in range(30):
            moved, node = move // 10, nodes[move // 10]
            step = moved_node(shape.x[node], shape.d[node], shape.e1[node], move % 10, (step_u, step_r),
                              (xe[moved], de[moved], e1e[moved]))
            fe[:] = 0.0
            edge_forces(xe, de, he, loads.outward[m], pressure, fe)
            weight = 1.0 / (2.0 * step)
            for a in range(3):
                for i in range(3):
                    ke[3 * a + i, move // 2] += weight * fe[a, i]
            copy_into(shape.x[node], xe[moved])  # the node back in place
            copy_into(shape.d[node], de[moved])
        element = body.slots[body.node_slots[nodes[1]]] // 9
        for a in range(3):
            for b in range(9):
                if body.conn[element, b] == nodes[a]:
                    local[a] = b
                    break
        for a in range(3):
            for i in range(3):
                for b in range(3):
                    for j in range(5):
                        k[element, 5 * local[a] + i, 5 * local[b] + j] -= ke[3 * a + i, 5 * b + j]
