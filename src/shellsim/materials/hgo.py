"""Incompressible Holzapfel-Gasser-Ogden law with fibre dispersion (Gasser, Ogden &
Holzapfel 2006, J. R. Soc. Interface 3:15-35, Eq 2.6-2.8; FEBio's and LS-DYNA MAT_295's
artery law):

    W = mu/2 (I1 - 3) + sum_f k1/(2 k2) (exp(k2 Ebar_f^2) - 1),
    Ebar_f = kappa (I1 - 3) + (1 - 3 kappa) (I4_f - 1),

two fibre families f at +-beta from material axis 1 in the 1-2 plane (axis 3 the lamina
normal), a_f = (cos beta, +-sin beta, 0), I4_f = a_f . C a_f; kappa from 0 (aligned
fibres) to 1/3 (isotropic dispersion). A family carries no load when it is not stretched
(I4_f <= 1). In Green-Lagrange strain, C = 2E + I, Ebar_f = 2 H_f : E with
H_f = kappa I + (1 - 3 kappa) a_f a_f, so with psi_f = k1 Ebar_f exp(k2 Ebar_f^2),

    S^w = mu I + sum_f 2 psi_f H_f,
    CC^w : dE = sum_f 4 k1 exp(k2 Ebar_f^2) (1 + 2 k2 Ebar_f^2) (H_f : dE) H_f.

Parameters (mu, k1 [stress], k2, kappa [-], cos beta, sin beta). Arrays (3, 3, G) carry one
strain per lane of an element group (:mod:`shellsim.element.lanes`).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from .axes import AnisotropicLaw, Axes
from ..table_types import NonNegative, Positive, Real
from ..lanes import LANES


class HolzapfelGasserOgden(AnisotropicLaw):
    """Incompressible Holzapfel-Gasser-Ogden with fibre dispersion (Gasser, Ogden &
    Holzapfel 2006): W = mu/2 (I1 - 3) + sum over the two families k1/(2 k2)
    (exp(k2 Ebar^2) - 1), Ebar = kappa (I1 - 3) + (1 - 3 kappa) (I4 - 1); the families at
    +-``beta_deg`` from material axis 1 (e.g. circumferential) toward axis 2, in the
    lamina; ``kappa`` the dispersion, 0 (aligned) to 1/3 (isotropic). A family in
    compression (I4 <= 1) carries no load."""

    model: Literal["hgo"]
    mu: Positive
    k1: Positive
    k2: Positive
    kappa: NonNegative = 0.0
    beta_deg: Real = Field(ge=0.0, le=90.0)
    density: Positive
    axes: Axes

    @model_validator(mode="after")
    def _dispersion(self) -> "HolzapfelGasserOgden":
        if self.kappa > 1.0 / 3.0:
            raise ValueError(f"kappa = {self.kappa} is beyond isotropic dispersion; expected 0 <= kappa <= 1/3")
        return self


INCOMPRESSIBLE = True
#: The deck's material models this law serves.
MODELS = (HolzapfelGasserOgden,)


def parameters(material) -> np.ndarray:
    """(mu, k1, k2, kappa, cos beta, sin beta) of a deck's HGO ``[material]``."""
    beta = math.radians(material.beta_deg)
    return np.array([material.mu, material.k1, material.k2, material.kappa, math.cos(beta), math.sin(beta)])


def fibres(params) -> np.ndarray:
    """(2, 2) the two families' directions in material axes 1, 2: (cos beta, +-sin beta)."""
    return np.array([[params[4], params[5]], [params[4], -params[5]]])


@njit(cache=True, error_model="numpy")
def _structure(params, family, H):
    """H (3, 3) = kappa I + (1 - 3 kappa) a a of fibre family 0 (+beta) or 1 (-beta);
    returns the family's direction a = (a0, a1, 0) as (a0, a1)."""
    kappa = params[3]
    a0, a1 = params[4], params[5] if family == 0 else -params[5]
    H[:] = 0.0
    for i in range(3):
        H[i, i] = kappa
    H[0, 0] += (1.0 - 3.0 * kappa) * a0 * a0
    H[1, 1] += (1.0 - 3.0 * kappa) * a1 * a1
    H[0, 1] += (1.0 - 3.0 * kappa) * a0 * a1
    H[1, 0] = H[0, 1]
    return a0, a1


@njit(cache=True, error_model="numpy")
def _fibre_strain(a0, a1, H, E, lane):
    """(Ebar = 2 H : E, whether the family along (a0, a1, 0) is stretched) of lane ``lane``
    of E (3, 3, G)."""
    stretched = a0 * a0 * E[0, 0, lane] + a1 * a1 * E[1, 1, lane] + 2.0 * a0 * a1 * E[0, 1, lane] > 0.0
    ebar = 0.0
    for i in range(3):
        for j in range(3):
            ebar += 2.0 * H[i, j] * E[i, j, lane]
    return ebar, stretched


@njit(cache=True, error_model="numpy")
def energy(params, E, W):
    """W (G,) of the strains E (3, 3, G)."""
    mu, k1, k2 = params[0], params[1], params[2]
    H = np.empty((3, 3))
    for lane in range(LANES):
        W[lane] = mu * (E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane])
    for family in range(2):
        a0, a1 = _structure(params, family, H)
        for lane in range(LANES):
            ebar, stretched = _fibre_strain(a0, a1, H, E, lane)
            if stretched:
                W[lane] += k1 / (2.0 * k2) * (np.exp(k2 * ebar * ebar) - 1.0)


@njit(cache=True, error_model="numpy")
def energy_stress(params, E, S):
    """S^w (3, 3, G) = dW/dE at E (3, 3, G)."""
    mu, k1, k2 = params[0], params[1], params[2]
    H = np.empty((3, 3))
    S[:] = 0.0
    for i in range(3):
        S[i, i, :] = mu
    for family in range(2):
        a0, a1 = _structure(params, family, H)
        for lane in range(LANES):
            ebar, stretched = _fibre_strain(a0, a1, H, E, lane)
            if stretched:
                psi = k1 * ebar * np.exp(k2 * ebar * ebar)
                for i in range(3):
                    for j in range(3):
                        S[i, j, lane] += 2.0 * psi * H[i, j]


@njit(cache=True, error_model="numpy")
def energy_tangent(params, E, dE, dS):
    """dS^w (3, 3, G) = CC^w : dE at E, dE (3, 3, G)."""
    k1, k2 = params[1], params[2]
    H = np.empty((3, 3))
    dS[:] = 0.0
    for family in range(2):
        a0, a1 = _structure(params, family, H)
        for lane in range(LANES):
            ebar, stretched = _fibre_strain(a0, a1, H, E, lane)
            if stretched:
                dEbar = 0.0
                for i in range(3):
                    for j in range(3):
                        dEbar += 2.0 * H[i, j] * dE[i, j, lane]
                dpsi = k1 * np.exp(k2 * ebar * ebar) * (1.0 + 2.0 * k2 * ebar * ebar) * dEbar
                for i in range(3):
                    for j in range(3):
                        dS[i, j, lane] += 2.0 * dpsi * H[i, j]
