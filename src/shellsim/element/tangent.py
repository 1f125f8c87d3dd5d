"""Each element's tangent stiffness: the derivative of its nodal forces with respect to its
45 DOFs, by central differences of the compiled element response, the lanes of a group
holding copies of one element each moved by one DOF.

DOFs of an element, in the order of its nodes, five per node: the translations along x,
y and z, then the rotations theta1, theta2 of :func:`shellsim.element.frames.rotate_director`
in the node's fibre frame. The forces are the same five per node, the rotational ones in
the (moved) fibre frame, so the derivative holds the frame's turning too. Differences of
a step h have truncation errors of order h^2 and round-off of order eps / h: on a
strongly strained element steps of 1e-5 of its size (and 1e-5 rad) left 2e-6 relative,
1e-6 left 1e-8 (:mod:`shellsim.solver.equilibrium` chooses them).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .frames import cross, rotate_director
from ..lanes import LANES
from .groups import gather_element_values, gather_nodal_scalars
from .response import group_arrays, group_response
from .steps import steps_of

#: DOFs of an element: 9 nodes x (3 translations, 2 rotations).
ELEMENT_DOFS = 45
#: Lanes per element: each DOF moved forward and back.
_MOVES = 2 * ELEMENT_DOFS
#: Group evaluations per element tangent.
BATCHES = -(-_MOVES // LANES)


@njit(cache=True, error_model="numpy")
def moved_node(x, d, e1, move, differences, moved):
    """moved = (xm, dm, e1m) (3,): the position, director and fibre axis of a node (x, d,
    e1 (3,)) moved by DOF ``move // 2`` of its five (forward when even): +-step_u along an
    axis or +-step_r about a fibre axis, differences = (step_u, step_r). Returns the
    signed step."""
    step_u, step_r = differences
    xm, dm, e1m = moved
    slot, sign = move // 2, 1.0 if move % 2 == 0 else -1.0
    xm[:] = x
    dm[:] = d
    e1m[:] = e1
    if slot < 3:
        xm[slot] += sign * step_u
        return sign * step_u
    rotate_director(dm, e1m, sign * step_r if slot == 3 else 0.0, sign * step_r if slot == 4 else 0.0)
    return sign * step_r


@njit(cache=True, parallel=True, error_model="numpy")
def element_tangents(rule, body, material, shape, converged, differences, k):
    """k (ne, 45, 45): each element's tangent stiffness, the derivative of its internal nodal
    forces with respect to its DOFs (both in the module's order).

    shape: the current :class:`~shellsim.bundles.Shape`; converged: (dx, dd, stress), the
    increments (n, 3) of position and director since the last converged state and the
    stress (ne, nq, nt, 5) there (read by an incremental material only); differences:
    (step_u [length], step_r [rad]), the difference steps. The fibre lengths are held
    (their update follows the deformation one evaluation behind).
    """
    ne = body.conn.shape[0]
    dx, dd, stress = converged
    step_u, step_r = differences
    path = steps_of(material, np.bool_(False))
    for e in prange(ne):
        # e as int64: the parallel loop's own index is unsigned, and typed so it would
        # compile _element_tangent a second time
        _element_tangent(np.int64(e), path, rule, body, material, shape, dx, dd, stress, step_u, step_r, k[e])


@njit(cache=True, error_model="numpy")
def _element_tangent(e, path, rule, body, material, shape, dx, dd, stress, step_u, step_r, ke):  # noqa: PLR0913 (prange-bound)
    """ke (45, 45) of element e; arguments as :func:`element_tangents`, ``path`` its
    :class:`~shellsim.element.steps.Steps`. Every lane holds the element as it is; each
    batch moves one node of each lane and puts it back after."""
    conn = body.conn
    nq, nt = rule.wq.shape[0], rule.tz.shape[0]
    group, points, scratch = group_arrays(rule.N.shape[0], nt, nq, rule.vol_basis.shape[1])
    members = group.members
    members[:] = e
    gather_nodal_scalars(conn, members, body.h0 if path.hyperelastic else shape.h, group.he)
    gather_element_values(body.jac0_inv, members, group.jac0)
    if path.hyperelastic:
        gather_element_values(material.axes0, members, group.axes0)
    if path.incremental:
        gather_element_values(stress, members, group.stress)
        base_stress = group.stress.copy()
    frames = np.empty((9, 2, 3, LANES))  # each lane's fibre axes e1, e2 at its nodes
    for a in range(9):
        node = conn[e, a]
        _place_node(group, frames, a, -1, (shape.x[node], shape.d[node], shape.e1[node]), (dx[node], dd[node]))
    xm, dm, e1m = np.empty(3), np.empty(3), np.empty(3)
    moves = np.zeros(LANES)
    ke[:] = 0.0
    for batch in range(BATCHES):
        for lane in range(LANES):
            move = min(batch * LANES + lane, _MOVES - 1)
            node = conn[e, move // 10]
            moves[lane] = moved_node(shape.x[node], shape.d[node], shape.e1[node], move % 10, (step_u, step_r),
                                     (xm, dm, e1m))
            _place_node(group, frames, move // 10, lane, (xm, dm, e1m),
                        (dx[node] + xm - shape.x[node], dd[node] + dm - shape.d[node]))
        if path.incremental:
            group.stress[:] = base_stress
        # every lane; counted at run time, as the element loop counts, so that one compiled
        # group_response serves both (the literal LANES would compile a second)
        group_response(path, rule, material, group, points, scratch, members.shape[0])
        for lane in range(LANES):
            move = min(batch * LANES + lane, _MOVES - 1)
            if batch * LANES + lane < _MOVES:
                column = move // 2
                weight = 1.0 / (2.0 * moves[lane])  # + f / 2h forward, - f / 2h back (moves[lane] = -h)
                for a in range(9):
                    for i in range(3):
                        ke[5 * a + i, column] += weight * group.fe[a, i, lane]
                    for j in range(2):  # in the moved frames
                        ke[5 * a + 3 + j, column] -= weight * (frames[a, j, 0, lane] * group.ge[a, 0, lane]
                                                               + frames[a, j, 1, lane] * group.ge[a, 1, lane]
                                                               + frames[a, j, 2, lane] * group.ge[a, 2, lane])
            node = conn[e, move // 10]
            _place_node(group, frames, move // 10, lane, (shape.x[node], shape.d[node], shape.e1[node]),
                        (dx[node], dd[node]))


@njit(cache=True, inline="always")
def _place_node(group, frames, a, lane, node, increments):
    """Node a of lane ``lane`` (every lane when -1) at node = (x, d, e1) (3,): position,
    director and fibre axis, with increments = (u, v) (3,) from the converged state."""
    x, d, e1 = node
    u, v = increments
    first, stop = (0, LANES) if lane < 0 else (lane, lane + 1)
    e2 = cross(d, e1)
    for k in range(first, stop):
        for i in range(3):
            group.xe[a, i, k] = x[i]
            group.de[a, i, k] = d[i]
            group.ue[a, i, k] = u[i]
            group.ve[a, i, k] = v[i]
            frames[a, 0, i, k] = e1[i]
            frames[a, 1, i, k] = e2[i]
