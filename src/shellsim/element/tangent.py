"""Each element's tangent stiffness: the derivative of its nodal forces with respect to its
45 DOFs, by differences of the compiled element response, the lanes of a group holding
copies of one element each moved by one DOF.

DOFs of an element, in the order of its nodes, five per node: the translations along x,
y and z, then the rotations theta1, theta2 of :func:`shellsim.element.frames.rotate_director`
in the node's fibre frame. The forces are the same five per node, the rotational ones in
the (moved) fibre frame, so the derivative holds the frame's turning too.

Forward differences (the element as it is and each DOF moved forward: 46 evaluations,
3 groups) cost half of central ones (90, 6 groups). Their truncation error is of order h
and their round-off of order eps / h, so their best step is near sqrt(eps) of the size:
against central differences of step 1e-6 (which leave about 1e-8), steps of 3e-9 of the
size and 3e-9 rad left at most 5e-7 relative on a strongly strained panel of every law
(1e-8 left up to 1.6e-6 on the exponential laws, 1e-9 up to 6e-7 on a thin hemisphere).
The static solver takes the forward ones, the central ones are their check
(:mod:`shellsim.solver.equilibrium` chooses the steps).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .frames import cross, rotate_director
from ..array_copy import copy_into
from ..lanes import LANES
from .groups import gather_element_values, gather_nodal_scalars
from .work_arrays import group_arrays
from .steps import steps_of

#: DOFs of an element: 9 nodes x (3 translations, 2 rotations).
ELEMENT_DOFS = 45
#: Moves of an element's DOFs in :func:`moved_node`'s numbering: each forward and back.
_MOVES = 2 * ELEMENT_DOFS
#: Group evaluations per element tangent by forward differences (the element as it is and
#: each DOF moved forward) and by central ones (each DOF moved forward and back).
FORWARD_BATCHES, CENTRAL_BATCHES = -(-(1 + ELEMENT_DOFS) // LANES), -(-_MOVES // LANES)


@njit(cache=True, error_model="numpy")
def moved_node(x, d, e1, move, differences, moved):
    """moved = (xm, dm, e1m) (3,): the position, director and fibre axis of a node (x, d,
    e1 (3,)) moved by DOF ``move // 2`` of its five (forward when even): +-step_u along an
    axis or +-step_r about a fibre axis, differences = (step_u, step_r). Returns the
    signed step taken."""
    step_u, step_r = differences
    xm, dm, e1m = moved
    slot, sign = move // 2, 1.0 if move % 2 == 0 else -1.0
    copy_into(x, xm)
    copy_into(d, dm)
    copy_into(e1, e1m)
    if slot < 3:
        xm[slot] += sign * step_u
        # the step as the sum rounded it: far from the origin a step of 1e-9 of an
        # element's size moves it by a few ulps of its coordinate, not by the step
        return xm[slot] - x[slot]
    rotate_director(dm, e1m, sign * step_r if slot == 3 else 0.0, sign * step_r if slot == 4 else 0.0)
    return sign * step_r


# inlined into the static solver's one compiled entry (shellsim.element.static_loop), which
# the element forces share
@njit(cache=True, error_model="numpy", inline="always")
def element_tangents(response, structure, shape, converged, differences, central, elements, k):
    """k (ne, 45, 45): the tangent stiffness of elements ``elements`` = (first, last),
    first..last-1: the derivative of each one's internal nodal forces with respect to its
    DOFs (both in the module's order), by forward differences, or central ones when
    ``central``. The other elements' blocks are left as they are.

    response: :func:`shellsim.element.response.group_response` by its address
    (:func:`~shellsim.element.response.response_by_address`); structure: (rule, body,
    material) of a :class:`~shellsim.bundles.Model`; shape: the current
    :class:`~shellsim.bundles.Shape`; converged: (dx, dd, stress), the increments (n, 3)
    of position and director since the last converged state and the stress
    (ne, nq, nt, 5) there (read by an incremental material only); differences:
    (step_u [length], step_r [rad]), the difference steps. The fibre lengths are held
    (their update follows the deformation one evaluation behind).
    """
    rule, body, material = structure
    dx, dd, stress = converged
    step_u, step_r = differences
    path = steps_of(material, np.bool_(False))
    first, last = elements
    for e in range(first, last):
        _element_tangent(response, e, path, rule, body, material, shape, dx, dd, stress, step_u, step_r, central, k[e])


@njit(cache=True)
def lane_move(k, central):
    """The move of an element's k-th evaluation: ``move % 10`` in :func:`moved_node`'s
    numbering, of the element's node ``move // 10``; or -1 for the element as it is (the
    forward differences' base, and a batch's spare lanes)."""
    if central:
        return k if k < _MOVES else -1
    return 2 * (k - 1) if 1 <= k <= ELEMENT_DOFS else -1


@njit(cache=True, error_model="numpy", inline="always")
def _element_tangent(response, e, path, rule, body, material, shape, dx, dd, stress, step_u, step_r, central, ke):  # noqa: PLR0913 (flat bundles)
    """ke (45, 45) of element e; arguments as :func:`element_tangents`, ``path`` its
    :class:`~shellsim.element.steps.Steps`. Every lane holds the element as it is; each
    batch moves one node of each lane (:func:`lane_move`) and puts it back after."""
    conn = body.conn
    nq, nt = rule.wq.shape[0], rule.tz.shape[0]
    group, points, scratch = group_arrays(rule.N.shape[0], nt, nq, rule.vol_basis.shape[1])
    members = group.members
    members[:] = e
    group.part[0] = body.part[e]
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
    forces, base = np.empty(ELEMENT_DOFS), np.zeros(ELEMENT_DOFS)
    spread = 2.0 if central else 1.0  # the distance between a difference's two evaluations, in steps
    ke[:] = 0.0
    for batch in range(CENTRAL_BATCHES if central else FORWARD_BATCHES):
        for lane in range(LANES):
            move = lane_move(batch * LANES + lane, central)
            if move >= 0:
                node = conn[e, move // 10]
                moves[lane] = moved_node(shape.x[node], shape.d[node], shape.e1[node], move % 10, (step_u, step_r),
                                         (xm, dm, e1m))
                _place_node(group, frames, move // 10, lane, (xm, dm, e1m),
                            (dx[node] + xm - shape.x[node], dd[node] + dm - shape.d[node]))
        if path.incremental:
            copy_into(base_stress, group.stress)
        # every lane; counted at run time, as the response's signature takes it
        response[0](path, rule, material, group, points, scratch, members.shape[0])
        for lane in range(LANES):
            move = lane_move(batch * LANES + lane, central)
            if move < 0:
                if batch == 0 and lane == 0 and not central:  # the base, before the lanes that need it
                    _lane_forces(group, frames, lane, base)
                continue
            _lane_forces(group, frames, lane, forces)
            # (f+ - f) / h forward; f+ / 2h and -f- / 2h central (moves[lane] = -h backward)
            weight = 1.0 / (spread * moves[lane])
            for i in range(ELEMENT_DOFS):
                ke[i, move // 2] += weight * (forces[i] - base[i])
            node = conn[e, move // 10]
            _place_node(group, frames, move // 10, lane, (shape.x[node], shape.d[node], shape.e1[node]),
                        (dx[node], dd[node]))


@njit(cache=True, inline="always")
def _lane_forces(group, frames, lane, forces):
    """forces (45,): lane ``lane``'s nodal forces in the module's order, the rotational ones
    from its director forces as :func:`shellsim.element.frames.to_rotational` forms them,
    in the lane's fibre frames."""
    for a in range(9):
        for i in range(3):
            forces[5 * a + i] = group.fe[a, i, lane]
        for j in range(2):
            forces[5 * a + 3 + j] = -(frames[a, j, 0, lane] * group.ge[a, 0, lane]
                                      + frames[a, j, 1, lane] * group.ge[a, 1, lane]
                                      + frames[a, j, 2, lane] * group.ge[a, 2, lane])


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
