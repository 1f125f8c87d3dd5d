"""A hyperelastic law under zero normal stress (thesis Technique 1, 3.10.1), in the
material frame of the points of an element group's lanes: axis 3 is the lamina normal of
the initial configuration, E (3, 3, G) the Green-Lagrange strain in that frame.

Incompressible laws, by the determinant condition (thesis Eq 3.28): with C = 2E + I,
det C is linear in C33, so det C = J^2 = 1 fixes E33 from the other eight components.
Substituting E33 = g(E_other) into W gives the reduced energy W~ whose derivatives are
the stresses (thesis 3.10.1, note 2):

    dg/dE_ij = -Cinv_ij / Cinv_33,  so  S~ = S^w - p Cinv,  p = S^w_33 / Cinv_33,

S^w = dW/dE at the solved strain; S~_33 = 0 by construction. Its tangent, the directional
derivative dS~ = d/de S~(E + e dE) with dE_33 following the constraint, is

    dE_33 = -sum_(ij != 33) Cinv_ij dE_ij / Cinv_33,
    dCinv = -2 Cinv dE Cinv,
    dp = (dS^w_33 - p dCinv_33) / Cinv_33,
    dS~ = CC^w : dE - dp Cinv - p dCinv.

Compressible laws (St. Venant-Kirchhoff) whose S^w_33 is linear in E33: S_33 = 0 fixes
E33 = -S^w_33(E33 = 0) / CC^w_3333 and dE33 = -(CC^w : dE)_33 / CC^w_3333 for a dE with
no normal part; S~ = S^w, no pressure, J = sqrt(det C).

The law's own S^w and CC^w : dE are the functions ``material`` holds for each part of
the model (the kernels' :class:`shellsim.bundles.Material`: energy_stress,
energy_tangent, params, incompressible, by part); ``part`` picks the group's. Scratch
``work`` (3, 3, 3, G).

The functions are inlined into their caller, the stress update
(:func:`shellsim.element.stress_update.hyperelastic_layers`), whose work arrays have their
trailing lengths fixed in the compiled code, so that their lane loops vectorise
(:mod:`shellsim.fixed_shape`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..lanes import LANES
from ..tensor3 import det3, to_lamina


@njit(cache=True, error_model="numpy", inline="always")
def normal_strain(material, part, E, stretch, work):
    """Set E[2, 2] (3, 3, G) for zero normal stress; stretch (G,) = sqrt(1 + 2 E33), the
    normal stretch."""
    if material.incompressible[part]:
        solve_normal_strain(E, stretch)
        return
    S, unit, dS = work[0], work[1], work[2]
    unit[:] = 0.0
    for lane in range(LANES):
        E[2, 2, lane] = 0.0
        unit[2, 2, lane] = 1.0
    material.energy_stress[part](material.params[part], E, S)
    material.energy_tangent[part](material.params[part], E, unit, dS)
    for lane in range(LANES):
        E[2, 2, lane] = -S[2, 2, lane] / dS[2, 2, lane]
        stretch[lane] = np.sqrt(1.0 + 2.0 * E[2, 2, lane])


@njit(cache=True, error_model="numpy", inline="always")
def solve_normal_strain(E, stretch):
    """Set E[2, 2] so that det(2E + I) = 1 (thesis Eq 3.28), E (3, 3, G).
    det C = C33 (C11 C22 - C12^2) + (terms free of C33), so the solution is direct.
    stretch (G,) = sqrt(C33)."""
    for lane in range(LANES):
        c11, c22 = 1.0 + 2.0 * E[0, 0, lane], 1.0 + 2.0 * E[1, 1, lane]
        c12, c13, c23 = 2.0 * E[0, 1, lane], 2.0 * E[0, 2, lane], 2.0 * E[1, 2, lane]
        minor = c11 * c22 - c12 * c12
        c33 = (1.0 - 2.0 * c12 * c13 * c23 + c11 * c23 * c23 + c22 * c13 * c13) / minor
        E[2, 2, lane] = 0.5 * (c33 - 1.0)
        stretch[lane] = np.sqrt(c33)


@njit(cache=True, error_model="numpy", inline="always")
def stress(material, part, E, S, Cinv, pressure, volume, work):
    """Second Piola stress S~ (3, 3, G) under zero normal stress (S33 = 0).

    E (3, 3, G): strains with any E33, which is replaced by the solution. Writes S, Cinv
    (3, 3, G) = (2E + I)^-1 (incompressible; else untouched), pressure (G,) the
    constraint's Lagrange multiplier p (0 for a compressible law) and volume (G,) the
    volume ratio J (1 for an incompressible law)."""
    normal_strain(material, part, E, volume, work)
    if material.incompressible[part]:
        _inverse_stretch(E, Cinv)
        material.energy_stress[part](material.params[part], E, S)
        for lane in range(LANES):
            pressure[lane] = S[2, 2, lane] / Cinv[2, 2, lane]
            volume[lane] = 1.0
        for i in range(3):
            for j in range(3):
                for lane in range(LANES):
                    S[i, j, lane] -= pressure[lane] * Cinv[i, j, lane]
    else:
        material.energy_stress[part](material.params[part], E, S)
        C = work[0]
        for i in range(3):
            for j in range(3):
                for lane in range(LANES):
                    C[i, j, lane] = 2.0 * E[i, j, lane] + (1.0 if i == j else 0.0)
        det3(C, volume)
        for lane in range(LANES):
            volume[lane] = np.sqrt(volume[lane])
            pressure[lane] = 0.0
    for lane in range(LANES):
        S[2, 2, lane] = 0.0


@njit(cache=True, error_model="numpy", inline="always")
def tangent(material, part, E, Cinv, pressure, dE, dS, work):
    """dS~ (3, 3, G) for strain directions dE (3, 3, G) at a solved state (E, Cinv,
    pressure from :func:`stress`). dE[2, 2] is overwritten by the constraint's value."""
    energy_tangent, params = material.energy_tangent[part], material.params[part]
    if material.incompressible[part]:
        for lane in range(LANES):
            acc = 0.0
            for i in range(3):
                for j in range(3):
                    if i != 2 or j != 2:
                        acc += Cinv[i, j, lane] * dE[i, j, lane]
            dE[2, 2, lane] = -acc / Cinv[2, 2, lane]
        CdC = work[0]  # dCinv = -2 Cinv dE Cinv
        to_lamina(Cinv, dE, CdC)
        energy_tangent(params, E, dE, dS)
        for lane in range(LANES):
            dp = (dS[2, 2, lane] + 2.0 * pressure[lane] * CdC[2, 2, lane]) / Cinv[2, 2, lane]
            for i in range(3):
                for j in range(3):
                    dS[i, j, lane] -= dp * Cinv[i, j, lane] - 2.0 * pressure[lane] * CdC[i, j, lane]
    else:
        unit, normal = work[1], work[2]
        unit[:] = 0.0
        for lane in range(LANES):
            dE[2, 2, lane] = 0.0
            unit[2, 2, lane] = 1.0
        energy_tangent(params, E, unit, normal)
        energy_tangent(params, E, dE, dS)
        # the tangent is linear in dE: adding dE33 adds dE33 times the unit's response
        for lane in range(LANES):
            dE[2, 2, lane] = -dS[2, 2, lane] / normal[2, 2, lane]
            for i in range(3):
                for j in range(3):
                    dS[i, j, lane] += dE[2, 2, lane] * normal[i, j, lane]
    for lane in range(LANES):
        dS[2, 2, lane] = 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _inverse_stretch(E, out):
    """out (3, 3, G) = (2E + I)^-1 of solved strains E (3, 3, G) of an incompressible law,
    whose determinant is 1: the inverse is the adjugate."""
    for lane in range(LANES):
        c11, c22, c33 = 1.0 + 2.0 * E[0, 0, lane], 1.0 + 2.0 * E[1, 1, lane], 1.0 + 2.0 * E[2, 2, lane]
        c12, c13, c23 = 2.0 * E[0, 1, lane], 2.0 * E[0, 2, lane], 2.0 * E[1, 2, lane]
        out[0, 0, lane] = c22 * c33 - c23 * c23
        out[1, 1, lane] = c11 * c33 - c13 * c13
        out[2, 2, lane] = c11 * c22 - c12 * c12
        out[0, 1, lane] = out[1, 0, lane] = c13 * c23 - c12 * c33
        out[0, 2, lane] = out[2, 0, lane] = c12 * c23 - c13 * c22
        out[1, 2, lane] = out[2, 1, lane] = c12 * c13 - c11 * c23
