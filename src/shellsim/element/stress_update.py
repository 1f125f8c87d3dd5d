"""The constitutive update of an element group at its Gauss points, every lane at once:
stress from strain for the constant lamina tensor (small strain, Techniques 2 and 3), a
hyperelastic law under zero normal stress (Technique 1,
:mod:`shellsim.materials.zero_normal_stress`), and the turning and stretching of
Techniques 2 and 3's accumulated stresses.

Arrays with a trailing G carry the group's lanes; ``group``, ``points`` and ``scratch``
are the group's arrays (:mod:`shellsim.element.work_arrays`), viewed again with their
trailing lengths fixed (:func:`~shellsim.element.work_arrays.fixed_lanes`) by the
functions the response calls, so that their lane loops vectorise: a view costs a few
comparisons, where inlining these updates into the response added about 17 s to a first
run's compiling.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..materials import zero_normal_stress
from ..tensor3 import congruence, det3, to_global, to_lamina
from ..lanes import LANES
from .work_arrays import fixed_lanes

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
def hyperelastic_layers(product, material, group, points, scratch, p, share):
    """Technique 1 at Gauss point p (thesis 3.10.1), every layer and lane: lamina Cauchy
    stresses into group.stress (nq, nt, 5, G), or, for the stiffness ``product``, the
    tangent times the field's strain; the point volumes points.DV become true volumes.
    share (nt,): layer weights over their sum. The response also writes
    group.stretch[p] (G,), the normal stretch of the fibre's mean strain (thesis Eq 3.31;
    the layers' bending parts cancel).

    Fl = q F R0^T maps the initial material frame R0 (group.axes0; rows: axes 1, 2, 3 =
    normal) to the current lamina frame q; its Green-Lagrange strain 1/2 (Fl^T Fl - I)
    gets the assumed-strain correction pulled back exactly, Fl^T (eps - eps0) Fl (eps:
    lamina strains after the tying, eps0: before; the tangent leaves it out). E33 then
    follows from zero normal stress (Eq 3.28), S~ from the law, and the Cauchy stress is
    its push-forward Fl S~ Fl^T / J in lamina components (Eq 3.27), J the true volume
    ratio (1 when incompressible). F is taken on the initial fibre lengths, so det Fl is
    not J: J / det Fl turns the point's volume into the true one, which every term of the
    virtual work then takes (Fl S~ Fl^T, the Kirchhoff stress, does not depend on Fl's
    normal column while S~_33 = 0, up to transverse shear). The tangent is pushed
    forward the same way (Eq 3.26), for the field's lamina strain pulled back."""
    group, points, scratch = fixed_lanes(group, points, scratch)
    M = scratch.M
    Fl, D, E, S, Cinv, dE, dS, tmp = M[0], M[1], M[2], M[3], M[4], M[5], M[6], M[7]
    law_work, det, pressure, volume, Emean = M[8:], scratch.det, scratch.pressure, scratch.volume, scratch.Emean
    Emean[:] = 0.0
    for k in range(share.shape[0]):
        congruence(points.Q[p, k], points.FP[p, k], group.axes0[p, k], Fl)
        det3(Fl, det)
        # 1/2 (Fl^T Fl - I) + Fl^T (eps - eps0) Fl = Fl^T (eps - eps0 + I/2) Fl - I/2
        D[:] = 0.0
        if not product:
            _add_strain_tensor(points.EPS[p, k], 1.0, D)
            _add_strain_tensor(points.EPS0[p, k], -1.0, D)
        for i in range(3):
            for lane in range(LANES):
                D[i, i, lane] += 0.5
        to_global(Fl, D, E)
        for i in range(3):
            for lane in range(LANES):
                E[i, i, lane] -= 0.5
        if not product:
            for i in range(3):
                for j in range(3):
                    for lane in range(LANES):
                        Emean[i, j, lane] += share[k] * E[i, j, lane]
        zero_normal_stress.stress(material, group.part[0], E, S, Cinv, pressure, volume, law_work)
        if product:  # the tangent at the current state times the field's strain
            D[:] = 0.0
            _add_strain_tensor(points.EPS[p, k], 1.0, D)
            to_global(Fl, D, dE)
            zero_normal_stress.tangent(material, group.part[0], E, Cinv, pressure, dE, dS, law_work)
            S = dS
        _push_forward(Fl, S, volume, tmp, group.stress[p, k])
        for lane in range(LANES):
            points.DV[p, k, lane] *= volume[lane] / det[lane]
    if not product:
        zero_normal_stress.normal_strain(material, group.part[0], Emean, group.stretch[p], law_work)


@njit(cache=True, error_model="numpy")
def convected_layer(material, group, points, scratch, p, k, share):
    """Techniques 2 and 3 at Gauss point p, layer k, every lane, after the stress
    increment: the normal strain increment from zero normal stress (added, times the
    layer's share, to group.stretch (nq, G)), Technique 2's push-forward by the step's
    stretch (material.push_forward), and the turn by the material's spin relative to the
    lamina frame."""
    group, points, scratch = fixed_lanes(group, points, scratch)
    normal, s5, M = scratch.normal, group.stress[p, k], scratch.M
    for lane in range(LANES):
        normal[lane] = -material.normal_ratio[group.part[0]] * (points.EPS[p, k, 0, lane] + points.EPS[p, k, 1, lane])
        group.stretch[p, lane] += share * normal[lane]
    if material.push_forward:
        _convect(s5, points.EPS[p, k], normal, M[0], M[1], M[2], scratch.det)
    _follow_material_spin(s5, points.LP[p, k], points.Q[p, k], points.G[p, k], M[0])


@njit(cache=True, error_model="numpy", inline="always")
def _follow_material_spin(s5, L, q, g, Ll):
    """Turn accumulated lamina stresses s5 (5, G) by the step's in-plane spin of the
    material relative to the lamina frame.

    The lamina frame follows the bisector of g_r and g_s (Hughes); on a distorted element
    stretched unevenly that bisector turns against the material, and stresses kept in
    it would turn with it (1.3% off the exact uniaxial response at lambda = 3.26 on a
    distorted patch). The material's spin is w = (L21 - L12) / 2 in lamina components
    (Jaumann), the frame's the mean of the turning rates of g_r and g_s,
    (a x L a) . e3 for a unit a; the stresses turn by the difference, exactly as a
    rotation. L (3, 3, G): the step's displacement gradient (global); q (3, 3, G): lamina
    frame; g (2, 3, G): g_r, g_s; Ll (3, 3, G) scratch."""
    to_lamina(q, L, Ll)
    for lane in range(LANES):
        spin = 0.5 * (Ll[1, 0, lane] - Ll[0, 1, lane])
        frame = 0.0
        for a in range(2):
            u0 = q[0, 0, lane] * g[a, 0, lane] + q[0, 1, lane] * g[a, 1, lane] + q[0, 2, lane] * g[a, 2, lane]
            u1 = q[1, 0, lane] * g[a, 0, lane] + q[1, 1, lane] * g[a, 1, lane] + q[1, 2, lane] * g[a, 2, lane]
            size = u0 * u0 + u1 * u1
            frame += 0.5 * (u0 * (Ll[1, 0, lane] * u0 + Ll[1, 1, lane] * u1)
                            - u1 * (Ll[0, 0, lane] * u0 + Ll[0, 1, lane] * u1)) / size
        angle = spin - frame
        c, s = np.cos(angle), np.sin(angle)
        s11, s22, s12 = s5[0, lane], s5[1, lane], s5[2, lane]
        s5[0, lane] = c * c * s11 - 2.0 * c * s * s12 + s * s * s22
        s5[1, lane] = s * s * s11 + 2.0 * c * s * s12 + c * c * s22
        s5[2, lane] = c * s * (s11 - s22) + (c * c - s * s) * s12
        s13, s23 = s5[3, lane], s5[4, lane]
        s5[3, lane] = c * s13 - s * s23
        s5[4, lane] = s * s13 + c * s23


@njit(cache=True, error_model="numpy", inline="always")
def _convect(s5, e5, normal, M, T, out, det):
    """Technique 2's push-forward of the accumulated stress (thesis Eqs 3.29-3.30) over
    one step: sigma <- M sigma M / det M, M = I + the step's lamina strain increment
    e5 (5, G) (11, 22, 2x12, 2x13, 2x23) with its normal part ``normal`` (G,) (zero
    normal stress). Only the stretch is applied: the lamina frame already turns with the
    body. M, T, out (3, 3, G), det (G,) scratch; s5 (5, G) updated."""
    M[:] = 0.0
    _add_strain_tensor(e5, 1.0, M)
    for lane in range(LANES):
        M[2, 2, lane] = normal[lane]
    for i in range(3):
        for lane in range(LANES):
            M[i, i, lane] += 1.0
    for lane in range(LANES):
        T[0, 0, lane], T[1, 1, lane], T[2, 2, lane] = s5[0, lane], s5[1, lane], 0.0
        T[0, 1, lane] = T[1, 0, lane] = s5[2, lane]
        T[0, 2, lane] = T[2, 0, lane] = s5[3, lane]
        T[1, 2, lane] = T[2, 1, lane] = s5[4, lane]
    det3(M, det)
    _push_forward(M, T, det, out, s5)


@njit(cache=True, error_model="numpy", inline="always")
def _add_strain_tensor(e5, scale, D):
    """D (3, 3, G) += scale x the lamina tensors of the strains e5 (5, G) (11, 22, 2x12,
    2x13, 2x23) (engineering shears halved); D[2, 2] untouched."""
    for lane in range(LANES):
        D[0, 0, lane] += scale * e5[0, lane]
        D[1, 1, lane] += scale * e5[1, lane]
        D[0, 1, lane] += 0.5 * scale * e5[2, lane]
        D[1, 0, lane] += 0.5 * scale * e5[2, lane]
        D[0, 2, lane] += 0.5 * scale * e5[3, lane]
        D[2, 0, lane] += 0.5 * scale * e5[3, lane]
        D[1, 2, lane] += 0.5 * scale * e5[4, lane]
        D[2, 1, lane] += 0.5 * scale * e5[4, lane]


@njit(cache=True, error_model="numpy", inline="always")
def _push_forward(Fl, S, det, tmp, out5):
    """out5 (5, G) = lamina components (11, 22, 12, 13, 23) of Fl S Fl^T / det; Fl, S,
    tmp (3, 3, G), det (G,)."""
    to_lamina(Fl, S, tmp)
    for lane in range(LANES):
        out5[0, lane] = tmp[0, 0, lane] / det[lane]
        out5[1, lane] = tmp[1, 1, lane] / det[lane]
        out5[2, lane] = tmp[0, 1, lane] / det[lane]
        out5[3, lane] = tmp[0, 2, lane] / det[lane]
        out5[4, lane] = tmp[1, 2, lane] / det[lane]
