"""Pressure on element faces (thesis 3.12.1): a follower load evaluated every step on the
current face, or a dead one tabulated on the initial face; compiled, with the follower's
derivative with respect to the element's DOFs (it turns with the shell: its tangent is
not symmetric)."""

from __future__ import annotations

from typing import ClassVar, Literal, NamedTuple

import numpy as np
from numba import njit

from ..array_copy import copy_into
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
    :class:`shellsim.bundles.Curves`, -1 constant)."""

    elements: np.ndarray
    face: np.ndarray
    values: np.ndarray
    curve: np.ndarray


def empty(scene) -> Bundle:
    """No follower pressure."""
    return faces(np.zeros(0, dtype=np.int64), 0, np.zeros((0, len(scene.rule.wq))), -1)


def faces(elements: np.ndarray, face: int, values: np.ndarray, curve: int) -> Bundle:
    """Pressures ``values`` (P, nq) at the Gauss points of one face of ``elements`` (P,),
    following curve ``curve``."""
    count = len(elements)
    return Bundle(elements=np.asarray(elements, dtype=np.int64), face=np.full(count, face, dtype=np.int64),
                  values=np.asarray(values, dtype=float), curve=np.full(count, curve, dtype=np.int64))


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
                    faces(elements, FACES[table.face], values, -1), f, g)
    return nodal.dead_forces(f, curve)


@njit(cache=True)
def face_forces(rule, xe, de, he, face, pressure, fe, ge):
    """Adds the forces of the pressures (nq,) [force/length^2] at the Gauss points of one
    element's ``face`` (-1 bottom, 0 mid-surface, +1 top) to fe, ge (9, 3):
    translational and director-conjugate. The element's nodes: xe, de (9, 3) positions
    and directors, he (9,) fibre lengths.

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
            w = sign * pressure[p] * N[p, a] * wq[p]
            for i in range(3):
                fe[a, i] += w * area[i]
                ge[a, i] += w * area[i] * t * 0.5 * he[a]


@njit(cache=True)
def add_face_forces(rule, conn, curves, t, shape, loads, f, g):
    """Adds the forces of the pressures of ``loads`` (:class:`Bundle`) at time t to f and g
    (n, 3) (:func:`face_forces`). rule: the element's :class:`~shellsim.bundles.Rule`;
    conn (ne, 9); curves: :class:`~shellsim.bundles.Curves`; shape: the current
    :class:`~shellsim.bundles.Shape`."""
    if loads.elements.shape[0] == 0:
        return  # no face: nothing allocated in the time loop
    xe, de, he = np.empty((9, 3)), np.empty((9, 3)), np.empty(9)
    fe, ge = np.empty((9, 3)), np.empty((9, 3))
    pressure = np.empty(loads.values.shape[1])
    for m in range(loads.elements.shape[0]):
        c = factor(curves, loads.curve[m], t)
        for p in range(pressure.shape[0]):
            pressure[p] = loads.values[m, p] * c
        nodes = conn[loads.elements[m]]
        gather_nodes(shape, nodes, xe, de, he)
        for a in range(9):
            copy_into(f[nodes[a]], fe[a])  # summed in place: the nodal sums keep the order of every step
            copy_into(g[nodes[a]], ge[a])
        face_forces(rule, xe, de, he, loads.face[m], pressure, fe, ge)
        for a in range(9):
            copy_into(fe[a], f[nodes[a]])
            copy_into(ge[a], g[nodes[a]])


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
