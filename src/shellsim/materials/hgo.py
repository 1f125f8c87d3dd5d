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

With kappa > 0 the sharp exclusion makes the energy itself jump where I4 crosses 1 (Ebar
= kappa (I1 - 3) there), and with k1 >> mu the stiffness jumps a hundredfold: Newton then
cycles between a family's two states. ``switch_sharpness`` k replaces the exclusion by the
smooth step chi = 1 / (1 + exp(-k (I4 - 1))) of svMultiPhysics' Holzapfel-Ogden law
(svFSI issue 55; k = 100 there), W_f = chi Phi_f, Phi_f = k1/(2 k2) (exp(k2 Ebar_f^2) - 1).
With x_f = I4_f - 1 = 2 A_f : E, A_f = a_f a_f,

    S_f = 2 chi' Phi_f A_f + 2 chi psi_f H_f,
    CC_f : dE = 2 (chi'' Phi_f dx + chi' psi_f dEbar) A_f + 2 (chi' psi_f dx + chi dpsi_f) H_f,

dx = 2 A_f : dE, dEbar = 2 H_f : dE, dpsi_f = k1 exp(k2 Ebar^2) (1 + 2 k2 Ebar^2) dEbar,
chi' = k chi (1 - chi), chi'' = k chi' (1 - 2 chi).

Parameters (mu, k1 [stress], k2, kappa [-], cos beta, sin beta, k [-], 0 for the sharp
exclusion). Arrays (3, 3, G) carry one strain per lane of an element group
(:mod:`shellsim.lanes`).
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
    compression (I4 <= 1) carries no load; with ``switch_sharpness`` k it is switched on
    smoothly instead, by 1 / (1 + exp(-k (I4 - 1))) (svMultiPhysics' smooth step, k = 100
    there), which static Newton needs when k1 >> mu or kappa > 0."""

    model: Literal["hgo"]
    mu: Positive
    k1: Positive
    k2: Positive
    kappa: NonNegative = 0.0
    beta_deg: Real = Field(ge=0.0, le=90.0)
    switch_sharpness: Positive | None = None
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
    """(mu, k1, k2, kappa, cos beta, sin beta, switch sharpness or 0) of a deck's HGO
    ``[material]``."""
    beta = math.radians(material.beta_deg)
    return np.array([material.mu, material.k1, material.k2, material.kappa, math.cos(beta), math.sin(beta),
                     material.switch_sharpness or 0.0])


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
    """(Ebar = 2 H : E, x = I4 - 1 = 2 a.E a) of the family along (a0, a1, 0) at lane
    ``lane`` of E (3, 3, G); of a strain change dE, (dEbar, dx)."""
    ebar = 0.0
    for i in range(3):
        for j in range(3):
            ebar += H[i, j] * E[i, j, lane]
    along = a0 * a0 * E[0, 0, lane] + a1 * a1 * E[1, 1, lane] + 2.0 * a0 * a1 * E[0, 1, lane]
    return 2.0 * ebar, 2.0 * along


@njit(cache=True, error_model="numpy")
def _add_along(a0, a1, factor, S, lane):
    """S[:, :, lane] += factor A, A = a a the family's structure along (a0, a1, 0)."""
    S[0, 0, lane] += factor * a0 * a0
    S[1, 1, lane] += factor * a1 * a1
    S[0, 1, lane] += factor * a0 * a1
    S[1, 0, lane] += factor * a0 * a1


@njit(cache=True, error_model="numpy")
def _switch(sharpness, x):
    """(chi, chi', chi'') of the family's switch at x = I4 - 1: the step x > 0 when
    ``sharpness`` is 0, else 1 / (1 + exp(-sharpness x)) and its derivatives in x."""
    if sharpness == 0.0:
        return (1.0 if x > 0.0 else 0.0), 0.0, 0.0
    chi = 1.0 / (1.0 + np.exp(-sharpness * x))  # exp overflows to inf far in compression: chi = 0
    dchi = sharpness * chi * (1.0 - chi)
    return chi, dchi, sharpness * dchi * (1.0 - 2.0 * chi)


@njit(cache=True, error_model="numpy")
def energy(params, E, W):
    """W (G,) of the strains E (3, 3, G)."""
    mu, k1, k2, sharpness = params[0], params[1], params[2], params[6]
    H = np.empty((3, 3))
    for lane in range(LANES):
        W[lane] = mu * (E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane])
    for family in range(2):
        a0, a1 = _structure(params, family, H)
        for lane in range(LANES):
            ebar, x = _fibre_strain(a0, a1, H, E, lane)
            chi = _switch(sharpness, x)[0]
            if chi > 0.0:
                W[lane] += chi * k1 / (2.0 * k2) * (np.exp(k2 * ebar * ebar) - 1.0)


@njit(cache=True, error_model="numpy")
def energy_stress(params, E, S):
    """S^w (3, 3, G) = dW/dE at E (3, 3, G)."""
    mu, k1, k2, sharpness = params[0], params[1], params[2], params[6]
    H = np.empty((3, 3))
    S[:] = 0.0
    for i in range(3):
        S[i, i, :] = mu
    for family in range(2):
        a0, a1 = _structure(params, family, H)
        for lane in range(LANES):
            ebar, x = _fibre_strain(a0, a1, H, E, lane)
            chi, dchi, _ = _switch(sharpness, x)
            if chi > 0.0:
                growth = np.exp(k2 * ebar * ebar)
                psi = k1 * ebar * growth
                for i in range(3):
                    for j in range(3):
                        S[i, j, lane] += 2.0 * chi * psi * H[i, j]
                if sharpness > 0.0:  # the smooth switch's own share, along the family
                    _add_along(a0, a1, 2.0 * dchi * k1 / (2.0 * k2) * (growth - 1.0), S, lane)


@njit(cache=True, error_model="numpy")
def energy_tangent(params, E, dE, dS):
    """dS^w (3, 3, G) = CC^w : dE at E, dE (3, 3, G)."""
    k1, k2, sharpness = params[1], params[2], params[6]
    H = np.empty((3, 3))
    dS[:] = 0.0
    for family in range(2):
        a0, a1 = _structure(params, family, H)
        for lane in range(LANES):
            ebar, x = _fibre_strain(a0, a1, H, E, lane)
            chi, dchi, ddchi = _switch(sharpness, x)
            if chi > 0.0:
                growth = np.exp(k2 * ebar * ebar)
                dEbar, dx = _fibre_strain(a0, a1, H, dE, lane)
                psi = k1 * ebar * growth
                dpsi = k1 * growth * (1.0 + 2.0 * k2 * ebar * ebar) * dEbar
                on_H = 2.0 * (chi * dpsi + dchi * psi * dx)
                for i in range(3):
                    for j in range(3):
                        dS[i, j, lane] += on_H * H[i, j]
                if sharpness > 0.0:  # the smooth switch's own share, along the family
                    phi = k1 / (2.0 * k2) * (growth - 1.0)
                    _add_along(a0, a1, 2.0 * (ddchi * phi * dx + dchi * psi * dEbar), dS, lane)
