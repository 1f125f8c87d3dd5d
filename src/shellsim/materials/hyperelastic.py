"""Hyperelastic laws under zero normal stress (thesis Technique 1, 3.10.1).

Everything here works in the material frame of one integration point: axis 3 is the
lamina normal of the initial configuration, axes 1 and 2 lie in the lamina (for an
anisotropic law, 1 is the fibre direction). E (3, 3) is the Green-Lagrange strain in that
frame, W its strain energy per unit initial volume.

Zero normal stress by the determinant condition (thesis Eq 3.28): with C = 2E + I,
det C is linear in C33, so det C = J^2 = 1 fixes E33 from the other eight components.
Substituting E33 = g(E_other) into W gives the reduced energy W~ whose derivatives are
the stresses (thesis 3.10.1, note 2):

    dg/dE_ij = -Cinv_ij / Cinv_33,  so  S~ = S^w - p Cinv,  p = S^w_33 / Cinv_33,

S^w = dW/dE at the solved strain; S~_33 = 0 by construction. Its tangent, the directional
derivative dS~ = d/de S~(E + e dE) with dE_33 following the constraint, is

    dE_33 = -sum_(ij != 33) Cinv_ij dE_ij / Cinv_33,
    dCinv = -2 Cinv dE Cinv,
    dp = (dS^w_33 - p dCinv_33) / Cinv_33,
    dS~ = CC^w : dE - dp Cinv - p dCinv,

with CC^w : dE the directional derivative of S^w (closed form per law below).

Laws (params (4,)):
- MOONEY_RIVLIN (C1, C2, -, -): W = C1 (I1 - 3) + C2 (I2 - 3) (neo-Hookean: C2 = 0);
  S^w = 2 (C1 + C2 I1) I - 2 C2 C;  CC^w : dE = 4 C2 (tr dE I - dE).
- GUCCIONE (C1, C2, C3, C4): W = C1/2 (exp Q - 1), Q = sum_ij b_ij E_ij^2 with
  b_11 = C2, b_22 = b_33 = b_23 = C3, b_12 = b_13 = C4 (thesis Eq 4.2);
  S^w_ij = C1 e^Q b_ij E_ij;  (CC^w : dE)_ij = C1 e^Q b_ij (dE_ij + E_ij dQ),
  dQ = 2 sum_kl b_kl E_kl dE_kl.
- ST_VENANT_KIRCHHOFF (lambda, mu, kappa, -): compressible, S = lambda tr E I + 2 mu E
  with the transverse shears scaled by kappa (as the small-strain law); zero normal
  stress fixes E33 = -lambda (E11 + E22) / (lambda + 2 mu) instead of J = 1, and there
  is no pressure: S~ = S^w, dS~ = CC^w : dE with dE33 following.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..tensor3 import congruence

#: Law codes of :func:`stress`; LINEAR marks the small-strain path (no law here).
LINEAR, MOONEY_RIVLIN, GUCCIONE, ST_VENANT_KIRCHHOFF = -1, 0, 1, 2


@njit(cache=True, error_model="numpy")
def _guccione_weight(params, i, j):
    """Guccione's b_ij from params (C1, C2, C3, C4): C2 along the fibre (11), C4 for the
    fibre shears (12, 13), C3 for the rest."""
    if i == 0 and j == 0:
        return params[1]
    if i == 0 or j == 0:
        return params[3]
    return params[2]


@njit(cache=True, error_model="numpy")
def _guccione_exponent(params, E):
    """Q = sum_ij b_ij E_ij^2 of E (3, 3)."""
    Q = 0.0
    for i in range(3):
        for j in range(3):
            Q += _guccione_weight(params, i, j) * E[i, j] * E[i, j]
    return Q


@njit(cache=True, error_model="numpy")
def strain_energy(law, params, E):
    """W (per unit initial volume) of the full strain E (3, 3); the constraint is not
    applied here (tests use it to check the stresses)."""
    if law == GUCCIONE:
        return 0.5 * params[0] * (np.exp(_guccione_exponent(params, E)) - 1.0)
    if law == ST_VENANT_KIRCHHOFF:
        trace = E[0, 0] + E[1, 1] + E[2, 2]
        energy = 0.5 * params[0] * trace * trace
        for i in range(3):
            for j in range(3):
                shear = params[2] if (i == 2) != (j == 2) else 1.0
                energy += params[1] * shear * E[i, j] * E[i, j]
        return energy
    I1 = 3.0 + 2.0 * (E[0, 0] + E[1, 1] + E[2, 2])
    trC2 = 0.0
    for i in range(3):
        for j in range(3):
            c = 2.0 * E[i, j] + (1.0 if i == j else 0.0)
            trC2 += c * c
    I2 = 0.5 * (I1 * I1 - trC2)
    return params[0] * (I1 - 3.0) + params[1] * (I2 - 3.0)


@njit(cache=True, error_model="numpy")
def _energy_stress(law, params, E, S):
    """S^w = dW/dE (3, 3) at E, without the constraint's pressure."""
    if law == GUCCIONE:
        scale = params[0] * np.exp(_guccione_exponent(params, E))
        for i in range(3):
            for j in range(3):
                S[i, j] = scale * _guccione_weight(params, i, j) * E[i, j]
        return
    if law == ST_VENANT_KIRCHHOFF:
        _svk(params, E, S)
        return
    I1 = 3.0 + 2.0 * (E[0, 0] + E[1, 1] + E[2, 2])
    for i in range(3):
        for j in range(3):
            S[i, j] = -2.0 * params[1] * (2.0 * E[i, j] + (1.0 if i == j else 0.0))
        S[i, i] += 2.0 * (params[0] + params[1] * I1)


@njit(cache=True, error_model="numpy")
def _energy_tangent(law, params, E, dE, dS):
    """dS^w = CC^w : dE (3, 3), the directional derivative of :func:`_energy_stress`."""
    if law == GUCCIONE:
        scale = params[0] * np.exp(_guccione_exponent(params, E))
        dQ = 0.0
        for i in range(3):
            for j in range(3):
                dQ += 2.0 * _guccione_weight(params, i, j) * E[i, j] * dE[i, j]
        for i in range(3):
            for j in range(3):
                dS[i, j] = scale * _guccione_weight(params, i, j) * (dE[i, j] + E[i, j] * dQ)
        return
    if law == ST_VENANT_KIRCHHOFF:
        _svk(params, dE, dS)
        return
    trace = dE[0, 0] + dE[1, 1] + dE[2, 2]
    for i in range(3):
        for j in range(3):
            dS[i, j] = -4.0 * params[1] * dE[i, j]
        dS[i, i] += 4.0 * params[1] * trace


@njit(cache=True, error_model="numpy")
def _svk(params, E, S):
    """S = lambda tr E I + 2 mu E, transverse shears times kappa (linear in E)."""
    lam, mu, kappa = params[0], params[1], params[2]
    trace = E[0, 0] + E[1, 1] + E[2, 2]
    for i in range(3):
        for j in range(3):
            shear = kappa if (i == 2) != (j == 2) else 1.0
            S[i, j] = 2.0 * mu * shear * E[i, j]
        S[i, i] += lam * trace


@njit(cache=True, error_model="numpy")
def normal_strain(law, params, E):
    """Set E[2, 2] for zero normal stress: from J = 1 for the incompressible laws, from
    S33 = 0 for St. Venant-Kirchhoff. Returns the normal stretch sqrt(1 + 2 E33)."""
    if law == ST_VENANT_KIRCHHOFF:
        E[2, 2] = -params[0] * (E[0, 0] + E[1, 1]) / (params[0] + 2.0 * params[1])
        return np.sqrt(1.0 + 2.0 * E[2, 2])
    return solve_normal_strain(E, 1.0)


@njit(cache=True, error_model="numpy")
def volume_ratio(law, E):
    """J = sqrt(det(2E + I)) of a solved strain: 1 for the incompressible laws (the
    constraint made it so), computed for St. Venant-Kirchhoff."""
    if law != ST_VENANT_KIRCHHOFF:
        return 1.0
    c11, c22, c33 = 1.0 + 2.0 * E[0, 0], 1.0 + 2.0 * E[1, 1], 1.0 + 2.0 * E[2, 2]
    c12, c13, c23 = 2.0 * E[0, 1], 2.0 * E[0, 2], 2.0 * E[1, 2]
    return np.sqrt(c11 * (c22 * c33 - c23 * c23) - c12 * (c12 * c33 - c23 * c13) + c13 * (c12 * c23 - c22 * c13))


@njit(cache=True, error_model="numpy")
def _inverse_stretch(E, out):
    """out = (2E + I)^-1 for a solved strain E (3, 3) of an incompressible law, whose
    determinant is 1: the inverse is the adjugate."""
    c11, c22, c33 = 1.0 + 2.0 * E[0, 0], 1.0 + 2.0 * E[1, 1], 1.0 + 2.0 * E[2, 2]
    c12, c13, c23 = 2.0 * E[0, 1], 2.0 * E[0, 2], 2.0 * E[1, 2]
    out[0, 0] = c22 * c33 - c23 * c23
    out[1, 1] = c11 * c33 - c13 * c13
    out[2, 2] = c11 * c22 - c12 * c12
    out[0, 1] = out[1, 0] = c13 * c23 - c12 * c33
    out[0, 2] = out[2, 0] = c12 * c23 - c13 * c22
    out[1, 2] = out[2, 1] = c12 * c13 - c11 * c23


@njit(cache=True, error_model="numpy")
def solve_normal_strain(E, J):
    """Set E[2, 2] so that det(2E + I) = J^2 (thesis Eq 3.28; J = 1: incompressible).
    det C = C33 (C11 C22 - C12^2) + (terms free of C33), so the solution is direct.
    Returns the normal stretch sqrt(C33)."""
    c11, c22 = 1.0 + 2.0 * E[0, 0], 1.0 + 2.0 * E[1, 1]
    c12, c13, c23 = 2.0 * E[0, 1], 2.0 * E[0, 2], 2.0 * E[1, 2]
    minor = c11 * c22 - c12 * c12
    c33 = (J * J - 2.0 * c12 * c13 * c23 + c11 * c23 * c23 + c22 * c13 * c13) / minor
    E[2, 2] = 0.5 * (c33 - 1.0)
    return np.sqrt(c33)


@njit(cache=True, error_model="numpy")
def stress(law, params, E, S, Cinv):
    """Second Piola stress S~ (3, 3) under zero normal stress, in the material frame.

    E (3, 3): strain with any E33; E33 is replaced by the incompressible solution. Writes
    S (S33 = 0) and Cinv (3, 3), (2E + I)^-1 (zeros for St. Venant-Kirchhoff, whose
    tangent needs none). Returns the pressure p (the constraint's
    Lagrange multiplier; 0 for St. Venant-Kirchhoff, which has none)."""
    normal_strain(law, params, E)
    if law == ST_VENANT_KIRCHHOFF:
        _svk(params, E, S)
        S[2, 2] = 0.0
        Cinv[:] = 0.0
        return 0.0
    _inverse_stretch(E, Cinv)
    _energy_stress(law, params, E, S)
    p = S[2, 2] / Cinv[2, 2]
    for i in range(3):
        for j in range(3):
            S[i, j] -= p * Cinv[i, j]
    S[2, 2] = 0.0
    return p


@njit(cache=True, error_model="numpy")
def tangent(law, params, E, Cinv, p, dE, dS):
    """dS~ (3, 3) for a strain direction dE (3, 3) at a solved state (E, Cinv, p from
    :func:`stress`). dE[2, 2] is overwritten by the constraint's value."""
    if law == ST_VENANT_KIRCHHOFF:
        normal_strain(law, params, dE)
        _svk(params, dE, dS)
        dS[2, 2] = 0.0
        return
    acc = 0.0
    for i in range(3):
        for j in range(3):
            if i != 2 or j != 2:
                acc += Cinv[i, j] * dE[i, j]
    dE[2, 2] = -acc / Cinv[2, 2]
    CdC = np.empty((3, 3))  # dCinv = -2 Cinv dE Cinv
    congruence(Cinv, dE, Cinv, CdC)
    _energy_tangent(law, params, E, dE, dS)
    dp = (dS[2, 2] + 2.0 * p * CdC[2, 2]) / Cinv[2, 2]
    for i in range(3):
        for j in range(3):
            dS[i, j] -= dp * Cinv[i, j] - 2.0 * p * CdC[i, j]
    dS[2, 2] = 0.0
