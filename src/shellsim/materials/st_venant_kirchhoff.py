"""St. Venant-Kirchhoff, the linear elastic material at large strain (Technique 1 with
``model = "linear_elastic"``); compressible.

    W = lambda/2 (tr E)^2 + mu sum_ij k_ij E_ij^2,
    S^w = lambda tr E I + 2 mu k_ij E_ij,  CC^w : dE = S^w(dE)  (linear in E),

with k_ij = kappa, the transverse shear factor of the small-strain law, for the shears
13 and 23 and 1 otherwise. Zero normal stress is S_33 = 0, which fixes
E_33 = -lambda (E_11 + E_22) / (lambda + 2 mu) (:mod:`shellsim.materials.zero_normal_stress`).

Parameters (lambda, mu [stress], kappa [-]). Arrays (3, 3, G) carry one strain per lane
of an element group (:mod:`shellsim.lanes`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..lanes import LANES
from .linear import SHEAR_FACTOR, LinearElastic

INCOMPRESSIBLE = False
#: The deck's material models this law serves (under Technique 1).
MODELS = (LinearElastic,)


def parameters(material) -> np.ndarray:
    """(lambda, mu, kappa) of a deck's linear elastic ``[material]`` (E, nu)."""
    lam = material.E * material.nu / ((1 + material.nu) * (1 - 2 * material.nu))
    return np.array([lam, material.E / (2 * (1 + material.nu)), SHEAR_FACTOR])


@njit(cache=True, error_model="numpy")
def _shear(params, i, j):
    """k_ij: kappa for the transverse shears (one index 3, the other not), else 1."""
    return params[2] if (i == 2) != (j == 2) else 1.0


@njit(cache=True, error_model="numpy")
def energy(params, E, W):
    """W (G,) of the strains E (3, 3, G)."""
    lam, mu = params[0], params[1]
    for lane in range(LANES):
        trace = E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane]
        W[lane] = 0.5 * lam * trace * trace
        for i in range(3):
            for j in range(3):
                W[lane] += mu * _shear(params, i, j) * E[i, j, lane] * E[i, j, lane]


@njit(cache=True, error_model="numpy")
def energy_stress(params, E, S):
    """S^w (3, 3, G) = dW/dE at E (3, 3, G)."""
    lam, mu = params[0], params[1]
    for lane in range(LANES):
        trace = E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane]
        for i in range(3):
            for j in range(3):
                S[i, j, lane] = 2.0 * mu * _shear(params, i, j) * E[i, j, lane]
            S[i, i, lane] += lam * trace


@njit(cache=True, error_model="numpy")
def energy_tangent(params, E, dE, dS):
    """dS^w (3, 3, G) = CC^w : dE, the stress of dE (3, 3, G) (the law is linear)."""
    energy_stress(params, dE, dS)
