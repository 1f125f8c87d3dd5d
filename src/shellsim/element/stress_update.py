"""The constitutive update of an element group at its Gauss points: stress from strain
for the constant lamina tensor (small strain, Techniques 2 and 3) over all lanes at once,
and per lane for a hyperelastic law (Technique 1, :mod:`shellsim.materials.hyperelastic`)
and for the turning and stretching of Techniques 2 and 3's accumulated stresses.

Arrays with a trailing G carry the group's lanes; ``work`` is the group's
:class:`shellsim.element.response.GroupScratch`, whose one-lane buffers (q1, F1, L1, g1,
e1, e01, s1, v5, Ct, Emean, M3) take a lane's values for the per-lane laws.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..materials import hyperelastic
from ..tensor3 import congruence, det3
from .lanes import LANES, lane_copy, lane_store

#: Modes of :func:`shellsim.element.response.group_response`: stress from the total
#: strain, stress plus C~ times the strain increment of a field, or the material
#: stiffness product (strain of a field, tangent times it).
TOTAL, INCREMENTAL, LINEAR = 0, 1, 2


@njit(cache=True, error_model="numpy")
def constant_tensor(C, eps, stress, incremental):
    """stress (5, G) = (or +=, incremental) C (5, 5) eps (5, G)."""
    for i in range(5):
        for lane in range(LANES):
            acc = 0.0
            for j in range(5):
                acc += C[i, j] * eps[j, lane]
            if incremental:
                stress[i, lane] += acc
            else:
                stress[i, lane] = acc


@njit(cache=True, error_model="numpy")
def hyperelastic_layers(mode, material, axes0, work, stress, p, lane, share):
    """Technique 1 at Gauss point p of one lane, every layer: lamina stresses into
    ``stress`` (nq, nt, 5, G) (TOTAL) or the tangent times the field's strain (LINEAR);
    the point volumes work.DV become true volumes. axes0 (nq, nt, 3, 3): the lane's
    initial material frames; share (nt,): layer weights over their sum. Returns the
    normal stretch of the fibre's mean strain (TOTAL; the layers' bending parts cancel),
    else 1."""
    law, params = material.law, material.params
    q1, F1, e1, e01, s1, v5, Ct, Emean, M3 = work.q1, work.F1, work.e1, work.e01, work.s1, work.v5, work.Ct, work.Emean, work.M3
    Emean[:] = 0.0
    for k in range(share.shape[0]):
        lane_copy(work.Q[p, k], lane, q1)
        lane_copy(work.FP[p, k], lane, F1)
        lane_copy(work.EPS0[p, k], lane, e01)
        if mode == TOTAL:
            lane_copy(work.EPS[p, k], lane, e1)
            # DV was taken on the initial fibre lengths; from here on it is the true volume
            work.DV[p, k, lane] *= _hyperelastic_point(law, params, axes0[p, k], q1, F1, e1, e01, s1, Ct, False, Emean,
                                                       share[k], M3, v5)
            lane_store(s1, lane, stress[p, k])
        else:  # the tangent at the current state times the field's strain
            work.DV[p, k, lane] *= _hyperelastic_point(law, params, axes0[p, k], q1, F1, e01, e01, v5, Ct, True, Emean,
                                                       0.0, M3, v5)
            lane_copy(work.EPS[p, k], lane, e1)
            for i in range(5):
                acc = 0.0
                for j in range(5):
                    acc += Ct[i, j] * e1[j]
                stress[p, k, i, lane] = acc
    if mode == TOTAL:
        return hyperelastic.normal_strain(law, params, Emean)
    return 1.0


@njit(cache=True, error_model="numpy")
def convected_layer(material, work, stress, p, k, share, stretch, count):
    """Techniques 2 and 3 at Gauss point p, layer k, every lane, after the stress
    increment: the normal strain increment from zero normal stress (added, times the
    layer's share, to stretch (nq, G)), Technique 2's push-forward by the step's stretch,
    and the turn by the material's spin relative to the lamina frame; the first
    ``count`` lanes."""
    e1, s1, q1, L1, g1, M3 = work.e1, work.s1, work.q1, work.L1, work.g1, work.M3
    for lane in range(count):
        normal = -material.normal_ratio * (work.EPS[p, k, 0, lane] + work.EPS[p, k, 1, lane])
        stretch[p, lane] += share * normal
        lane_copy(stress[p, k], lane, s1)
        if material.technique == 2:
            lane_copy(work.EPS[p, k], lane, e1)
            _convect(s1, e1, normal, M3[0], M3[1], M3[2])
        lane_copy(work.LP[p, k], lane, L1)
        lane_copy(work.Q[p, k], lane, q1)
        lane_copy(work.G[p, k], lane, g1)
        _follow_material_spin(s1, L1, q1, g1, M3[0])
        lane_store(s1, lane, stress[p, k])


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
    congruence(q, L, q, Ll)
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
