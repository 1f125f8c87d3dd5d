"""Element kernels of the 9-node continuum-based shell, compiled with numba.

Kinematics (thesis Eq 3.3): y(r, s, t) = sum_a N_a (x_a + t h_a/2 d_a), with mid-surface
nodes x_a, unit directors d_a and fibre lengths h_a. A director moves by
delta d_a = -theta1 e1f_a - theta2 e2f_a (thesis Eq 2.62), so each node has 5 DOF.

Strain-displacement, done once and consistently instead of copying Eqs 3.18-3.19 (whose
rotation columns swap e1f and e2f between the two equations): at an integration point, a
virtual field changes the displacement gradient by

    delta L = sum_a delta u_a (x) gN_a + delta d_a (x) gM_a,
    gN_a = J^-T (dN_a/dr, dN_a/ds, 0),  gM_a = h_a/2 J^-T (t dN_a/dr, t dN_a/ds, N_a),

J = dy/d(r, s, t) the current Jacobian (columns). The lamina strains of Eq 3.20 are the
components of sym(q delta L q^T), q the lamina frame; the thesis' B~_L^l is exactly this
map. So B^T sigma needs no B: with sigma_g = q^T sigma^l q (global Cauchy stress),
f_a = sigma_g gN_a dv (translations) and g_a = sigma_g gM_a dv (conjugate to the director),
whose rotational components are -e1f.g_a and -e2f.g_a. The same two helpers give the
material stiffness product K v of Eq 3.37 (strain from v, stress by C~, force).

Integration: n_q in-plane Gauss points (3 x 3) times n_t through the thickness.
Array layout: element axis first; (ne, n_q, n_t, ...) for point data.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import get_num_threads, njit, prange

from ..materials import hyperelastic
from ..tensor3 import congruence, det3
from .frames import director_increments, lamina_frame, to_rotational


@njit(cache=True, error_model="numpy")
def _point_geometry(xe, de, he, N, dNr, dNs, t, jac, jinv, q, gN, gM):
    """Current Jacobian, its inverse, lamina frame and the gradient vectors at one point.

    xe, de (9, 3); he (9,); N, dNr, dNs (9,) at the point; t the thickness coordinate.
    Writes jac, jinv, q (3, 3) and gN, gM (9, 3). Returns det J.
    """
    for i in range(3):
        jac[i, 0] = 0.0
        jac[i, 1] = 0.0
        jac[i, 2] = 0.0
    for a in range(9):
        half = 0.5 * he[a]
        for i in range(3):
            pos = xe[a, i] + t * half * de[a, i]
            jac[i, 0] += dNr[a] * pos
            jac[i, 1] += dNs[a] * pos
            jac[i, 2] += N[a] * half * de[a, i]
    det = det3(jac)
    jinv[0, 0] = (jac[1, 1] * jac[2, 2] - jac[1, 2] * jac[2, 1]) / det
    jinv[0, 1] = (jac[0, 2] * jac[2, 1] - jac[0, 1] * jac[2, 2]) / det
    jinv[0, 2] = (jac[0, 1] * jac[1, 2] - jac[0, 2] * jac[1, 1]) / det
    jinv[1, 0] = (jac[1, 2] * jac[2, 0] - jac[1, 0] * jac[2, 2]) / det
    jinv[1, 1] = (jac[0, 0] * jac[2, 2] - jac[0, 2] * jac[2, 0]) / det
    jinv[1, 2] = (jac[0, 2] * jac[1, 0] - jac[0, 0] * jac[1, 2]) / det
    jinv[2, 0] = (jac[1, 0] * jac[2, 1] - jac[1, 1] * jac[2, 0]) / det
    jinv[2, 1] = (jac[0, 1] * jac[2, 0] - jac[0, 0] * jac[2, 1]) / det
    jinv[2, 2] = (jac[0, 0] * jac[1, 1] - jac[0, 1] * jac[1, 0]) / det
    lamina_frame(jac, q)
    for a in range(9):
        half = 0.5 * he[a]
        for j in range(3):
            gN[a, j] = jinv[0, j] * dNr[a] + jinv[1, j] * dNs[a]
            gM[a, j] = half * (t * gN[a, j] + jinv[2, j] * N[a])
    return det


@njit(cache=True, error_model="numpy")
def _lamina_to_global(s5, q, sg):
    """Global stress sg (3, 3) = q^T sigma^l q from lamina (s11, s22, s12, s13, s23)."""
    for i in range(3):
        # row i of q^T sigma^l: sum_k q[k, i] sigma^l[k, :]
        t0 = q[0, i] * s5[0] + q[1, i] * s5[2] + q[2, i] * s5[3]
        t1 = q[0, i] * s5[2] + q[1, i] * s5[1] + q[2, i] * s5[4]
        t2 = q[0, i] * s5[3] + q[1, i] * s5[4]
        for j in range(3):
            sg[i, j] = t0 * q[0, j] + t1 * q[1, j] + t2 * q[2, j]


@njit(cache=True, error_model="numpy")
def _global_to_lamina_strain(eg, q, e5, v):
    """Lamina strain vector (e11, e22, 2e12, 2e13, 2e23) of q eg q^T, eg (3, 3) symmetric;
    v (3, 3) scratch."""
    # rows of eg q^T, i.e. (eg q_a) for lamina axes a = 0, 1, 2
    for a in range(3):
        for i in range(3):
            v[a, i] = eg[i, 0] * q[a, 0] + eg[i, 1] * q[a, 1] + eg[i, 2] * q[a, 2]
    e5[0] = q[0, 0] * v[0, 0] + q[0, 1] * v[0, 1] + q[0, 2] * v[0, 2]
    e5[1] = q[1, 0] * v[1, 0] + q[1, 1] * v[1, 1] + q[1, 2] * v[1, 2]
    e5[2] = 2.0 * (q[0, 0] * v[1, 0] + q[0, 1] * v[1, 1] + q[0, 2] * v[1, 2])
    e5[3] = 2.0 * (q[0, 0] * v[2, 0] + q[0, 1] * v[2, 1] + q[0, 2] * v[2, 2])
    e5[4] = 2.0 * (q[1, 0] * v[2, 0] + q[1, 1] * v[2, 1] + q[1, 2] * v[2, 2])


@njit(cache=True, error_model="numpy")
def _accumulate(sg, gN, gM, dv, fe, ge):
    """fe[a] += sg gN[a] dv, ge[a] += sg gM[a] dv, for the 9 nodes."""
    for a in range(9):
        for i in range(3):
            fe[a, i] += (sg[i, 0] * gN[a, 0] + sg[i, 1] * gN[a, 1] + sg[i, 2] * gN[a, 2]) * dv
            ge[a, i] += (sg[i, 0] * gM[a, 0] + sg[i, 1] * gM[a, 1] + sg[i, 2] * gM[a, 2]) * dv


@njit(cache=True, error_model="numpy")
def _gradient_of(ue, ve, gN, gM, L):
    """L (3, 3) = sum_a ue[a] (x) gN[a] + ve[a] (x) gM[a]."""
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for a in range(9):
                acc += ue[a, i] * gN[a, j] + ve[a, i] * gM[a, j]
            L[i, j] = acc


#: Modes of :func:`_element_response`.
TOTAL, INCREMENTAL, LINEAR = 0, 1, 2


@njit(cache=True, error_model="numpy")
def _almansi(F, eg, B):
    """Almansi strain eg = 1/2 (I - (F F^T)^-1) of a deformation gradient F (3, 3); B (3, 3)
    scratch. A degenerate F gives non-finite values (no exception), which the time loop
    detects."""
    for i in range(3):
        for j in range(i, 3):
            B[i, j] = B[j, i] = F[i, 0] * F[j, 0] + F[i, 1] * F[j, 1] + F[i, 2] * F[j, 2]
    det = det3(B)
    eg[0, 0] = 0.5 - 0.5 * (B[1, 1] * B[2, 2] - B[1, 2] * B[2, 1]) / det
    eg[1, 1] = 0.5 - 0.5 * (B[0, 0] * B[2, 2] - B[0, 2] * B[2, 0]) / det
    eg[2, 2] = 0.5 - 0.5 * (B[0, 0] * B[1, 1] - B[0, 1] * B[1, 0]) / det
    eg[0, 1] = eg[1, 0] = -0.5 * (B[0, 2] * B[2, 1] - B[0, 1] * B[2, 2]) / det
    eg[0, 2] = eg[2, 0] = -0.5 * (B[0, 1] * B[1, 2] - B[0, 2] * B[1, 1]) / det
    eg[1, 2] = eg[2, 1] = -0.5 * (B[0, 2] * B[1, 0] - B[0, 0] * B[1, 2]) / det


@njit(cache=True, error_model="numpy")
def _element_response(mode, xe, de, he, ue, ve, jac0_inv, rule, material, axes0, stress, state_stress, stretch, fe, ge,
                      work):
    """Stresses and nodal forces of one element, with assumed membrane and shear strains.

    mode: TOTAL (stress from the total Almansi strain), INCREMENTAL (stress plus C~ times
    the strain increment of the field ue, ve) or LINEAR (strain of the field ue, ve: the
    material stiffness product). Points: rows 0..nq-1 of N, dNr, dNs are the 3 x 3 Gauss
    points, the remaining rows the membrane tying points; tie (3, nq, m) and tie_points
    (3, m) give, for the covariant components rr, ss and rs, the interpolation weights at
    each integration point and the tying points they refer to.

    Assumed membrane strain against membrane locking (a curved quadratic element cannot
    bend without stretching by O(theta^2), which full integration samples): the covariant
    membrane strains c_ab = g_a . eps . g_b, averaged through the thickness, are tied at
    points where that spurious stretch vanishes, each component on its own set
    (rr: 2 x 3, ss: 3 x 2, rs: 2 x 2, as in Huang and Hinton's and Bathe's MITC9 9-node
    shells; one shared 2 x 2 set would leave three zero-energy membrane modes):
        c*_ab(p, t) = c_ab(p, t) - cbar_ab(p) + sum_m tie_ab(p, m) cbar_ab(m),
    and the change goes back into the lamina strains through the contravariant basis. The
    bending part (the deviation through the thickness) stays at the point. The transverse
    shears are tied too (against shear locking of thin, distorted elements), layer by
    layer: gamma_r on the rr points, gamma_s on the ss points. Constant strain on straight-edged elements and rigid motion are
    reproduced exactly; the virtual work of sigma . delta eps* puts effective stresses at
    the tying points too.

    Constitutive law (``material``, :class:`shellsim.bundles.Material`): the law LINEAR
    uses the reduced matrix C (5, 5); a hyperelastic law
    (:mod:`shellsim.materials.hyperelastic`, Technique 1, TOTAL and LINEAR modes) takes
    its parameters and the element's initial material frames ``axes0`` (nq, nt, 3, 3)
    (see :func:`_hyperelastic_point`). ``rule``: :class:`shellsim.bundles.Rule`.

    xe, de (9, 3), he (9,), ue, ve (9, 3); jac0_inv (npts, nt, 3, 3);
    Techniques 2 and 3 (law LINEAR, INCREMENTAL)
    add C times the step's strain increment to the stresses kept in the lamina frame,
    turn them with the material's spin relative to that frame, and (2) push them forward
    with the step's stretch (:func:`_convect`).
    stress (nq, nt, 5) read (INCREMENTAL) and written; stretch (nq,): the normal stretch
    of the through-thickness mean strain at each point, from zero normal stress
    (hyperelastic TOTAL), or 1 + the step's mean normal strain increment (Techniques 2
    and 3); else left alone;
    state_stress (nq, nt, 5): the current stress, whose initial-stress stiffness LINEAR adds
    to the material one (the critical step of a stretched membrane is set by both);
    fe, ge (9, 3) overwritten; work: an :class:`ElementScratch`.
    """
    N, dNr, dNs, tie, tie_points, wq, tz, wt = rule.N, rule.dNr, rule.dNs, rule.tie, rule.tie_points, rule.wq, rule.tz, rule.wt
    law, params, C, technique = material.law, material.params, material.C, material.technique
    jac, jinv, q, gN, gM, sg, eg, F = work.jac, work.jinv, work.q, work.gN, work.gM, work.sg, work.eg, work.F
    plane, glob, local, v, s5, cov, delta = work.plane, work.glob, work.local, work.v, work.s5, work.cov, work.delta
    Q, GN, GM, G, jinv_all, A, DV = work.Q, work.GN, work.GM, work.G, work.jinv_all, work.A, work.DV
    EPS, EPS0, FP, LP, SW = work.EPS, work.EPS0, work.FP, work.LP, work.SW
    cbar, Bab, T, cov_shear, TS = work.cbar, work.Bab, work.T, work.cov_shear, work.TS
    coef, rhs, Mb, Ct, Emean, M3 = work.coef, work.rhs, work.Mb, work.Ct, work.Emean, work.M3
    hyper = law != hyperelastic.LINEAR
    # Techniques 2 and 3: stresses accumulated from strain increments, turned and stretched
    convected = mode == INCREMENTAL and technique >= 2
    # the field's (or the step's) gradient serves the initial-stress stiffness (LINEAR) and
    # the spin correction of Techniques 2 and 3
    keep_gradient = mode == LINEAR or convected
    nq = wq.shape[0]
    npts = N.shape[0]
    nt = tz.shape[0]
    wsum = 0.0
    for k in range(nt):
        wsum += wt[k]
    for p in range(npts):
        for k in range(nt):
            det = _point_geometry(xe, de, he, N[p], dNr[p], dNs[p], tz[k], jac, jinv, q, gN, gM)
            Q[p, k] = q
            GN[p, k] = gN
            GM[p, k] = gM
            jinv_all[p, k] = jinv
            for i in range(3):
                G[p, k, 0, i] = jac[i, 0]
                G[p, k, 1, i] = jac[i, 1]
            DV[p, k] = det * wq[p] * wt[k] if p < nq else 0.0
            if mode == TOTAL or (hyper and p < nq):
                for i in range(3):
                    for j in range(3):
                        acc = 0.0
                        for m in range(3):
                            acc += jac[i, m] * jac0_inv[p, k, m, j]
                        F[i, j] = acc
                if hyper and p < nq:
                    FP[p, k] = F
            if mode == TOTAL:
                _almansi(F, eg, v)
            else:
                _gradient_of(ue, ve, gN, gM, F)
                for i in range(3):
                    for j in range(3):
                        eg[i, j] = 0.5 * (F[i, j] + F[j, i])
                if keep_gradient and p < nq:
                    LP[p, k] = F
            _global_to_lamina_strain(eg, q, EPS[p, k], v)
            if hyper and p < nq:
                EPS0[p, k] = EPS[p, k]
    # Covariant membrane strains c_ab = g_a . eps . g_b (a, b in r, s), frame-free, and their
    # through-thickness means cbar (the membrane part), at every point.
    cbar[:] = 0.0
    for x in range(npts):
        for k in range(nt):
            _lamina_strain_tensor(EPS[x, k], Q[x, k], plane, glob)
            _covariant(glob, G[x, k], cov)
            for c in range(3):
                cbar[x, c] += wt[k] / wsum * cov[c]
    # Assumed: c*_ab(p, t) = c_ab(p, t) - cbar_ab(p) + [tied cbar_ab at p], each component
    # interpolated from its own tying points (rr: 2 x 3, ss: 3 x 2, rs: 2 x 2); the change
    # goes back to a tensor with the contravariant basis and into the lamina strains.
    for p in range(nq):
        for c in range(3):
            acc = -cbar[p, c]
            for m in range(tie.shape[2]):
                if tie[c, p, m] != 0.0:
                    acc += tie[c, p, m] * cbar[tie_points[c, m], c]
            delta[c] = acc
        for k in range(nt):
            _contravariant_tensor(delta, jinv_all[p, k], glob)
            _rotate(Q[p, k], glob, local)
            EPS[p, k, 0] += local[0, 0]
            EPS[p, k, 1] += local[1, 1]
            EPS[p, k, 2] += 2.0 * local[0, 1]
    # Assumed transverse shear against shear locking of thin, distorted elements: the
    # covariant shears gamma_a = g_a . gamma (gamma = (2e13, 2e23) in the lamina plane) are
    # tied layer by layer, gamma_r on the rr points and gamma_s on the ss points (MITC9).
    for x in range(npts):
        for k in range(nt):
            _lamina_tangents(Q[x, k], G[x, k], A[x, k])
            for c in range(2):
                cov_shear[x, k, c] = A[x, k, c, 0] * EPS[x, k, 3] + A[x, k, c, 1] * EPS[x, k, 4]
    for p in range(nq):
        for k in range(nt):
            for c in range(2):
                acc = 0.0
                for m in range(tie.shape[2]):
                    if tie[c, p, m] != 0.0:
                        acc += tie[c, p, m] * cov_shear[tie_points[c, m], k, c]
                delta[c] = acc
            _solve2(A[p, k], delta[0], delta[1], EPS[p, k, 3:5])
    vol_basis = rule.vol_basis
    nb = vol_basis.shape[1]
    if nb:
        _project_volumetric(EPS, DV, vol_basis, nq, nt, False, coef, rhs, Mb)
    for p in range(nq):
        Emean[:] = 0.0
        if convected:
            stretch[p] = 1.0
        for k in range(nt):
            if hyper and mode == TOTAL:
                # DV was taken on the initial fibre lengths; from here on it is the true volume
                DV[p, k] *= _hyperelastic_point(law, params, axes0[p, k], Q[p, k], FP[p, k], EPS[p, k], EPS0[p, k],
                                                stress[p, k], Ct, False, Emean, wt[k] / wsum, M3, s5)
            elif hyper:  # LINEAR: the tangent at the current state times the field's strain
                DV[p, k] *= _hyperelastic_point(law, params, axes0[p, k], Q[p, k], FP[p, k], EPS0[p, k], EPS0[p, k],
                                                s5, Ct, True, Emean, 0.0, M3, s5)
                for i in range(5):
                    acc = 0.0
                    for j in range(5):
                        acc += Ct[i, j] * EPS[p, k, j]
                    stress[p, k, i] = acc
            else:
                for i in range(5):
                    acc = 0.0
                    for j in range(5):
                        acc += C[i, j] * EPS[p, k, j]
                    if mode == INCREMENTAL:
                        stress[p, k, i] += acc
                    else:
                        stress[p, k, i] = acc
                if convected:
                    normal = -material.normal_ratio * (EPS[p, k, 0] + EPS[p, k, 1])
                    stretch[p] += wt[k] / wsum * normal
                    if technique == 2:
                        _convect(stress[p, k], EPS[p, k], normal, local, glob, eg)
                    _follow_material_spin(stress[p, k], LP[p, k], Q[p, k], G[p, k], local)
            for i in range(3):
                SW[p, k, i] = stress[p, k, i] * DV[p, k]
        if hyper and mode == TOTAL:
            # normal stretch of the fibre's mean strain: the layers' bending parts cancel
            stretch[p] = hyperelastic.normal_strain(law, params, Emean)
    if nb:
        _project_volumetric(SW, DV, vol_basis, nq, nt, True, coef, rhs, Mb)
    # Virtual work: the direct terms s dv at (p, k). The in-plane stresses, contracted
    # with the contravariant basis, Bab(p) = sum_k dv g^a . sigma_m . g^b (twice for rs),
    # act back through -cbar(p) at the integration points and through the tying at the
    # tying points, as the global stress (w_k / W) sum_ab T_ab sym(g_a (x) g_b).
    Bab[:] = 0.0
    for p in range(nq):
        for k in range(nt):
            plane[:] = 0.0
            plane[0, 0] = SW[p, k, 0]
            plane[1, 1] = SW[p, k, 1]
            plane[0, 1] = plane[1, 0] = SW[p, k, 2]
            _rotate(Q[p, k].T, plane, glob)
            _contract_contravariant(glob, jinv_all[p, k], cov)
            for c in range(3):
                Bab[p, c] += cov[c]
    T[:] = 0.0
    for p in range(nq):
        for c in range(3):
            T[p, c] -= Bab[p, c]
            for m in range(tie.shape[2]):
                if tie[c, p, m] != 0.0:
                    T[tie_points[c, m], c] += tie[c, p, m] * Bab[p, c]
    # The shear stresses work through the tied covariant shears only: tau . A_p^-1 g* at
    # the integration points puts A_m^T (sum_p tie(p, m) A_p^-T tau_p dv_p) at each tying
    # point m, as an effective lamina shear stress there.
    TS[:] = 0.0
    for p in range(nq):
        for k in range(nt):
            _solve2(A[p, k].T, stress[p, k, 3] * DV[p, k], stress[p, k, 4] * DV[p, k], delta)
            for c in range(2):
                for m in range(tie.shape[2]):
                    if tie[c, p, m] != 0.0:
                        TS[tie_points[c, m], k, c] += tie[c, p, m] * delta[c]
    fe[:] = 0.0
    ge[:] = 0.0
    for x in range(npts):
        for k in range(nt):
            for i in range(3):
                s5[i] = SW[x, k, i] if x < nq else 0.0
            for i in range(2):
                s5[3 + i] = TS[x, k, 0] * A[x, k, 0, i] + TS[x, k, 1] * A[x, k, 1, i]
            _lamina_to_global(s5, Q[x, k], sg)
            share = wt[k] / wsum
            for i in range(3):
                for j in range(3):
                    sg[i, j] += share * (T[x, 0] * G[x, k, 0, i] * G[x, k, 0, j]
                                         + T[x, 1] * G[x, k, 1, i] * G[x, k, 1, j]
                                         + 0.5 * T[x, 2] * (G[x, k, 0, i] * G[x, k, 1, j]
                                                            + G[x, k, 1, i] * G[x, k, 0, j]))
            _accumulate(sg, GN[x, k], GM[x, k], 1.0, fe, ge)
    if mode == LINEAR:
        # initial-stress stiffness: the current stress sigma acting through the field's
        # gradient L, f_a += L sigma gN_a dv (and gM_a for the director)
        for p in range(nq):
            for k in range(nt):
                _lamina_to_global(state_stress[p, k], Q[p, k], sg)
                for i in range(3):
                    for j in range(3):
                        acc = 0.0
                        for m in range(3):
                            acc += LP[p, k, i, m] * sg[m, j]
                        eg[i, j] = acc
                _accumulate(eg, GN[p, k], GM[p, k], DV[p, k], fe, ge)


@njit(cache=True, error_model="numpy")
def _hyperelastic_point(law, params, R0, q, F, eps, eps0, out5, Ct, want_tangent, Emean, share, M3, v5):
    """Technique 1 at one point (thesis 3.10.1): lamina Cauchy stress out5 (5,) from a
    hyperelastic law, or (want_tangent) its tangent Ct (5, 5) in the current lamina frame.

    Fl = q F R0^T maps the initial material frame R0 (rows: axes 1, 2, 3 = normal) to the
    current lamina frame q; its Green-Lagrange strain 1/2 (Fl^T Fl - I) gets the assumed-
    strain correction pulled back exactly, Fl^T (eps - eps0) Fl (eps: lamina strains after
    the tying, eps0: before; (11, 22, 2x12, 2x13, 2x23)). E33 then follows from zero
    normal stress (Eq 3.28), S~ from the law, and the Cauchy stress is its push-forward
    Fl S~ Fl^T / J in lamina components (Eq 3.27), J = sqrt(det(2E + I)) the true volume
    ratio (1 when incompressible). F is taken on the initial fibre lengths, so det Fl is
    not J: the return value J / det Fl turns the point's volume into the true one, which
    every term of the virtual work then takes (Fl S~ Fl^T, the Kirchhoff stress, does not
    depend on Fl's normal column while S~_33 = 0, up to transverse shear). The tangent is
    pushed forward the same way (Eq 3.26), column by column for unit lamina strains.
    Adds share x E (before E33 is solved) to Emean (3, 3), for the fibre's mean strain
    (Eq 3.31). M3 (8, 3, 3), v5 (5,): scratch."""
    Fl, D, E, S, Cinv, dE, dS, tmp = M3[0], M3[1], M3[2], M3[3], M3[4], M3[5], M3[6], M3[7]
    congruence(q, F, R0, Fl)
    det = det3(Fl)
    # 1/2 (Fl^T Fl - I) + Fl^T (eps - eps0) Fl = Fl^T (eps - eps0 + I/2) Fl - I/2
    D[:] = 0.0
    _add_strain_tensor(eps, 1.0, D)
    _add_strain_tensor(eps0, -1.0, D)
    for i in range(3):
        D[i, i] += 0.5
    congruence(Fl.T, D, Fl.T, E)
    for i in range(3):
        E[i, i] -= 0.5
        for j in range(3):
            Emean[i, j] += share * E[i, j]
    p = hyperelastic.stress(law, params, E, S, Cinv)
    volume = hyperelastic.volume_ratio(law, E)
    if not want_tangent:
        _push_forward(Fl, S, volume, tmp, out5)
        return volume / det
    for b in range(5):
        v5[:] = 0.0
        v5[b] = 1.0
        D[:] = 0.0
        _add_strain_tensor(v5, 1.0, D)
        congruence(Fl.T, D, Fl.T, dE)  # pulled back: Fl^T D Fl
        hyperelastic.tangent(law, params, E, Cinv, p, dE, dS)
        _push_forward(Fl, dS, volume, tmp, v5)
        for a in range(5):
            Ct[a, b] = v5[a]
    return volume / det


@njit(cache=True, error_model="numpy")
def _follow_material_spin(s5, L, q, g, Ll):
    """Turn accumulated lamina stresses s5 (5,) by the step's in-plane spin of the
    material relative to the lamina frame.

    The lamina frame follows the bisector of g_r and g_s (Hughes); on a distorted element
    stretched unevenly that bisector turns against the material, and stresses kept in
    it would turn with it (1.3% off the exact uniaxial response at lambda = 3.26 on a
    distorted patch). The material's spin is w = (L21 - L12) / 2 in lamina components
    (Jaumann), the frame's the mean of the turning rates of g_r and g_s,
    (a x L a) . e3 for a unit a; the stresses turn by the difference, exactly as a
    rotation. L (3, 3): the step's displacement gradient (global); q (3, 3): lamina
    frame; g (2, 3): g_r, g_s; Ll (3, 3) scratch."""
    _rotate(q, L, Ll)
    spin = 0.5 * (Ll[1, 0] - Ll[0, 1])
    frame = 0.0
    for a in range(2):
        u0 = q[0, 0] * g[a, 0] + q[0, 1] * g[a, 1] + q[0, 2] * g[a, 2]
        u1 = q[1, 0] * g[a, 0] + q[1, 1] * g[a, 1] + q[1, 2] * g[a, 2]
        size = u0 * u0 + u1 * u1
        frame += 0.5 * (u0 * (Ll[1, 0] * u0 + Ll[1, 1] * u1) - u1 * (Ll[0, 0] * u0 + Ll[0, 1] * u1)) / size
    angle = spin - frame
    c, s = np.cos(angle), np.sin(angle)
    s11, s22, s12 = s5[0], s5[1], s5[2]
    s5[0] = c * c * s11 - 2.0 * c * s * s12 + s * s * s22
    s5[1] = s * s * s11 + 2.0 * c * s * s12 + c * c * s22
    s5[2] = c * s * (s11 - s22) + (c * c - s * s) * s12
    s13, s23 = s5[3], s5[4]
    s5[3] = c * s13 - s * s23
    s5[4] = s * s13 + c * s23


@njit(cache=True, error_model="numpy")
def _convect(s5, e5, normal, M, T, out):
    """Technique 2's push-forward of the accumulated stress (thesis Eqs 3.29-3.30) over
    one step: sigma <- M sigma M / det M, M = I + the step's lamina strain increment
    e5 (11, 22, 2x12, 2x13, 2x23) with its normal part ``normal`` (zero normal stress).
    Only the stretch is applied: the lamina frame already turns with the body. M, T, out
    (3, 3) scratch; s5 (5,) updated."""
    M[:] = 0.0
    _add_strain_tensor(e5, 1.0, M)
    M[2, 2] = normal
    for i in range(3):
        M[i, i] += 1.0
    T[:] = 0.0
    T[0, 0], T[1, 1] = s5[0], s5[1]
    T[0, 1] = T[1, 0] = s5[2]
    T[0, 2] = T[2, 0] = s5[3]
    T[1, 2] = T[2, 1] = s5[4]
    _push_forward(M, T, det3(M), out, s5)


@njit(cache=True, error_model="numpy")
def _add_strain_tensor(e5, scale, D):
    """D (3, 3) += scale x the lamina tensor of the strains e5 (11, 22, 2x12, 2x13, 2x23)
    (engineering shears halved); D[2, 2] untouched."""
    D[0, 0] += scale * e5[0]
    D[1, 1] += scale * e5[1]
    D[0, 1] += 0.5 * scale * e5[2]
    D[1, 0] += 0.5 * scale * e5[2]
    D[0, 2] += 0.5 * scale * e5[3]
    D[2, 0] += 0.5 * scale * e5[3]
    D[1, 2] += 0.5 * scale * e5[4]
    D[2, 1] += 0.5 * scale * e5[4]


@njit(cache=True, error_model="numpy")
def _push_forward(Fl, S, det, tmp, out5):
    """Lamina components (11, 22, 12, 13, 23) of Fl S Fl^T / det; tmp (3, 3) scratch."""
    congruence(Fl, S, Fl, tmp)
    out5[0] = tmp[0, 0] / det
    out5[1] = tmp[1, 1] / det
    out5[2] = tmp[0, 1] / det
    out5[3] = tmp[0, 2] / det
    out5[4] = tmp[1, 2] / det


@njit(cache=True, error_model="numpy")
def _project_volumetric(V, DV, basis, nq, nt, adjoint, coef, rhs, Mb):
    """In-plane volumetric strain projected, layer by layer, on the fields of ``basis``
    (nq, nb): with (1, r, s) the 9-node quadrilateral becomes Q9/P3, free of volumetric
    locking in plane strain.

    Forward (adjoint=False): V = EPS (npts, nt, 5); e_v = e11 + e22 at the integration
    points is replaced by its L2 projection e_v* = phi^T Mb^-1 sum_p phi(p) DV(p) e_v(p),
    the change going half into e11 and half into e22 (the deviatoric strain is untouched).
    Adjoint (adjoint=True): V = SW (npts, nt, 3), the volume-weighted in-plane stresses;
    with S = (SW_11 + SW_22) / 2 their virtual work through e_v* adds
    DV(q) phi(q)^T Mb^-1 sum_p phi(p) S(p) - S(q) to both normal stresses at each point q.
    DV (npts, nt) point volumes; coef, rhs (nb,) and Mb (nb, nb) scratch."""
    nb = basis.shape[1]
    for k in range(nt):
        _projection_system(DV, basis, nq, k, Mb)
        rhs[:] = 0.0
        for p in range(nq):
            weight = 0.5 if adjoint else DV[p, k]
            for i in range(nb):
                rhs[i] += basis[p, i] * weight * (V[p, k, 0] + V[p, k, 1])
        coef[:] = np.linalg.solve(Mb, rhs)
        for q in range(nq):
            projected = 0.0
            for i in range(nb):
                projected += basis[q, i] * coef[i]
            change = (DV[q, k] if adjoint else 0.5) * projected - 0.5 * (V[q, k, 0] + V[q, k, 1])
            V[q, k, 0] += change
            V[q, k, 1] += change


@njit(cache=True, error_model="numpy")
def _projection_system(DV, basis, nq, k, Mb):
    """Mb (nb, nb) = sum_p DV(p, k) phi(p) phi(p)^T, the Gram matrix of the projection."""
    nb = basis.shape[1]
    Mb[:] = 0.0
    for p in range(nq):
        for i in range(nb):
            for j in range(nb):
                Mb[i, j] += DV[p, k] * basis[p, i] * basis[p, j]


@njit(cache=True, error_model="numpy")
def _lamina_tangents(q, g, out):
    """Lamina in-plane components out (2, 2) of the tangents g (2, 3): out[a, i] = g_a . e_i."""
    for a in range(2):
        for i in range(2):
            out[a, i] = q[i, 0] * g[a, 0] + q[i, 1] * g[a, 1] + q[i, 2] * g[a, 2]


@njit(cache=True, error_model="numpy")
def _solve2(A, b0, b1, out):
    """out[:2] = A^-1 (b0, b1) for A (2, 2)."""
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    out[0] = (A[1, 1] * b0 - A[0, 1] * b1) / det
    out[1] = (A[0, 0] * b1 - A[1, 0] * b0) / det


@njit(cache=True, error_model="numpy")
def _lamina_strain_tensor(e5, q, plane, out):
    """The in-plane part (11, 22, 12) of lamina strains e5 as a global tensor out (3, 3)."""
    plane[:] = 0.0
    plane[0, 0] = e5[0]
    plane[1, 1] = e5[1]
    plane[0, 1] = plane[1, 0] = 0.5 * e5[2]
    _rotate(q.T, plane, out)


@njit(cache=True, error_model="numpy")
def _covariant(e, g, cov):
    """Covariant components (rr, ss, rs) of a global tensor e with tangents g (2, 3)."""
    for c, (a, b) in enumerate(((0, 0), (1, 1), (0, 1))):
        acc = 0.0
        for i in range(3):
            for j in range(3):
                acc += g[a, i] * e[i, j] * g[b, j]
        cov[c] = acc


@njit(cache=True, error_model="numpy")
def _contravariant_tensor(c, jinv, out):
    """Global tensor sum_ab g^a (x) g^b c_ab (ordered pairs, c_rs counted twice), with the
    contravariant vectors g^a = jinv[a] (rows of the inverse Jacobian)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = (c[0] * jinv[0, i] * jinv[0, j] + c[1] * jinv[1, i] * jinv[1, j]
                         + c[2] * (jinv[0, i] * jinv[1, j] + jinv[1, i] * jinv[0, j]))


@njit(cache=True, error_model="numpy")
def _contract_contravariant(s, jinv, out):
    """(g^r.s.g^r, g^s.s.g^s, 2 g^r.s.g^s) of a global tensor s (3, 3): the adjoint of
    :func:`_contravariant_tensor`."""
    for c, (a, b, factor) in enumerate(((0, 0, 1.0), (1, 1, 1.0), (0, 1, 2.0))):
        acc = 0.0
        for i in range(3):
            for j in range(3):
                acc += jinv[a, i] * s[i, j] * jinv[b, j]
        out[c] = factor * acc


@njit(cache=True, error_model="numpy")
def _rotate(q, A, out):
    """out = q A q^T, all (3, 3): global tensor to lamina components with q, and back with
    q.T."""
    congruence(q, A, q, out)


class ElementScratch(NamedTuple):
    """Work arrays of :func:`_element_response` for one element at a time: at one point
    (3, 3) jac, jinv, q, sg, eg, F, plane, glob, local, v; (9, 3) gN, gM; s5 (5,); cov,
    delta (3,); Ct (5, 5); Emean (3, 3); M3 (8, 3, 3) for :func:`_hyperelastic_point`.
    At every point (npts, nt, ...): Q, jinv_all (3, 3) lamina frames and inverse
    Jacobians, GN, GM (9, 3) gradient vectors, G (2, 3) tangents, A (2, 2) their lamina
    components, DV point volumes, EPS (5) lamina strains, cov_shear and TS (2) covariant
    shears and their tying-point stresses, SW (3) volume-weighted in-plane stresses;
    per in-plane point (npts, 3) cbar, Bab, T; at the Gauss points (nq, nt, ...) FP and
    LP (3, 3) deformation and field gradients, EPS0 (5) strains before the tying;
    coef, rhs (nb,), Mb (nb, nb) of the volumetric projection. Then one element's
    gathered xe, de, ue, ve (9, 3), he (9,) and its normal stretches stretch (nq,)."""

    jac: np.ndarray
    jinv: np.ndarray
    q: np.ndarray
    sg: np.ndarray
    eg: np.ndarray
    F: np.ndarray
    plane: np.ndarray
    glob: np.ndarray
    local: np.ndarray
    v: np.ndarray
    gN: np.ndarray
    gM: np.ndarray
    s5: np.ndarray
    cov: np.ndarray
    delta: np.ndarray
    Ct: np.ndarray
    Emean: np.ndarray
    M3: np.ndarray
    Q: np.ndarray
    jinv_all: np.ndarray
    GN: np.ndarray
    GM: np.ndarray
    G: np.ndarray
    A: np.ndarray
    DV: np.ndarray
    EPS: np.ndarray
    cov_shear: np.ndarray
    TS: np.ndarray
    SW: np.ndarray
    cbar: np.ndarray
    Bab: np.ndarray
    T: np.ndarray
    FP: np.ndarray
    LP: np.ndarray
    EPS0: np.ndarray
    coef: np.ndarray
    rhs: np.ndarray
    Mb: np.ndarray
    xe: np.ndarray
    de: np.ndarray
    ue: np.ndarray
    ve: np.ndarray
    he: np.ndarray
    stretch: np.ndarray


@njit(cache=True, error_model="numpy")
def _scratch(npts, nt, nb, nq):
    """An :class:`ElementScratch` for ``npts`` in-plane points, ``nt`` layers, ``nb``
    volumetric fields and ``nq`` Gauss points."""
    return ElementScratch(
        jac=np.empty((3, 3)), jinv=np.empty((3, 3)), q=np.empty((3, 3)), sg=np.empty((3, 3)), eg=np.empty((3, 3)),
        F=np.empty((3, 3)), plane=np.empty((3, 3)), glob=np.empty((3, 3)), local=np.empty((3, 3)), v=np.empty((3, 3)),
        gN=np.empty((9, 3)), gM=np.empty((9, 3)), s5=np.empty(5), cov=np.empty(3), delta=np.empty(3),
        Ct=np.empty((5, 5)), Emean=np.empty((3, 3)), M3=np.empty((8, 3, 3)),
        Q=np.empty((npts, nt, 3, 3)), jinv_all=np.empty((npts, nt, 3, 3)), GN=np.empty((npts, nt, 9, 3)),
        GM=np.empty((npts, nt, 9, 3)), G=np.empty((npts, nt, 2, 3)), A=np.empty((npts, nt, 2, 2)),
        DV=np.empty((npts, nt)), EPS=np.empty((npts, nt, 5)), cov_shear=np.empty((npts, nt, 2)),
        TS=np.empty((npts, nt, 2)), SW=np.empty((npts, nt, 3)), cbar=np.empty((npts, 3)), Bab=np.empty((npts, 3)),
        T=np.empty((npts, 3)), FP=np.empty((nq, nt, 3, 3)), LP=np.empty((nq, nt, 3, 3)), EPS0=np.empty((nq, nt, 5)),
        coef=np.empty(nb), rhs=np.empty(nb), Mb=np.empty((nb, nb)),
        xe=np.empty((9, 3)), de=np.empty((9, 3)), ue=np.empty((9, 3)), ve=np.empty((9, 3)), he=np.empty(9),
        stretch=np.ones(nq))


class Assembly(NamedTuple):
    """Per-element results before they are summed at the nodes (ne elements, n nodes):
    fe, ge (ne, 9, 3) translational and director-conjugate forces; volume, stretch (ne,)
    the element's volume and volume-weighted normal stretch (fibre-length update);
    g (n, 3) the summed director-conjugate forces. Allocated once per model
    (:func:`assembly`)."""

    fe: np.ndarray
    ge: np.ndarray
    volume: np.ndarray
    stretch: np.ndarray
    g: np.ndarray


def element_chunks(n_elements: int) -> int:
    """How many runs of elements the threads share out: one per thread (fewer on a tiny
    mesh), each with its own scratch."""
    return max(1, min(n_elements, get_num_threads()))


def assembly(n_nodes: int, n_elements: int) -> Assembly:
    """An :class:`Assembly` for a mesh of that size."""
    return Assembly(fe=np.zeros((n_elements, 9, 3)), ge=np.zeros((n_elements, 9, 3)), volume=np.zeros(n_elements),
                    stretch=np.zeros(n_elements), g=np.zeros((n_nodes, 3)))


@njit(cache=True, error_model="numpy")
def _gather(nodes, x, d, h, xe, de, he):
    """Copy one element's positions, directors (9, 3) and fibre lengths (9,) from the
    nodal arrays."""
    for a in range(9):
        node = nodes[a]
        he[a] = h[node]
        for i in range(3):
            xe[a, i] = x[node, i]
            de[a, i] = d[node, i]


@njit(cache=True, parallel=True, error_model="numpy")
def _all_elements(mode, rule, body, material, shape, ux, ud, stress, state_stress, f, fr, parts, chunks):
    """Sum the element responses into nodal forces f (n, 3) and rotational forces fr (n, 2).

    Elements are shared out in contiguous chunks over the threads; each writes only its
    own slots of ``parts`` (:class:`Assembly`) and of ``stress`` (ne, nq, nt, 5), and the
    nodes then add their elements' slots in ascending element order, so the sums are the
    same to the last bit for any number of threads (and the same as a serial loop's).

    With Techniques 2 and 3 (INCREMENTAL mode), the fibre lengths
    are scaled each step by 1 + the step's normal strain increment (thesis Eq 3.33); with
    a hyperelastic law in TOTAL mode the initial ones by the normal stretch, h = h0
    lambda_3 (thesis 3.11), one step behind the kinematics as in the thesis. Either factor
    is the element's volume mean, and a node takes the volume-weighted mean of its
    elements': averaged from the integration points with weights N_a dv, or N_a^2 dv, the
    nodal lengths of a refined holed sheet (Techniques 2, 3) grew a pattern inside the
    elements next to the hole that broke the run down. The stresses of a hyperelastic law
    are computed on the initial fibre lengths: J = 1 fixes the thickness strain anyway,
    and with the current ones a node-to-node difference in h tilts the layers, strains
    them and feeds back into lambda_3 (a loop no energy stands behind, which broke Test 10
    down). The updated h moves the faces (pressure, probes), masses and volume.
    """
    hyper = material.law != hyperelastic.LINEAR
    ne = body.conn.shape[0]
    # Technique 1 sets h = h0 lambda_3 (total), Techniques 2 and 3 scale h by each step's
    # 1 + normal strain increment (incremental, thesis Eq 3.33)
    incremental_update = material.technique >= 2 and mode == INCREMENTAL
    update = material.thickness_update and ((hyper and mode == TOTAL) or incremental_update)
    for c in prange(chunks):
        _element_chunk(c * ne // chunks, (c + 1) * ne // chunks, mode, rule, body, material, shape, ux, ud, stress,
                       state_stress, parts, update)
    _gather_at_nodes(body, parts, f)
    to_rotational(parts.g, shape.d, shape.e1, fr)
    if update:
        _update_fibre_lengths(body, parts, shape.h, incremental_update)


@njit(cache=True, error_model="numpy")
def _element_chunk(start, stop, mode, rule, body, material, shape, ux, ud, stress, state_stress, parts, update):
    """The responses of elements start..stop-1 into their slots of ``parts`` and
    ``stress``; arguments as :func:`_all_elements`, ``update``: whether the fibre lengths
    follow (element volumes and mean stretches are then kept)."""
    conn = body.conn
    hyper = material.law != hyperelastic.LINEAR
    nq = rule.wq.shape[0]
    nt = rule.tz.shape[0]
    work = _scratch(rule.N.shape[0], nt, rule.vol_basis.shape[1], nq)
    for e in range(start, stop):
        _gather(conn[e], shape.x, shape.d, body.h0 if hyper else shape.h, work.xe, work.de, work.he)
        for a in range(9):
            for i in range(3):
                work.ue[a, i] = ux[conn[e, a], i]
                work.ve[a, i] = ud[conn[e, a], i]
        _element_response(mode, work.xe, work.de, work.he, work.ue, work.ve, body.jac0_inv[e], rule, material,
                          material.axes0[e if hyper else 0], stress[e], state_stress[e], work.stretch, parts.fe[e],
                          parts.ge[e], work)
        if update:
            vol = 0.0
            mean = 0.0
            for p in range(nq):
                dv = 0.0
                for k in range(nt):
                    dv += work.DV[p, k]
                vol += dv
                mean += dv * work.stretch[p]
            parts.volume[e] = vol
            parts.stretch[e] = mean


@njit(cache=True, error_model="numpy")
def _gather_at_nodes(body, parts, f):
    """The nodal sums of the element forces in ``parts`` (:class:`Assembly`), each node's
    slots in ascending order: f (n, 3) from fe, parts.g from ge."""
    g = parts.g
    for node in range(g.shape[0]):
        f[node, :] = 0.0
        g[node, :] = 0.0
        for slot in range(body.node_slots[node], body.node_slots[node + 1]):
            e, a = divmod(body.slots[slot], 9)
            for i in range(3):
                f[node, i] += parts.fe[e, a, i]
                g[node, i] += parts.ge[e, a, i]


@njit(cache=True, error_model="numpy")
def _update_fibre_lengths(body, parts, h, incremental):
    """h (n,) = (h, incremental; else h0) x the volume-weighted mean of the normal
    stretches of the node's elements (``parts``), summed in ascending element order."""
    for node in range(h.shape[0]):
        weighted = 0.0
        weights = 0.0
        for slot in range(body.node_slots[node], body.node_slots[node + 1]):
            e = body.slots[slot] // 9
            weighted += parts.stretch[e]
            weights += parts.volume[e]
        if weights > 0.0:
            h[node] = (h[node] if incremental else body.h0[node]) * weighted / weights


@njit(cache=True, error_model="numpy")
def internal_forces(rule, body, material, shape, dx, dd, stress, f, fr, parts, chunks):
    """Internal forces of all elements at the current configuration.

    Parameters
    ----------
    rule, body, material : :class:`shellsim.bundles.Rule`, :class:`~shellsim.bundles.Body`,
        :class:`~shellsim.bundles.Material`. In the total formulation the stress follows
        from the total deformation (Almansi strain, thesis Eq 3.1 and 3.22); in the
        incremental one (``material.incremental``) the stress in the lamina frame gains
        C~ times the strain increment of the last step (Eq 3.2).
    shape : :class:`~shellsim.bundles.Shape`, the current configuration; its fibre lengths
        h are updated in place when the material asks (see :func:`_all_elements`).
    dx, dd : (n, 3) last step's mid-surface and director increments (incremental only).
    stress : (ne, nq, nt, 5) lamina Cauchy stress, written (and read when incremental).
    f : (n, 3) translational forces, fr : (n, 2) rotational forces, both overwritten.
    parts : :class:`Assembly` of the mesh (scratch).
    chunks : how many contiguous runs of elements the threads share out (see
        :func:`element_chunks`); the results do not depend on it.
    """
    _all_elements(INCREMENTAL if material.incremental else TOTAL, rule, body, material, shape, dx, dd, stress, stress,
                  f, fr, parts, chunks)


@njit(cache=True, error_model="numpy")
def stiffness_product(rule, body, material, shape, stress, vu, vr, f, fr, parts, chunks):
    """Tangent stiffness times a DOF vector, K v, without forming K: the material part
    K_L (thesis Eq 3.37; with a hyperelastic law its tangent at the current state,
    Eq 3.26) plus the initial-stress part of the current stress (ne, nq, nt, 5), which the
    thesis leaves out but a membrane stretched to large strain needs (Test 8: the step
    from K_L alone was too long on refined meshes).

    vu (n, 3) translational and vr (n, 2) rotational components of v; writes f (n, 3),
    fr (n, 2). Other arguments as :func:`internal_forces` (``parts`` may be the time
    loop's: it is scratch between steps).
    """
    vd = np.empty((shape.x.shape[0], 3))
    director_increments(vr, shape.d, shape.e1, vd)
    field_stress = np.empty((body.conn.shape[0], rule.wq.shape[0], rule.tz.shape[0], 5))
    _all_elements(LINEAR, rule, body, material, shape, vu, vd, field_stress, stress, f, fr, parts, chunks)


@njit(cache=True, error_model="numpy")
def lumped_masses(rule, body, shape, density, hughes, mt, mr):
    """Lumped nodal masses on the current ``shape`` (thesis 3.14); rule, body: the
    element's :class:`~shellsim.bundles.Rule` and the mesh's :class:`~shellsim.bundles.Body`.

    hughes=True gives M1 (Hughes et al. 1981): translational masses proportional to
    int N_a^2 rho dV, scaled to the element mass; rotational ones are those times
    max(h_a^2/12, A/8). hughes=False gives M2: row sums of the consistent mass, separately
    for the translational block (int N_a rho dV) and the director block
    (sum_b int rho N_a N_b t^2 h_a h_b / 4 dV, with t^2 taken at its exact mean 1/3 over
    the thickness: the 2- and 3-point rules give that anyway, and the 1-point rule of a
    membrane-only scene would give no rotary inertia at all). Writes mt (n,) and mr (n,).
    """
    x, d, h, conn = shape.x, shape.d, shape.h, body.conn
    N, dNr, dNs, wq, tz, wt = rule.N, rule.dNr, rule.dNs, rule.wq, rule.tz, rule.wt
    mt[:] = 0.0
    mr[:] = 0.0
    jac = np.empty((3, 3))
    jinv = np.empty((3, 3))
    q = np.empty((3, 3))
    gN = np.empty((9, 3))
    gM = np.empty((9, 3))
    xe = np.empty((9, 3))
    de = np.empty((9, 3))
    he = np.empty(9)
    raw = np.empty(9)
    rot = np.empty(9)
    for e in range(conn.shape[0]):
        _gather(conn[e], x, d, h, xe, de, he)
        raw[:] = 0.0
        rot[:] = 0.0
        volume = 0.0
        for p in range(wq.shape[0]):
            for k in range(tz.shape[0]):
                det = _point_geometry(xe, de, he, N[p], dNr[p], dNs[p], tz[k], jac, jinv, q, gN, gM)
                dv = det * wq[p] * wt[k]
                volume += dv
                if hughes:
                    for a in range(9):
                        raw[a] += N[p, a] * N[p, a] * density * dv
                else:
                    hbar = 0.0
                    for b in range(9):
                        hbar += N[p, b] * he[b]
                    for a in range(9):
                        raw[a] += N[p, a] * density * dv
                        rot[a] += N[p, a] * density * dv * he[a] * hbar / 12.0
        if hughes:
            total = raw.sum()
            h_avg = he.mean()
            area = volume / h_avg
            for a in range(9):
                m = density * volume * raw[a] / total
                rot[a] = m * max(he[a] * he[a] / 12.0, area / 8.0)
                raw[a] = m
        for a in range(9):
            mt[conn[e, a]] += raw[a]
            mr[conn[e, a]] += rot[a]
