"""Pressure on element faces (thesis 3.12.1): a follower load evaluated every step on the
current face, or a dead one tabulated on the initial face; compiled, with the follower's
derivative with respect to the element's DOFs (it turns with the shell: its tangent is
not symmetric)."""

from __future__ import annotations

from typing import ClassVar, Literal, NamedTuple

import numpy as np
from numba import njit, prange

from ..array_copy import copy_into
from ..bundles import slots_by_node
from ..curve_tables import factor
from ..element.frames import cross
from ..element.groups import gather_nodes
from ..element.kinematics import fibre_point
from ..element.tangent import ELEMENT_DOFS, moved_node
from ..mesh import FACES
from ..table_types import Name, Real
from . import nodal
from .table import LoadTable


class Pressure(LoadTable):
    """Pressure ``value * curve(t)`` on one face of a surface set: ``bottom`` (t = -1, the
    side the directors point away from), ``top`` (t = +1) or the ``mid`` surface. Positive
    pressure pushes into the shell: along the directors on the bottom face and the
    mid-surface (it inflates a tube whose directors point outward), against them on the top
    face. ``follower``: acts normal to the current face on its current area (thesis
    3.12.1); otherwise a dead load along the initial normal on the initial area."""

    type: Literal["pressure"]
    set: Name = "all"
    value: Real
    curve: Name | None = None
    face: Literal["bottom", "mid", "top"] = "mid"
    follower: bool = True
    SET_KINDS: ClassVar[tuple[str, ...]] = ("surface",)
    FEATURES: ClassVar[tuple[str, ...]] = ("follower_pressure", "dead_pressure")
    QUANTITY: ClassVar[str] = "pressure"

    @property
    def feature(self) -> str:
        return self.FEATURES[0] if self.follower else self.FEATURES[1]


TABLES = (Pressure,)


class Bundle(NamedTuple):
    """Follower pressure on element faces (P,): elements, face (-1 bottom, 0 mid, +1 top),
    values (P, nq) [force/length^2] at the face's Gauss points, curve (index into
    :class:`shellsim.bundles.Curves`, -1 constant); scratch of the forces' two passes:
    pressure (P, nq) the values at the time, area (P, nq, 3) the face's area vectors at its
    Gauss points. Over all tables (:func:`joined`; empty in one table's): each node's faces
    as compressed rows, node_slots (n + 1,) into slots (9P,) face * 9 + the node's place
    in it, in face order (:func:`shellsim.bundles.slots_by_node`)."""

    elements: np.ndarray
    face: np.ndarray
    values: np.ndarray
    curve: np.ndarray
    pressure: np.ndarray
    area: np.ndarray
    node_slots: np.ndarray
    slots: np.ndarray


def empty(scene) -> Bundle:
    """No follower pressure."""
    return faces(np.zeros(0, dtype=np.int64), 0, np.zeros((0, len(scene.rule.wq))), -1)


def faces(elements: np.ndarray, face: int, values: np.ndarray, curve: int) -> Bundle:
    """Pressures ``values`` (P, nq) at the Gauss points of one face of ``elements`` (P,),
    following curve ``curve``; its nodes' map still empty (:func:`joined`)."""
    count = len(elements)
    values = np.asarray(values, dtype=float)
    none = np.zeros(0, dtype=np.int64)
    return Bundle(elements=np.asarray(elements, dtype=np.int64), face=np.full(count, face, dtype=np.int64),
                  values=values, curve=np.full(count, curve, dtype=np.int64), pressure=np.zeros_like(values),
                  area=np.zeros((*values.shape, 3)), node_slots=none, slots=none)


def joined(loads: Bundle, scene) -> Bundle:
    """``loads`` of every table with the map from their nodes to the faces on them, in face
    order, with which each node sums its forces on its own (:func:`add_face_forces`)."""
    node_slots, slots = slots_by_node(scene.body.conn[loads.elements], scene.mesh.n_nodes)
    return loads._replace(node_slots=node_slots, slots=slots)


def build(table: Pressure, scene) -> Bundle | nodal.Bundle:
    """A follower pressure's faces, or a dead pressure's nodal forces on the initial
    shape (their director-conjugate part, the lever arm of an offset face, is not kept)."""
    elements = scene.mesh.sets[table.set].elements
    values = np.full((len(elements), len(scene.rule.wq)), table.value)
    curve = scene.curve_index(table.curve)
    if table.follower:
        return faces(elements, FACES[table.face], values, curve)
    f, g = np.zeros((scene.mesh.n_nodes, 3)), np.zeros((scene.mesh.n_nodes, 3))
    add_face_forces(scene.rule, scene.body.conn, scene.curves, 0.0, scene.initial,
                    joined(faces(elements, FACES[table.face], values, -1), scene), f, g)
    return nodal.dead_forces(f, curve)


#: The nodes of an element's own arrays (9, 3) in their order, for :func:`face_area`.
OWN_NODES = np.arange(9)


@njit(cache=True, inline="always")
def face_area(rule, x, d, h, nodes, t, p):
    """The area vector g_r x g_s (3-tuple) at Gauss point p of the face t (-1 bottom, 0
    mid-surface, +1 top) of the element on ``nodes`` (9,) of x, d (n, 3), h (n,)."""
    yr0 = yr1 = yr2 = ys0 = ys1 = ys2 = 0.0
    for a in range(9):
        node = nodes[a]
        pos = fibre_point(x[node, 0], d[node, 0], h[node], t)
        yr0 += rule.dNr[p, a] * pos
        ys0 += rule.dNs[p, a] * pos
        pos = fibre_point(x[node, 1], d[node, 1], h[node], t)
        yr1 += rule.dNr[p, a] * pos
        ys1 += rule.dNs[p, a] * pos
        pos = fibre_point(x[node, 2], d[node, 2], h[node], t)
        yr2 += rule.dNr[p, a] * pos
        ys2 += rule.dNs[p, a] * pos
    return cross((yr0, yr1, yr2), (ys0, ys1, ys2))


@njit(cache=True, inline="always")
def _weight(rule, face, pressure, p, a):
    """The weight of node a's share at Gauss point p of a face (-1, 0, +1) under
    ``pressure`` there. Positive pressure pushes into the shell, i.e. along +n on the
    bottom face and the mid-surface and along -n on the top face, n = g_r x g_s / |.|
    (the directors' side)."""
    sign = -1.0 if face > 0 else 1.0
    return sign * pressure * rule.N[p, a] * rule.wq[p]


@njit(cache=True)
def face_forces(rule, xe, de, he, face, pressure, fe, ge):
    """Adds the forces of the pressures (nq,) [force/length^2] at the Gauss points of one
    element's ``face`` (-1 bottom, 0 mid-surface, +1 top) to fe, ge (9, 3):
    translational and director-conjugate. The element's nodes: xe, de (9, 3) positions
    and directors, he (9,) fibre lengths. Forces act where the face is, so the
    director-conjugate part carries their lever arm (:func:`_weight` for their sense).
    """
    t = float(face)
    for p in range(rule.wq.shape[0]):
        area = face_area(rule, xe, de, he, OWN_NODES, t, p)
        for a in range(9):
            w = _weight(rule, face, pressure[p], p, a)
            for i in range(3):
                fe[a, i] += w * area[i]
                ge[a, i] += w * area[i] * t * 0.5 * he[a]


@njit(cache=True, parallel=True)
def add_face_forces(rule, conn, curves, t, shape, loads, f, g):
    """Adds the forces of the pressures of ``loads`` (:class:`Bundle`, :func:`joined`) at
    time t to f and g (n, 3), as :func:`face_forces` does face by face, over the threads:
    the faces' area vectors first, face by face, then each node's forces, its faces' in
    face order (the sums of a loop over the faces, in every bit). rule: the element's
    :class:`~shellsim.bundles.Rule`; conn (ne, 9); curves:
    :class:`~shellsim.bundles.Curves`; shape: the current :class:`~shellsim.bundles.Shape`."""
    x, d, h, elements, face, pressure, area = shape.x, shape.d, shape.h, loads.elements, loads.face, loads.pressure, loads.area
    values, curve, node_slots, slots = loads.values, loads.curve, loads.node_slots, loads.slots
    if elements.shape[0] == 0:
        return  # no face: no parallel loop started in the time step
    for m in prange(elements.shape[0]):
        c = factor(curves, curve[m], t)
        on = conn[elements[m]]
        for p in range(values.shape[1]):
            pressure[m, p] = values[m, p] * c
            area[m, p, 0], area[m, p, 1], area[m, p, 2] = face_area(rule, x, d, h, on, float(face[m]), p)
    for node in prange(node_slots.shape[0] - 1):
        for slot in range(node_slots[node], node_slots[node + 1]):
            m, a = divmod(slots[slot], 9)
            t_face = float(face[m])
            for p in range(values.shape[1]):
                w = _weight(rule, face[m], pressure[m, p], p, a)
                for i in range(3):
                    f[node, i] += w * area[m, p, i]
                    g[node, i] += w * area[m, p, i] * t_face * 0.5 * h[node]


@njit(cache=True)
def add_forces(t, model, shape, loads, f, g):
    """f, g (n, 3) += the follower pressures' translational and director-conjugate forces
    at time t on the current ``shape``."""
    add_face_forces(model.rule, model.body.conn, model.curves, t, shape, loads, f, g)


@njit(cache=True)
def add_tangent(t, model, shape, loads, step_u, step_r, k):
    """k (ne, 45, 45) -= the derivative of each loaded face's nodal forces at time t with
    respect to its element's DOFs, by central differences (order and steps as
    :mod:`shellsim.element.tangent`; the fibre lengths held)."""
    rule, conn = model.rule, model.body.conn
    xe, de, he, e1e = np.empty((9, 3)), np.empty((9, 3)), np.empty(9), np.empty((9, 3))
    fe, ge = np.empty((9, 3)), np.empty((9, 3))
    ke = np.empty((ELEMENT_DOFS, ELEMENT_DOFS))
    pressure = np.empty(loads.values.shape[1])
    for m in range(loads.elements.shape[0]):
        c = factor(model.curves, loads.curve[m], t)
        for p in range(pressure.shape[0]):
            pressure[p] = loads.values[m, p] * c
        nodes = conn[loads.elements[m]]
        gather_nodes(shape, nodes, xe, de, he)
        for a in range(9):
            copy_into(shape.e1[nodes[a]], e1e[a])
        ke[:] = 0.0
        for move in range(2 * ELEMENT_DOFS):
            moved, node = move // 10, nodes[move // 10]
            step = moved_node(shape.x[node], shape.d[node], shape.e1[node], move % 10, (step_u, step_r),
                              (xe[moved], de[moved], e1e[moved]))
            fe[:] = 0.0
            ge[:] = 0.0
            face_forces(rule, xe, de, he, loads.face[m], pressure, fe, ge)
            weight = 1.0 / (2.0 * step)
            column = move // 2
            for a in range(9):
                e2 = cross(de[a], e1e[a])
                for i in range(3):
                    ke[5 * a + i, column] += weight * fe[a, i]
                    ke[5 * a + 3, column] -= weight * e1e[a, i] * ge[a, i]
                    ke[5 * a + 4, column] -= weight * e2[i] * ge[a, i]
            copy_into(shape.x[node], xe[moved])  # the node back in place
            copy_into(shape.d[node], de[moved])
            copy_into(shape.e1[node], e1e[moved])
        element = loads.elements[m]
        for i in range(ELEMENT_DOFS):
            for j in range(ELEMENT_DOFS):
                k[element, i, j] -= ke[i, j]
