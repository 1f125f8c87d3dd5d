"""Incompressible Guccione (thesis Eq 4.2; LS-DYNA MAT_128 with C, B1, B2, B3 = C1..C4).

    W = C1/2 (exp Q - 1),  Q = sum_ij b_ij E_ij^2,

in the material axes (1 = fibre, 2 = cross-fibre, 3 = lamina normal), with b_11 = C2
along the fibre, b_12 = b_13 = C4 for the fibre shears and C3 for the rest
(b_22 = b_33 = b_23). With dQ/dE_ij = 2 b_ij E_ij,

    S^w_ij = C1 e^Q b_ij E_ij,
    (CC^w : dE)_ij = C1 e^Q b_ij (dE_ij + E_ij dQ),  dQ = 2 sum_kl b_kl E_kl dE_kl.

Parameters (C1 [stress], C2, C3, C4 [-]). Arrays (3, 3, G) carry one strain per lane of an
element group (:mod:`shellsim.lanes`).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit

from .axes import AnisotropicLaw, Axes
from ..table_types import Positive
from ..lanes import LANES


class Guccione(AnisotropicLaw):
    """Incompressible Guccione (thesis Eq 4.2): W = C1/2 (exp Q - 1),
    Q = C2 E11^2 + C3 (E22^2 + E33^2 + 2 E23^2) + C4 (2 E12^2 + 2 E13^2)
    in material axes (1 = fibre, e.g. circumferential; 2 = cross-fibre; 3 = normal)."""

    model: Literal["guccione"]
    C1: Positive
    C2: Positive
    C3: Positive
    C4: Positive
    density: Positive
    axes: Axes


INCOMPRESSIBLE = True
#: The deck's material models this law serves.
MODELS = (Guccione,)


def parameters(material) -> np.ndarray:
    """(C1, C2, C3, C4) of a deck's Guccione ``[material]``."""
    return np.array([material.C1, material.C2, material.C3, material.C4])


def fibres(params) -> np.ndarray:
    """(1, 2) the fibre's direction in material axes 1, 2: axis 1."""
    return np.array([[1.0, 0.0]])


@njit(cache=True, error_model="numpy")
def _weight(params, i, j):
    """b_ij: C2 along the fibre (11), C4 for the fibre shears (12, 13), C3 for the rest."""
    if i == 0 and j == 0:
        return params[1]
    if i == 0 or j == 0:
        return params[3]
    return params[2]


@njit(cache=True, error_model="numpy")
def _exponent(params, E, lane):
    """Q = sum_ij b_ij E_ij^2 of lane ``lane`` of E (3, 3, G)."""
    Q = 0.0
    for i in range(3):
        for j in range(3):
            Q += _weight(params, i, j) * E[i, j, lane] * E[i, j, lane]
    return Q


@njit(cache=True, error_model="numpy")
def energy(params, E, W):
    """W (G,) of the strains E (3, 3, G)."""
    for lane in range(LANES):
        W[lane] = 0.5 * params[0] * (np.exp(_exponent(params, E, lane)) - 1.0)


@njit(cache=True, error_model="numpy")
def energy_stress(params, E, S):
    """S^w (3, 3, G) = dW/dE at E (3, 3, G)."""
    for lane in range(LANES):
        scale = params[0] * np.exp(_exponent(params, E, lane))
        for i in range(3):
            for j in range(3):
                S[i, j, lane] = scale * _weight(params, i, j) * E[i, j, lane]


@njit(cache=True, error_model="numpy")
def energy_tangent(params, E, dE, dS):
    """dS^w (3, 3, G) = CC^w : dE at E, dE (3, 3, G)."""
    for lane in range(LANES):
        scale = params[0] * np.exp(_exponent(params, E, lane))
        dQ = 0.0
        for i in range(3):
            for j in range(3):
                dQ += 2.0 * _weight(params, i, j) * E[i, j, lane] * dE[i, j, lane]
        for i in range(3):
            for j in range(3):
                dS[i, j, lane] = scale * _weight(params, i, j) * (dE[i, j, lane] + E[i, j, lane] * dQ)
