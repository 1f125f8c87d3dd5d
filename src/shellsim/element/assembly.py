"""The element loop: groups of elements shared out over the threads, their forces summed
at the nodes in one fixed order; internal forces in the time loop (a parallel loop) and
from Python (:class:`shellsim.element.static_loop.ElementLoop`), the stiffness product
K v from Python through the time loop's parallel loop (:class:`StiffnessProduct`).

Results are the same to the last bit for any number of threads: each group writes only
its own elements' slots of an :class:`Assembly` and of the stresses, and each node then
adds its elements' slots in ascending element order (the order of a serial loop).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import get_num_threads, njit, prange

from .frames import director_increments, rotational_at
from .groups import (gather_element_values, gather_members_shape, gather_nodal_vectors, group_count,
                     part_group_members, scatter_element_values)
from .work_arrays import group_arrays
from .steps import steps_of
from ..compiled_call import TypedCall


class Assembly(NamedTuple):
    """Per-element results before they are summed at the nodes (ne elements, n nodes):
    fe, ge (ne, 9, 3) translational and director-conjugate forces; volume, stretch (ne,)
    the element's volume and volume-weighted normal stretch (fibre-length update);
    g (n, 3) the summed director-conjugate forces; chunks: how many runs of element
    groups the threads share out (the results do not depend on it). Allocated once per
    model (:func:`assembly`)."""

    fe: np.ndarray
    ge: np.ndarray
    volume: np.ndarray
    stretch: np.ndarray
    g: np.ndarray
    chunks: int


def assembly(n_nodes: int, n_elements: int) -> Assembly:
    """An :class:`Assembly` for a mesh of that size, one run of groups per thread (fewer
    on a tiny mesh)."""
    chunks = max(1, min(group_count(n_elements), get_num_threads()))
    return Assembly(fe=np.zeros((n_elements, 9, 3)), ge=np.zeros((n_elements, 9, 3)), volume=np.zeros(n_elements),
                    stretch=np.zeros(n_elements), g=np.zeros((n_nodes, 3)), chunks=chunks)


@njit(cache=True, parallel=True, error_model="numpy")
def _all_elements(response, steps, rule, body, material, shape, ux, ud, stress, f, fr, parts):  # noqa: PLR0913 (prange-bound: flat bundles)
    """Sum the element responses into nodal forces f (n, 3) and rotational forces fr (n, 2).

    response: :func:`shellsim.element.response.group_response`, by its address
    (:func:`~shellsim.element.response.response_by_address`); steps:
    :class:`shellsim.element.steps.Steps`; ux, ud (n, 3) the field's translations and
    director increments (not total); stress (ne, nq, nt, 5) written (read too when
    incremental), or, for the product, the state's stress (read only).

    With Techniques 2 and 3 (convected), the fibre lengths are scaled each step by
    1 + the step's normal strain increment (thesis Eq 3.33); with a hyperelastic law in
    the response the initial ones by the normal stretch, h = h0 lambda_3 (thesis 3.11), one
    step behind the kinematics as in the thesis. Either factor is the element's volume
    mean, and a node takes the volume-weighted mean of its elements': averaged from the
    integration points with weights N_a dv, or N_a^2 dv, the nodal lengths of a refined
    holed sheet (Techniques 2, 3) grew a pattern inside the elements next to the hole
    that broke the run down. The stresses of a hyperelastic law are computed on the
    initial fibre lengths: J = 1 fixes the thickness strain anyway, and with the current
    ones a node-to-node difference in h tilts the layers, strains them and feeds back
    into lambda_3 (a loop no energy stands behind, which broke Test 10 down). The updated
    h moves the faces (pressure, probes), masses and volume.
    """
    groups = body.group_part.shape[0]
    chunks = parts.chunks
    # the chunks' bodies run in a function of their own: a nested bundle cannot cross into
    # a prange body, and code written inline there was compiled wrongly
    for c in prange(chunks):
        _group_run(response, c * groups // chunks, (c + 1) * groups // chunks, steps, rule, body, material, shape, ux, ud,
                   stress, parts)
    after_groups(steps, body, shape, parts, f, fr)


@njit(cache=True, nogil=True, error_model="numpy")
def _group_run(response, start, stop, steps, rule, body, material, shape, ux, ud, stress, parts):  # noqa: PLR0913 (prange-bound)
    """The responses of groups start..stop-1, as :func:`run_groups`, in a compiled layer of
    their own for the parallel loop."""
    run_groups(response, start, stop, steps, rule, body, material, shape, ux, ud, stress, parts)


# inlined into its two callers, the parallel loop's layer above and the static solver's
# one entry (shellsim.element.static_loop)
@njit(cache=True, error_model="numpy", inline="always")
def run_groups(response, start, stop, steps, rule, body, material, shape, ux, ud, stress, parts):  # noqa: PLR0913 (flat bundles)
    """The responses of groups start..stop-1 into their elements' slots of ``parts`` and
    ``stress``; arguments as :func:`_all_elements`. Element volumes and mean stretches are
    kept when the fibre lengths follow."""
    conn = body.conn
    nq, nt = rule.wq.shape[0], rule.tz.shape[0]
    group, points, scratch = group_arrays(rule.N.shape[0], nt, nq, rule.vol_basis.shape[1])
    members = group.members
    lengths = body.h0 if steps.hyperelastic else shape.h
    for g in range(start, stop):
        count = part_group_members(g, body.group_start, body.group_order, members)
        gather_members_shape(conn, (shape.x, shape.d, lengths), members, (group.xe, group.de, group.he))
        group.part[0] = body.group_part[g]
        gather_element_values(body.jac0_inv, members, group.jac0)
        if steps.hyperelastic:
            gather_element_values(material.axes0, members, group.axes0)
        if not steps.total:
            gather_nodal_vectors(conn, members, ux, group.ue)
            gather_nodal_vectors(conn, members, ud, group.ve)
        if steps.incremental:
            gather_element_values(stress, members, group.stress)
        if steps.product:
            gather_element_values(stress, members, group.state_stress)
        response[0](steps, rule, material, group, points, scratch, count)
        if not steps.product:  # the K v product's stresses are the field's, of no use after
            scatter_element_values(group.stress, members, count, stress)
        for lane in range(count):
            e = members[lane]
            for a in range(9):
                for i in range(3):
                    parts.fe[e, a, i] = group.fe[a, i, lane]
                    parts.ge[e, a, i] = group.ge[a, i, lane]
            if steps.update_lengths:
                volume = 0.0
                mean = 0.0
                for p in range(nq):
                    dv = 0.0
                    for k in range(nt):
                        dv += points.DV[p, k, lane]
                    volume += dv
                    mean += dv * group.stretch[p, lane]
                parts.volume[e] = volume
                parts.stretch[e] = mean


@njit(cache=True, error_model="numpy")
def after_groups(steps, body, shape, parts, f, fr):
    """What follows the groups' responses in ``parts``: their nodal sums f (n, 3) and fr
    (n, 2), and the fibre lengths of ``shape`` updated when ``steps`` say so."""
    _gather_at_nodes(body, parts, shape, f, fr)
    if steps.update_lengths:
        _update_fibre_lengths(body, parts, shape.h, steps.convected)


@njit(cache=True, parallel=True, error_model="numpy")
def _gather_at_nodes(body, parts, shape, f, fr):
    """The nodal sums of the element forces in ``parts`` (:class:`Assembly`), each node's
    slots in ascending order, node by node over the threads: f (n, 3) from fe, parts.g
    from ge, and from those the rotational forces fr (n, 2) on the directors of ``shape``."""
    g, fe, ge, slots, node_slots, d, e1 = parts.g, parts.fe, parts.ge, body.slots, body.node_slots, shape.d, shape.e1
    for node in prange(g.shape[0]):
        for i in range(3):
            f[node, i] = 0.0
            g[node, i] = 0.0
        for slot in range(node_slots[node], node_slots[node + 1]):
            e, a = divmod(slots[slot], 9)
            for i in range(3):
                f[node, i] += fe[e, a, i]
                g[node, i] += ge[e, a, i]
        rotational_at(node, g, d, e1, fr)


@njit(cache=True, parallel=True, error_model="numpy")
def _update_fibre_lengths(body, parts, h, incremental):
    """h (n,) = (h, incremental; else h0) x the volume-weighted mean of the normal
    stretches of the node's elements (``parts``), summed in ascending element order."""
    slots, node_slots, h0, stretch, volume = body.slots, body.node_slots, body.h0, parts.stretch, parts.volume
    for node in prange(h.shape[0]):
        weighted = 0.0
        weights = 0.0
        for slot in range(node_slots[node], node_slots[node + 1]):
            e = slots[slot] // 9
            weighted += stretch[e]
            weights += volume[e]
        if weights > 0.0:
            h[node] = (h[node] if incremental else h0[node]) * weighted / weights


# inlined into the time step (shellsim.solver.explicit.forces): a compiled layer of its own
# would only pass its arguments on
@njit(cache=True, error_model="numpy", inline="always")
def internal_forces(response, structure, shape, dx, dd, stress, f, fr, parts):  # noqa: PLR0913 (flat bundles)
    """Internal forces of all elements at the current configuration, in the time loop
    (from Python: :meth:`shellsim.element.static_loop.ElementLoop.forces`, the same in every bit).

    Parameters
    ----------
    response : :func:`shellsim.element.response.group_response` by its address
        (:func:`~shellsim.element.response.response_by_address`).
    structure : (rule, body, material) of a :class:`shellsim.bundles.Model` (its
        ``structure``; the material's path, :class:`~shellsim.bundles.Material`, says how.
        Not the model: its type changes with the load kinds a scene has, and this would
        compile once for each). In the total formulation the stress follows
        from the total deformation (Almansi strain, thesis Eq 3.1 and 3.22); in the
        incremental one (``material.incremental``) the stress in the lamina frame gains
        C~ times the strain increment of the last step (Eq 3.2).
    shape : :class:`~shellsim.bundles.Shape`, the current configuration; its fibre lengths
        h are updated in place when the material asks (see :func:`_all_elements`).
    dx, dd : (n, 3) last step's mid-surface and director increments (incremental only).
    stress : (ne, nq, nt, 5) lamina Cauchy stress, written (and read when incremental).
    f : (n, 3) translational forces, fr : (n, 2) rotational forces, both overwritten.
    parts : :class:`Assembly` of the mesh (scratch).
    """
    # a run-time boolean, as the response's signature takes it (a constant would type as a
    # literal)
    rule, body, material = structure
    _all_elements(response, steps_of(material, np.bool_(False)), rule, body, material, shape, dx, dd, stress, f, fr, parts)


class StiffnessProduct:
    """Tangent stiffness times a DOF vector, K v, without forming K: the material part
    K_L (thesis Eq 3.37; with a hyperelastic law its tangent at the current state,
    Eq 3.26) plus the initial-stress part of the current stress (ne, nq, nt, 5), which the
    thesis leaves out but a membrane stretched to large strain needs (Test 8: the step
    from K_L alone was too long on refined meshes).

    Called from Python (the critical step's estimates call it thousands of times): the
    time loop's own parallel loop, :func:`_all_elements`, with the product's ``Steps``: a
    compiled function of its own around that loop would compile the loop once more. Each
    call keeps the argument types of its first; ``response`` is the element response by
    its address (:func:`shellsim.element.response.response_by_address`).
    """

    def __init__(self, response):
        self._steps, self._turn = TypedCall(steps_of), TypedCall(director_increments)
        self._elements, self._response = TypedCall(_all_elements), response

    def __call__(self, structure, shape, stress, vu, vr, f, fr, parts) -> None:
        """vu (n, 3) translational and vr (n, 2) rotational components of v; writes f
        (n, 3), fr (n, 2). Other arguments as :func:`internal_forces` (``parts`` may be the
        time loop's: it is scratch between steps)."""
        vd = np.empty((len(shape.x), 3))
        self._turn(vr, shape.d, shape.e1, vd)
        rule, body, material = structure
        self._elements(self._response, self._steps(material, np.bool_(True)), rule, body, material, shape, vu, vd,
                       stress, f, fr, parts)
