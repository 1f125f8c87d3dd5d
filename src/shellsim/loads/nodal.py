"""Dead nodal forces and moments: loads tabulated once on the initial shape as nodal
vectors (edge, point and body loads here; a dead pressure lowers to them too), each
scaled by its curve, and the stiffness of a dead moment, which turns with the director."""

from __future__ import annotations

from typing import ClassVar, Literal, NamedTuple

import numpy as np
from numba import njit

from ..array_copy import copy_into
from ..curve_tables import factor
from ..element.frames import rotate_director, rotational_at
from ..element.shape import EDGE_DN, EDGE_N, EDGE_W
from ..mesh import inverse_jacobians
from ..table_types import Name, Vec3
from .table import LoadTable


class VectorLoad(LoadTable):
    """A load with global vector components, ``value * curve(t)``."""

    set: Name
    value: Vec3
    curve: Name | None = None


class EdgeForce(VectorLoad):
    """Force per unit (initial) length along an edge set, global components."""

    type: Literal["edge_force"]
    SET_KINDS: ClassVar[tuple[str, ...]] = ("edge",)
    FEATURES: ClassVar[tuple[str, ...]] = ("edge_loads",)


class EdgeMoment(VectorLoad):
    """Moment per unit (initial) length along an edge set, global components."""

    type: Literal["edge_moment"]
    SET_KINDS: ClassVar[tuple[str, ...]] = ("edge",)
    FEATURES: ClassVar[tuple[str, ...]] = ("edge_loads",)


class PointForce(VectorLoad):
    """Force on every node of a set, global components."""

    type: Literal["point_force"]
    SET_KINDS: ClassVar[tuple[str, ...]] = ("point", "edge", "surface")
    FEATURES: ClassVar[tuple[str, ...]] = ("point_loads",)


class PointMoment(VectorLoad):
    """Moment on every node of a set, global components."""

    type: Literal["point_moment"]
    SET_KINDS: ClassVar[tuple[str, ...]] = ("point", "edge", "surface")
    FEATURES: ClassVar[tuple[str, ...]] = ("point_loads",)


class BodyForce(VectorLoad):
    """Force per unit (initial) volume on a surface set, global components (self-weight is
    density times gravity)."""

    type: Literal["body_force"]
    set: Name = "all"
    SET_KINDS: ClassVar[tuple[str, ...]] = ("surface",)
    FEATURES: ClassVar[tuple[str, ...]] = ("body_force",)


TABLES = (EdgeForce, EdgeMoment, PointForce, PointMoment, BodyForce)


class Bundle(NamedTuple):
    """Dead nodal vectors (n nodes): forces (F, n, 3) and moments (M, n, 3), each scaled
    by its curve, force_curve (F,) and moment_curve (M,) (index into
    :class:`shellsim.bundles.Curves`, -1 constant)."""

    forces: np.ndarray
    force_curve: np.ndarray
    moments: np.ndarray
    moment_curve: np.ndarray


def empty(scene) -> Bundle:
    """No dead loads on ``scene``'s mesh."""
    n = scene.mesh.n_nodes
    return Bundle(forces=np.zeros((0, n, 3)), force_curve=np.zeros(0, dtype=np.int64),
                  moments=np.zeros((0, n, 3)), moment_curve=np.zeros(0, dtype=np.int64))


def dead_forces(vectors: np.ndarray, curve: int, moments: bool = False) -> Bundle:
    """One dead load of nodal vectors (n, 3), forces or ``moments``, following curve
    ``curve``."""
    one, none = vectors[None], np.zeros((0,) + vectors.shape)
    curves, no_curve = np.array([curve], dtype=np.int64), np.zeros(0, dtype=np.int64)
    if moments:
        return Bundle(forces=none, force_curve=no_curve, moments=one, moment_curve=curves)
    return Bundle(forces=one, force_curve=curves, moments=none, moment_curve=no_curve)


def build(table: VectorLoad, scene) -> Bundle:
    """The nodal vectors of one table on ``scene`` (:class:`shellsim.loads.LoadScene`)."""
    mesh = scene.mesh
    named = mesh.sets[table.set]
    vectors = np.zeros((mesh.n_nodes, 3))
    value = np.asarray(table.value)
    if table.type in ("edge_force", "edge_moment"):
        np.add.at(vectors, named.edges, _edge_integral(mesh.x, named.edges)[:, :, None] * value)
    elif table.type in ("point_force", "point_moment"):
        vectors[named.nodes] += value
    else:  # body force per unit initial volume
        vectors += _nodal_volumes(mesh, named.elements, scene.rule)[:, None] * value
    return dead_forces(vectors, scene.curve_index(table.curve), moments=table.type.endswith("moment"))


def _edge_integral(x0: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Consistent nodal weights int N_k ds over edge segments (m, 3) on the initial
    geometry: (m, 3) lengths (1/6 : 4/6 : 1/6 of a straight segment)."""
    tangent = np.einsum("pk,mki->mpi", EDGE_DN, x0[edges])
    return np.einsum("pk,mp,p->mk", EDGE_N, np.linalg.norm(tangent, axis=-1), EDGE_W)


def _nodal_volumes(mesh, elements: np.ndarray, rule) -> np.ndarray:
    """int N_a dV over ``elements`` on the initial configuration, per node: (n,)."""
    nq = len(rule.wq)
    jac_inv = inverse_jacobians(mesh, rule.N[:nq], rule.dNr[:nq], rule.dNs[:nq], rule.tz)[elements]
    dv = np.einsum("q,t,eqt->eqt", rule.wq, rule.wt, 1.0 / np.linalg.det(jac_inv))
    out = np.zeros(mesh.n_nodes)
    np.add.at(out, mesh.conn[elements], np.einsum("qa,eqt->ea", rule.N[:nq], dv))
    return out


@njit(cache=True)
def add_forces(t, model, shape, loads, f, g):
    """f (n, 3) += sum_k curve_k(t) forces[k]; g (n, 3) += the director-conjugate forces
    M x d of the moments M(t): a moment M turns the director d by M x d."""
    curves, d = model.curves, shape.d
    for k in range(loads.force_curve.shape[0]):
        c = factor(curves, loads.force_curve[k], t)
        for node in range(f.shape[0]):
            for i in range(3):
                f[node, i] += c * loads.forces[k, node, i]
    for k in range(loads.moment_curve.shape[0]):
        c = factor(curves, loads.moment_curve[k], t)
        for node in range(g.shape[0]):
            mx, my, mz = c * loads.moments[k, node, 0], c * loads.moments[k, node, 1], c * loads.moments[k, node, 2]
            g[node, 0] += my * d[node, 2] - mz * d[node, 1]
            g[node, 1] += mz * d[node, 0] - mx * d[node, 2]
            g[node, 2] += mx * d[node, 1] - my * d[node, 0]


@njit(cache=True)
def add_tangent(t, model, shape, loads, step_u, step_r, k):
    """Less the derivative of the dead moments' rotational forces with respect to their
    nodes' rotations (central differences of step_r [rad]), into each node's diagonal
    block in the first element holding it (k (ne, 45, 45)). Dead forces have none."""
    n = shape.d.shape[0]
    body = model.body
    moment = np.empty(3)
    d, e1, g = np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3))
    fr = np.empty((1, 2))
    block = np.empty((2, 2))
    for node in range(n):
        moment[:] = 0.0
        loaded = False
        for m in range(loads.moment_curve.shape[0]):
            for i in range(3):
                loaded |= loads.moments[m, node, i] != 0.0
        if not loaded:
            continue
        for m in range(loads.moment_curve.shape[0]):
            c = factor(model.curves, loads.moment_curve[m], t)
            for i in range(3):
                moment[i] += c * loads.moments[m, node, i]
        block[:] = 0.0
        for j in range(2):
            for sign in (1.0, -1.0):
                copy_into(shape.d[node], d[0])
                copy_into(shape.e1[node], e1[0])
                turn = sign * step_r
                rotate_director(d[0], e1[0], turn if j == 0 else 0.0, turn if j == 1 else 0.0)
                # the moment's director-conjugate force M x d
                g[0, 0] = moment[1] * d[0, 2] - moment[2] * d[0, 1]
                g[0, 1] = moment[2] * d[0, 0] - moment[0] * d[0, 2]
                g[0, 2] = moment[0] * d[0, 1] - moment[1] * d[0, 0]
                rotational_at(0, g, d, e1, fr)
                for r in range(2):
                    block[r, j] -= sign * fr[0, r] / (2.0 * step_r)
        e, a = divmod(body.slots[body.node_slots[node]], 9)
        for r in range(2):
            for c2 in range(2):
                k[e, 5 * a + 3 + r, 5 * a + 3 + c2] += block[r, c2]
