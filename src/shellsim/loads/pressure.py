"""Follower pressure on element faces (thesis 3.12.1), compiled, and its derivative with
respect to the element's DOFs (a follower load turns with the shell: its tangent is not
symmetric)."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..element.frames import cross
from ..element.kinematics import fibre_point
from ..element.tangent import ELEMENT_DOFS, moved_node


@njit(cache=True)
def face_forces(rule, xe, de, he, face, pressure, fe, ge):
    """Adds the forces of a pressure [force/length^2] on one element's ``face`` (-1 bottom,
    0 mid-surface, +1 top) to fe, ge (9, 3): translational and director-conjugate. The
    element's nodes: xe, de (9, 3) positions and directors, he (9,) fibre lengths.

    Positive pushes into the shell, i.e. along +n on the bottom face and the mid-surface
    and along -n on the top face, n = g_r x g_s / |.| (the directors' side). Forces act
    where the face is, so the director-conjugate part carries their lever arm.
    """
    N, dNr, dNs, wq = rule.N, rule.dNr, rule.dNs, rule.wq
    t = float(face)
    sign = -1.0 if face > 0 else 1.0
    yr = np.empty(3)
    ys = np.empty(3)
    area = np.empty(3)
    for p in range(wq.shape[0]):
        yr[:] = 0.0
        ys[:] = 0.0
        for a in range(9):
            for i in range(3):
                pos = fibre_point(xe[a, i], de[a, i], he[a], t)
                yr[i] += dNr[p, a] * pos
                ys[i] += dNs[p, a] * pos
        area[0], area[1], area[2] = cross(yr, ys)
        for a in range(9):
            w = sign * pressure * N[p, a] * wq[p]
            for i in range(3):
                fe[a, i] += w * area[i]
                ge[a, i] += w * area[i] * t * 0.5 * he[a]


@njit(cache=True)
def gather_nodes(shape, nodes, xe, de, he):
    """The mid-surface points, directors and fibre lengths of a face's or an edge's nodes
    (k,) into xe, de (k, 3) and he (k,)."""
    for a in range(nodes.shape[0]):
        xe[a] = shape.x[nodes[a]]
        de[a] = shape.d[nodes[a]]
        he[a] = shape.h[nodes[a]]


@njit(cache=True)
def pressure_forces(rule, conn, shape, faces, scale, f, g):
    """Adds the forces of pressures ``scale`` (P,) [force/length^2] on ``faces``
    (:class:`shellsim.bundles.PressureLoads`) to f and g (n, 3) (:func:`face_forces`).
    rule: the element's :class:`~shellsim.bundles.Rule`; conn (ne, 9); shape: the
    current :class:`~shellsim.bundles.Shape`."""
    xe, de, he = np.empty((9, 3)), np.empty((9, 3)), np.empty(9)
    fe, ge = np.empty((9, 3)), np.empty((9, 3))
    for m in range(faces.elements.shape[0]):
        nodes = conn[faces.elements[m]]
        gather_nodes(shape, nodes, xe, de, he)
        for a in range(9):
            fe[a] = f[nodes[a]]  # summed in place: the nodal sums keep the order of every step
            ge[a] = g[nodes[a]]
        face_forces(rule, xe, de, he, faces.face[m], scale[m], fe, ge)
        for a in range(9):
            f[nodes[a]] = fe[a]
            g[nodes[a]] = ge[a]


@njit(cache=True)
def pressure_tangents(rule, conn, shape, faces, scale, step_u, step_r, k):
    """k (P, 45, 45): the derivative of each loaded face's nodal forces with respect to its
    element's DOFs, by central differences (order and steps as
    :mod:`shellsim.element.tangent`; the fibre lengths held)."""
    xe, de, he, e1e = np.empty((9, 3)), np.empty((9, 3)), np.empty(9), np.empty((9, 3))
    fe, ge = np.empty((9, 3)), np.empty((9, 3))
    for m in range(faces.elements.shape[0]):
        nodes = conn[faces.elements[m]]
        gather_nodes(shape, nodes, xe, de, he)
        for a in range(9):
            e1e[a] = shape.e1[nodes[a]]
        k[m] = 0.0
        for move in range(2 * ELEMENT_DOFS):
            moved, node = move // 10, nodes[move // 10]
            step = moved_node(shape.x[node], shape.d[node], shape.e1[node], move % 10, step_u, step_r, xe[moved],
                              de[moved], e1e[moved])
            fe[:] = 0.0
            ge[:] = 0.0
            face_forces(rule, xe, de, he, faces.face[m], scale[m], fe, ge)
            weight = 1.0 / (2.0 * step)
            column = move // 2
            for a in range(9):
                e2 = cross(de[a], e1e[a])
                for i in range(3):
                    k[m, 5 * a + i, column] += weight * fe[a, i]
                    k[m, 5 * a + 3, column] -= weight * e1e[a, i] * ge[a, i]
                    k[m, 5 * a + 4, column] -= weight * e2[i] * ge[a, i]
            xe[moved] = shape.x[node]  # the node back in place
            de[moved] = shape.d[node]
            e1e[moved] = shape.e1[node]
