"""Pressure on the shell's edge faces, compiled, its derivative with respect to the edge
nodes' DOFs (it turns with the shell), and the edge quadrature it shares with the dead
edge loads."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..element.frames import cross
from ..element.tangent import moved_node
from .pressure import gather_nodes

#: 3-point Gauss rule along an element edge and the 1D quadratic shape functions at its
#: points, for (corner, mid-side, corner) node triples.
EDGE_XI = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
EDGE_W = np.array([5.0, 8.0, 5.0]) / 9.0
EDGE_N = np.stack([EDGE_XI * (EDGE_XI - 1) / 2, 1 - EDGE_XI**2, EDGE_XI * (EDGE_XI + 1) / 2], axis=1)
EDGE_DN = np.stack([EDGE_XI - 0.5, -2 * EDGE_XI, EDGE_XI + 0.5], axis=1)


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
def edge_pressure_forces(shape, loads, scale, f):
    """Pressure ``scale`` (E,) [force/length^2] on the edge faces of ``loads``
    (:class:`shellsim.bundles.EdgePressureLoads`), :func:`edge_forces`. Adds to f (n, 3);
    shape: the current :class:`~shellsim.bundles.Shape`."""
    xe, de, he, fe = np.empty((3, 3)), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    for m in range(loads.edges.shape[0]):
        nodes = loads.edges[m]
        gather_nodes(shape, nodes, xe, de, he)
        for k in range(3):
            fe[k] = f[nodes[k]]  # summed in place: the nodal sums keep the order of every step
        edge_forces(xe, de, he, loads.outward[m], scale[m], fe)
        for k in range(3):
            f[nodes[k]] = fe[k]


@njit(cache=True)
def edge_pressure_tangents(shape, loads, scale, step_u, step_r, k):
    """k (E, 9, 15): the derivative of each loaded edge's nodal forces (its three nodes'
    x, y, z) with respect to their DOFs (five per node, order and steps as
    :mod:`shellsim.element.tangent`), by central differences, the fibre lengths held."""
    xe, de, he, e1e = np.empty((3, 3)), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    fe = np.empty((3, 3))
    for m in range(loads.edges.shape[0]):
        nodes = loads.edges[m]
        gather_nodes(shape, nodes, xe, de, he)
        k[m] = 0.0
        for move in range(30):
            moved, node = move // 10, nodes[move // 10]
            step = moved_node(shape.x[node], shape.d[node], shape.e1[node], move % 10, step_u, step_r, xe[moved],
                              de[moved], e1e[moved])
            fe[:] = 0.0
            edge_forces(xe, de, he, loads.outward[m], scale[m], fe)
            weight = 1.0 / (2.0 * step)
            for a in range(3):
                for i in range(3):
                    k[m, 3 * a + i, move // 2] += weight * fe[a, i]
            xe[moved] = shape.x[node]  # the node back in place
            de[moved] = shape.d[node]
