"""Stresses and nodal forces of an element group, in visible phases: geometry and strain
at every point, the assumed strains, the stress update, the tying adjoints, the forces.
The phases hand on what they compute in the group's work arrays
(:mod:`shellsim.element.work_arrays`), viewed once at the start with their trailing
lengths known to the compiled code, so that the lane loops vectorise.

Integration: nq in-plane Gauss points (3 x 3) times nt points through the thickness; the
membrane tying points (rows nq.. of the rule) get geometry, strains and effective
stresses too. Work arrays carry the group's lanes last (G, :data:`shellsim.lanes.LANES`).
"""

from __future__ import annotations

import numpy as np
from numba import njit, typeof, types

from .assumed_strain import membrane_tying_stresses, project_volumetric, shear_tying_stresses, tie_membrane, tie_shear
from ..tensor3 import product
from .kinematics import (add_forces, almansi, field_gradient, global_stress, gradient_vectors, lamina_strain,
                         point_geometry, symmetric_part)
from ..array_copy import copy_into
from ..compiled_call import held_by_address
from ..lanes import LANES
from .steps import steps_of
from .work_arrays import fixed_lanes, group_arrays
from .stress_update import constant_tensor, convected_layer, hyperelastic_layers


@njit(cache=True, error_model="numpy")
def group_response(steps, rule, material, group, points, scratch, count):
    """Stresses group.stress and nodal forces group.fe, group.ge (9, 3, G) of the group
    gathered in ``group``, whose first ``count`` lanes hold elements of their own, with
    assumed membrane and shear strains (:mod:`shellsim.element.assumed_strain`).

    ``steps`` (:class:`shellsim.element.steps.Steps`): total, stress from the total
    Almansi strain; incremental, group.stress plus C~ times the strain increment of the
    field (ue, ve); product, the material stiffness product: the strain of the field
    (ue, ve), the tangent times it, plus the initial-stress stiffness of
    group.state_stress (the critical step of a stretched membrane is set by both).

    Constitutive law (``material``, :class:`shellsim.bundles.Material`): the small-strain
    and convected paths use the reduced matrix C (5, 5); a hyperelastic law (Technique 1)
    its parameters and the members' initial material frames (group.axes0). Techniques 2
    and 3 (convected) add C times the step's strain increment to the stresses kept in the
    lamina frame, turn them with the material's spin relative to that frame, and (2) push
    them forward with the step's stretch. group.stretch (nq, G): the normal stretch of the
    through-thickness mean strain at each point, from zero normal stress (hyperelastic
    response), or 1 + the step's mean normal strain increment (convected); else left
    alone. ``rule``: :class:`shellsim.bundles.Rule`.
    """
    nq, nt = rule.wq.shape[0], rule.tz.shape[0]
    group, points, scratch = fixed_lanes(group, points, scratch)
    # 1. geometry and strain at every point
    _strains(steps, rule, group, points, scratch)
    # 2. assumed strains
    tie_membrane(rule, points, scratch, nq, nt)
    tie_shear(rule, points, scratch, nq, nt)
    nb = rule.vol_basis.shape[1]
    if nb:  # the direction as a run-time boolean: a literal one would compile the projection twice
        project_volumetric(points.EPS, points.DV, rule.vol_basis, np.bool_(False), count, scratch)
    # 3. stresses at the Gauss points
    _stresses(steps, rule, material, group, points, scratch)
    # 4. the effective stresses of the assumed strains
    if nb:
        project_volumetric(points.SW, points.DV, rule.vol_basis, np.bool_(True), count, scratch)
    membrane_tying_stresses(rule, points, scratch, nq, nt)
    shear_tying_stresses(rule, points, group.stress, scratch, nq, nt)
    # 5. nodal forces: the direct stresses at the Gauss points, the tied shears and
    # membrane weights at every point
    _point_forces(rule, group, points, scratch, nq)
    if steps.product:
        _initial_stress_forces(rule, group, points, scratch, nq)


def response_by_address(rule, material):
    """:func:`group_response` for the element loops of a model with this ``rule`` and
    ``material`` (:class:`shellsim.bundles.Rule`, :class:`~shellsim.bundles.Material`),
    held for calls through its address (:func:`shellsim.compiled_call.held_by_address`:
    the loops call ``response[0](...)``). Each loop that named it would link the whole
    element path into its own code and optimise and emit it again: seconds of a first run
    for each of the static entry, the time loop and the parallel loop's layers. Compiled
    (or loaded) here at once; a :class:`~shellsim.solver.simulation.Simulation` holds its
    own, compiled by a second process on an empty cache (:mod:`shellsim.compile_beside`)."""
    return held_by_address(group_response, response_signature(rule, material))


def response_signature(rule, material):
    """The numba signature of :func:`group_response` (and of :func:`no_response`) for a
    model with this ``rule`` and ``material``. The arrays and decisions are made by the
    Python versions of :func:`group_arrays` and ``steps_of``, of the same types: compiling
    them first would hold up a second process compiling the response by about 1.5 s of a
    first run (:mod:`shellsim.compile_beside`)."""
    nq, nt = rule.wq.shape[0], rule.tz.shape[0]
    arrays = group_arrays.py_func(rule.N.shape[0], nt, nq, rule.vol_basis.shape[1])
    steps = steps_of.py_func(material, np.bool_(False))  # the product's are of the same type
    return types.none(typeof(steps), typeof(rule), typeof(material), *(typeof(a) for a in arrays), types.int64)


@njit(cache=True)
def no_response(steps, rule, material, group, points, scratch, count):
    """A stand-in of :func:`group_response`'s type that computes nothing: no nodal forces
    (group.fe, group.ge zero), the stresses and stretches left as they are. The loops
    compile around it while the response compiles in a second process
    (:mod:`shellsim.compile_beside`)."""
    group.fe[:] = 0.0
    group.ge[:] = 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _strains(steps, rule, group, points, scratch):
    """Geometry and lamina strains points.EPS at every point and layer: from the total
    deformation (steps.total) or from the field's gradient; keeps the deformation
    gradients points.FP and the untied strains points.EPS0 at the Gauss points
    (hyperelastic), the field's gradients points.LP (steps.keep_gradient)."""
    N, dNr, dNs, wq, tz, wt = rule.N, rule.dNr, rule.dNs, rule.wq, rule.tz, rule.wt
    nq, npts, nt = wq.shape[0], N.shape[0], tz.shape[0]
    he, jac, F, eg, v, det = group.he, scratch.jac, scratch.F, scratch.eg, scratch.v, scratch.det
    Q, jinv_all, G, DV, EPS = points.Q, points.jinv_all, points.G, points.DV, points.EPS
    for p in range(npts):
        gauss = p < nq
        for k in range(nt):
            point_geometry((group.xe, group.de, he), (N[p], dNr[p], dNs[p]), tz[k], (jac, jinv_all[p, k], Q[p, k], det))
            for lane in range(LANES):
                for i in range(3):
                    G[p, k, 0, i, lane] = jac[i, 0, lane]
                    G[p, k, 1, i, lane] = jac[i, 1, lane]
                DV[p, k, lane] = det[lane] * wq[p] * wt[k] if gauss else 0.0
            if steps.total or (steps.hyperelastic and gauss):
                product(jac, group.jac0[p, k], F)
                if steps.hyperelastic and gauss:
                    copy_into(F, points.FP[p, k])
            if steps.total:
                almansi(F, eg, v, det)
            else:
                gradient_vectors(jinv_all[p, k], he, N[p], dNr[p], dNs[p], tz[k], scratch.gN, scratch.gM)
                field_gradient(group.ue, group.ve, scratch.gN, scratch.gM, F)
                symmetric_part(F, eg)
                if steps.keep_gradient and gauss:
                    copy_into(F, points.LP[p, k])
            lamina_strain(eg, Q[p, k], EPS[p, k], v)
            if steps.hyperelastic and gauss:
                copy_into(EPS[p, k], points.EPS0[p, k])


@njit(cache=True, error_model="numpy", inline="always")
def _stresses(steps, rule, material, group, points, scratch):
    """Lamina stresses group.stress at the Gauss points by the material's path, and their
    volume-weighted in-plane parts points.SW."""
    nq, nt, share = rule.wq.shape[0], rule.tz.shape[0], rule.share
    stress, SW, DV = group.stress, points.SW, points.DV
    C = material.C[group.part[0]]  # the group's part's, taken once
    for p in range(nq):
        if steps.hyperelastic:
            hyperelastic_layers(steps.product, material, group, points, scratch, p, share)
        else:
            if steps.convected:
                group.stretch[p, :] = 1.0
            for k in range(nt):
                constant_tensor(C, points.EPS[p, k], stress[p, k], steps.incremental)
                if steps.convected:
                    convected_layer(material, group, points, scratch, p, k, share[k])
        for k in range(nt):
            for i in range(3):
                for lane in range(LANES):
                    SW[p, k, i, lane] = stress[p, k, i, lane] * DV[p, k, lane]


@njit(cache=True, error_model="numpy", inline="always")
def _initial_stress_forces(rule, group, points, scratch, nq):
    """The product's initial-stress stiffness: the state's stress sigma acting through the
    field's gradient L, f_a += L sigma gN_a dv (and gM_a for the director)."""
    N, dNr, dNs, tz = rule.N, rule.dNr, rule.dNs, rule.tz
    for p in range(nq):
        for k in range(tz.shape[0]):
            global_stress(group.state_stress[p, k], points.Q[p, k], scratch.sg)
            product(points.LP[p, k], scratch.sg, scratch.eg)
            gradient_vectors(points.jinv_all[p, k], group.he, N[p], dNr[p], dNs[p], tz[k], scratch.gN, scratch.gM)
            add_forces(scratch.eg, scratch.gN, scratch.gM, points.DV[p, k], group.fe, group.ge)


@njit(cache=True, error_model="numpy", inline="always")
def _point_forces(rule, group, points, scratch, nq):
    """group.fe, group.ge (9, 3, G) = the virtual work of the stresses at every point: the
    direct in-plane stresses points.SW at the Gauss points, the tied shears points.TS and
    the membrane tying weights points.T ((w_k / W) sum_ab T_ab sym(g_a (x) g_b), w_k / W =
    rule.share[k])."""
    N, dNr, dNs, tz, share = rule.N, rule.dNr, rule.dNs, rule.tz, rule.share
    SW, TS, T, A, G, s5, sg = points.SW, points.TS, points.T, points.A, points.G, scratch.s5, scratch.sg
    fe, ge = group.fe, group.ge
    fe[:] = 0.0
    ge[:] = 0.0
    for x in range(N.shape[0]):
        for k in range(tz.shape[0]):
            for i in range(3):
                for lane in range(LANES):
                    s5[i, lane] = SW[x, k, i, lane] if x < nq else 0.0
            for lane in range(LANES):
                for i in range(2):
                    s5[3 + i, lane] = TS[x, k, 0, lane] * A[x, k, 0, i, lane] + TS[x, k, 1, lane] * A[x, k, 1, i, lane]
            global_stress(s5, points.Q[x, k], sg)
            g = G[x, k]
            for i in range(3):
                for j in range(3):
                    for lane in range(LANES):
                        sg[i, j, lane] += share[k] * (T[x, 0, lane] * g[0, i, lane] * g[0, j, lane]
                                                      + T[x, 1, lane] * g[1, i, lane] * g[1, j, lane]
                                                      + 0.5 * T[x, 2, lane] * (g[0, i, lane] * g[1, j, lane]
                                                                               + g[1, i, lane] * g[0, j, lane]))
            gradient_vectors(points.jinv_all[x, k], group.he, N[x], dNr[x], dNs[x], tz[k], scratch.gN, scratch.gM)
            add_forces(sg, scratch.gN, scratch.gM, scratch.ones, fe, ge)
