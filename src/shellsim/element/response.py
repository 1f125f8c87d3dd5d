"""Stresses and nodal forces of an element group, in visible phases: geometry and strain
at every point, the assumed strains, the stress update, the tying adjoints, the forces.

Integration: nq in-plane Gauss points (3 x 3) times nt points through the thickness; the
membrane tying points (rows nq.. of the rule) get geometry, strains and effective
stresses too. Work arrays carry the group's lanes last (G, see
:mod:`shellsim.element.lanes`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from .assumed_strain import membrane_tying_stresses, project_volumetric, shear_tying_stresses, tie_membrane, tie_shear
from ..tensor3 import product
from .kinematics import (add_forces, almansi, field_gradient, global_stress, gradient_vectors, lamina_strain,
                         point_geometry, symmetric_part)
from ..lanes import LANES
from .stress_update import INCREMENTAL, LINEAR, TOTAL, constant_tensor, convected_layer, hyperelastic_layers


class GroupScratch(NamedTuple):
    """Work arrays of :func:`group_response`, G = LANES, npts points, nt layers, nq Gauss
    points, nb volumetric fields.

    The group: members (G,) element numbers; xe, de, ue, ve (9, 3, G) positions,
    directors and the field's increments, he (9, G) fibre lengths; jac0 (npts, nt, 3, 3, G)
    inverse initial Jacobians; stress, state_stress (nq, nt, 5, G) lamina stresses (the
    response's, and the state's for the initial-stress stiffness); stretch (nq, G) normal
    stretches; fe, ge (9, 3, G) the nodal forces.
    At one point (3, 3, G): jac, F, eg, v, plane, glob, local, sg; gN, gM (9, 3, G);
    s5 (5, G); cov, delta (3, G); det (G,); ones (G,) of 1.0.
    At every point (npts, nt, ...): Q, jinv_all (3, 3, G) lamina frames and inverse
    Jacobians, G (2, 3, G) tangents g_r, g_s, A (2, 2, G) their lamina components,
    DV (G) volumes, EPS (5, G) lamina strains, cov_shear and TS (2, G) covariant shears and
    their tying-point stresses; cbar, T (npts, 3, G) membrane means and tying weights.
    At the Gauss points (nq, nt, ...): SW (3, G) volume-weighted in-plane stresses, FP, LP
    (3, 3, G) deformation and field gradients, EPS0 (5, G) strains before the tying;
    Bab (nq, 3, G).
    The stress update (:mod:`shellsim.element.stress_update`): axes0 (nq, nt, 3, 3, G)
    initial material frames (Technique 1), M (11, 3, 3, G), Emean (3, 3, G), pressure,
    volume, normal (G,). Mb (nb, nb), rhs (nb,) of the projection.
    """

    members: np.ndarray
    xe: np.ndarray
    de: np.ndarray
    ue: np.ndarray
    ve: np.ndarray
    he: np.ndarray
    jac0: np.ndarray
    stress: np.ndarray
    state_stress: np.ndarray
    stretch: np.ndarray
    fe: np.ndarray
    ge: np.ndarray
    jac: np.ndarray
    F: np.ndarray
    eg: np.ndarray
    v: np.ndarray
    plane: np.ndarray
    glob: np.ndarray
    local: np.ndarray
    sg: np.ndarray
    gN: np.ndarray
    gM: np.ndarray
    s5: np.ndarray
    cov: np.ndarray
    delta: np.ndarray
    det: np.ndarray
    ones: np.ndarray
    Q: np.ndarray
    jinv_all: np.ndarray
    G: np.ndarray
    A: np.ndarray
    DV: np.ndarray
    EPS: np.ndarray
    cov_shear: np.ndarray
    TS: np.ndarray
    cbar: np.ndarray
    T: np.ndarray
    SW: np.ndarray
    FP: np.ndarray
    LP: np.ndarray
    EPS0: np.ndarray
    Bab: np.ndarray
    axes0: np.ndarray
    M: np.ndarray
    Emean: np.ndarray
    pressure: np.ndarray
    volume: np.ndarray
    normal: np.ndarray
    Mb: np.ndarray
    rhs: np.ndarray


@njit(cache=True, error_model="numpy")
def group_scratch(npts, nt, nq, nb):
    """A :class:`GroupScratch`."""
    g = LANES
    return GroupScratch(
        members=np.zeros(g, dtype=np.int64), xe=np.empty((9, 3, g)), de=np.empty((9, 3, g)), ue=np.zeros((9, 3, g)),
        ve=np.zeros((9, 3, g)), he=np.empty((9, g)), jac0=np.empty((npts, nt, 3, 3, g)), stress=np.zeros((nq, nt, 5, g)),
        state_stress=np.zeros((nq, nt, 5, g)), stretch=np.ones((nq, g)), fe=np.empty((9, 3, g)), ge=np.empty((9, 3, g)),
        jac=np.empty((3, 3, g)), F=np.empty((3, 3, g)), eg=np.empty((3, 3, g)), v=np.empty((3, 3, g)),
        plane=np.zeros((3, 3, g)), glob=np.empty((3, 3, g)), local=np.empty((3, 3, g)), sg=np.empty((3, 3, g)),
        gN=np.empty((9, 3, g)), gM=np.empty((9, 3, g)), s5=np.empty((5, g)), cov=np.empty((3, g)), delta=np.empty((3, g)),
        det=np.empty(g), ones=np.ones(g),
        Q=np.empty((npts, nt, 3, 3, g)), jinv_all=np.empty((npts, nt, 3, 3, g)), G=np.empty((npts, nt, 2, 3, g)),
        A=np.empty((npts, nt, 2, 2, g)), DV=np.empty((npts, nt, g)), EPS=np.empty((npts, nt, 5, g)),
        cov_shear=np.empty((npts, nt, 2, g)), TS=np.empty((npts, nt, 2, g)), cbar=np.empty((npts, 3, g)),
        T=np.empty((npts, 3, g)), SW=np.empty((nq, nt, 3, g)), FP=np.empty((nq, nt, 3, 3, g)),
        LP=np.empty((nq, nt, 3, 3, g)), EPS0=np.empty((nq, nt, 5, g)), Bab=np.empty((nq, 3, g)),
        axes0=np.empty((nq, nt, 3, 3, g)), M=np.empty((11, 3, 3, g)), Emean=np.empty((3, 3, g)), pressure=np.empty(g),
        volume=np.empty(g), normal=np.empty(g), Mb=np.empty((nb, nb)), rhs=np.empty(nb))


@njit(cache=True, error_model="numpy")
def group_response(mode, rule, material, work, count):
    """Stresses work.stress and nodal forces work.fe, work.ge (9, 3, G) of the group gathered in
    ``work``, whose first ``count`` lanes hold elements of their own, with assumed
    membrane and shear strains (:mod:`shellsim.element.assumed_strain`).

    mode (:mod:`shellsim.element.stress_update`): TOTAL, stress from the total Almansi
    strain; INCREMENTAL, work.stress plus C~ times the strain increment of the field
    (ue, ve); LINEAR, the material stiffness product: the strain of the field (ue, ve),
    the tangent times it, plus the initial-stress stiffness of work.state_stress (the
    critical step of a stretched membrane is set by both).

    Constitutive law (``material``, :class:`shellsim.bundles.Material`): the law LINEAR
    uses the reduced matrix C (5, 5); a hyperelastic law (Technique 1, TOTAL and LINEAR
    modes) its parameters and the members' initial material frames (work.axes0). Techniques 2 and 3
    (law LINEAR, INCREMENTAL) add C times the step's strain increment to the stresses
    kept in the lamina frame, turn them with the material's spin relative to that frame,
    and (2) push them forward with the step's stretch. work.stretch (nq, G): the normal
    stretch of the through-thickness mean strain at each point, from zero normal stress
    (hyperelastic TOTAL), or 1 + the step's mean normal strain increment (Techniques 2
    and 3); else left alone. ``rule``: :class:`shellsim.bundles.Rule`.
    """
    N, dNr, dNs, wq, tz, wt = rule.N, rule.dNr, rule.dNs, rule.wq, rule.tz, rule.wt
    hyper = material.technique == 1
    # Techniques 2 and 3: stresses accumulated from strain increments, turned and stretched
    convected = mode == INCREMENTAL and material.technique >= 2
    # the field's (or the step's) gradient serves the initial-stress stiffness (LINEAR) and
    # the spin correction of Techniques 2 and 3
    keep_gradient = mode == LINEAR or convected
    nq, npts, nt = wq.shape[0], N.shape[0], tz.shape[0]
    stress, stretch, he, jac, F, eg, v, det = work.stress, work.stretch, work.he, work.jac, work.F, work.eg, work.v, work.det
    Q, jinv_all, G, DV, EPS, SW = work.Q, work.jinv_all, work.G, work.DV, work.EPS, work.SW
    share = rule.share
    # 1. geometry and strain at every point
    for p in range(npts):
        for k in range(nt):
            point_geometry(work.xe, work.de, he, N[p], dNr[p], dNs[p], tz[k], jac, jinv_all[p, k], Q[p, k], det)
            for lane in range(LANES):
                for i in range(3):
                    G[p, k, 0, i, lane] = jac[i, 0, lane]
                    G[p, k, 1, i, lane] = jac[i, 1, lane]
                DV[p, k, lane] = det[lane] * wq[p] * wt[k] if p < nq else 0.0
            if mode == TOTAL or (hyper and p < nq):
                product(jac, work.jac0[p, k], F)
                if hyper and p < nq:
                    work.FP[p, k] = F
            if mode == TOTAL:
                almansi(F, eg, v, det)
            else:
                gradient_vectors(jinv_all[p, k], he, N[p], dNr[p], dNs[p], tz[k], work.gN, work.gM)
                field_gradient(work.ue, work.ve, work.gN, work.gM, F)
                symmetric_part(F, eg)
                if keep_gradient and p < nq:
                    work.LP[p, k] = F
            lamina_strain(eg, Q[p, k], EPS[p, k], v)
            if hyper and p < nq:
                work.EPS0[p, k] = EPS[p, k]
    # 2. assumed strains
    tie_membrane(rule, work, nq, nt)
    tie_shear(rule, work, nq, nt)
    nb = rule.vol_basis.shape[1]
    if nb:
        project_volumetric(EPS, DV, rule.vol_basis, nq, nt, False, count, work.Mb, work.rhs)
    # 3. stresses at the Gauss points
    for p in range(nq):
        if hyper:
            hyperelastic_layers(mode, material, work, stress, p, share)
        else:
            if convected:
                stretch[p, :] = 1.0
            for k in range(nt):
                constant_tensor(material.C, EPS[p, k], stress[p, k], mode == INCREMENTAL)
                if convected:
                    convected_layer(material, work, stress, p, k, share[k], stretch)
        for k in range(nt):
            for i in range(3):
                for lane in range(LANES):
                    SW[p, k, i, lane] = stress[p, k, i, lane] * DV[p, k, lane]
    # 4. the effective stresses of the assumed strains
    if nb:
        project_volumetric(SW, DV, rule.vol_basis, nq, nt, True, count, work.Mb, work.rhs)
    membrane_tying_stresses(rule, work, nq, nt)
    shear_tying_stresses(rule, work, stress, nq, nt)
    # 5. nodal forces: the direct stresses at the Gauss points, the tied shears and
    # membrane weights at every point
    fe, ge = work.fe, work.ge
    _point_forces(rule, work, nq, fe, ge)
    if mode == LINEAR:
        # initial-stress stiffness: the current stress sigma acting through the field's
        # gradient L, f_a += L sigma gN_a dv (and gM_a for the director)
        for p in range(nq):
            for k in range(nt):
                global_stress(work.state_stress[p, k], Q[p, k], work.sg)
                product(work.LP[p, k], work.sg, eg)
                gradient_vectors(jinv_all[p, k], he, N[p], dNr[p], dNs[p], tz[k], work.gN, work.gM)
                add_forces(eg, work.gN, work.gM, DV[p, k], fe, ge)


@njit(cache=True, error_model="numpy")
def _point_forces(rule, work, nq, fe, ge):
    """fe, ge (9, 3, G) = the virtual work of the stresses at every point: the direct
    in-plane stresses work.SW at the Gauss points, the tied shears work.TS and the
    membrane tying weights work.T ((w_k / W) sum_ab T_ab sym(g_a (x) g_b), w_k / W =
    rule.share[k])."""
    N, dNr, dNs, tz, share = rule.N, rule.dNr, rule.dNs, rule.tz, rule.share
    SW, TS, T, A, G, s5, sg = work.SW, work.TS, work.T, work.A, work.G, work.s5, work.sg
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
            global_stress(s5, work.Q[x, k], sg)
            g = G[x, k]
            for i in range(3):
                for j in range(3):
                    for lane in range(LANES):
                        sg[i, j, lane] += share[k] * (T[x, 0, lane] * g[0, i, lane] * g[0, j, lane]
                                                      + T[x, 1, lane] * g[1, i, lane] * g[1, j, lane]
                                                      + 0.5 * T[x, 2, lane] * (g[0, i, lane] * g[1, j, lane]
                                                                               + g[1, i, lane] * g[0, j, lane]))
            gradient_vectors(work.jinv_all[x, k], work.he, N[x], dNr[x], dNs[x], tz[k], work.gN, work.gM)
            add_forces(sg, work.gN, work.gM, work.ones, fe, ge)
