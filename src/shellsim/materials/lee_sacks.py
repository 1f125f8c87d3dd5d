"""Incompressible Lee-Sacks law of heart-valve leaflets (Lee, Amini, Gorman, Gorman & Sacks
2014, J. Biomech. 47:2055-2063, Eq 1; svMultiPhysics' shell law ``lee_sacks``):

    W = c0/2 (I1 - 3) + c1/2 [delta (exp(c2 (I1 - 3)^2) - 1)
                              + (1 - delta) (exp(c3 (I4 - 1)^2) - 1)],

one fibre family along a = (cos beta, sin beta, 0), beta from material axis 1 toward axis
2 in the lamina (axis 3 the normal), I4 = a . C a; the fibre term acts only when the fibre
is stretched (I4 > 1). In Green-Lagrange strain I1 - 3 = 2 tr E and I4 - 1 = 2 a.E a, so
with e1 = exp(4 c2 tr(E)^2), e4 = exp(4 c3 (a.E a)^2),

    S^w = (c0 + 4 c1 delta c2 tr(E) e1) I + 4 c1 (1 - delta) c3 (a.E a) e4 A,   A = a a,
    CC^w : dE = 4 c1 delta c2 e1 (1 + 8 c2 tr(E)^2) tr(dE) I
              + 4 c1 (1 - delta) c3 e4 (1 + 8 c3 (a.E a)^2) (A : dE) A.

Parameters (c0, c1 [stress], c2, c3, delta [-], cos beta, sin beta). Arrays (3, 3, G) carry
one strain per lane of an element group (:mod:`shellsim.lanes`).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from .axes import AnisotropicLaw, Axes
from ..table_types import NonNegative, Positive, Real
from ..lanes import LANES


class LeeSacks(AnisotropicLaw):
    """Incompressible Lee-Sacks law of heart-valve leaflets (Lee et al. 2014): W = c0/2
    (I1 - 3) + c1/2 [delta (exp(c2 (I1 - 3)^2) - 1) + (1 - delta) (exp(c3 (I4 - 1)^2) - 1)],
    one fibre family at ``beta_deg`` from material axis 1 toward axis 2, in the lamina;
    ``delta`` shares the exponential stiffening between the matrix (1) and the fibres (0).
    A fibre in compression (I4 <= 1) carries no load."""

    model: Literal["lee_sacks"]
    c0: Positive
    c1: NonNegative
    c2: NonNegative
    c3: NonNegative
    delta: Real = Field(ge=0.0, le=1.0)
    beta_deg: Real = Field(default=0.0, ge=-90.0, le=90.0)
    density: Positive
    axes: Axes

    @property
    def isotropic(self) -> bool:
        """delta = 1 leaves no fibre term: W = c0/2 (I1 - 3) + c1/2 (exp(c2 (I1 - 3)^2) - 1)."""
        return self.delta == 1.0


INCOMPRESSIBLE = True
#: The deck's material models this law serves.
MODELS = (LeeSacks,)


def parameters(material) -> np.ndarray:
    """(c0, c1, c2, c3, delta, cos beta, sin beta) of a deck's Lee-Sacks ``[material]``."""
    beta = math.radians(material.beta_deg)
    return np.array([material.c0, material.c1, material.c2, material.c3, material.delta,
                     math.cos(beta), math.sin(beta)])


def fibres(params) -> np.ndarray:
    """(1, 2) the fibre's direction in material axes 1, 2: (cos beta, sin beta)."""
    return np.array([[params[5], params[6]]])


@njit(cache=True, error_model="numpy")
def _invariants(params, E, lane):
    """(tr E, a.E a) of lane ``lane`` of E (3, 3, G)."""
    c, s = params[5], params[6]
    trace = E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane]
    fibre = c * c * E[0, 0, lane] + s * s * E[1, 1, lane] + 2.0 * c * s * E[0, 1, lane]
    return trace, fibre


@njit(cache=True, error_model="numpy")
def _add_fibre(params, factor, T, lane):
    """T[:, :, lane] += factor a a."""
    c, s = params[5], params[6]
    T[0, 0, lane] += factor * c * c
    T[1, 1, lane] += factor * s * s
    T[0, 1, lane] += factor * c * s
    T[1, 0, lane] += factor * c * s


@njit(cache=True, error_model="numpy")
def energy(params, E, W):
    """W (G,) of the strains E (3, 3, G)."""
    c0, c1, c2, c3, delta = params[0], params[1], params[2], params[3], params[4]
    for lane in range(LANES):
        trace, fibre = _invariants(params, E, lane)
        W[lane] = c0 * trace + 0.5 * c1 * delta * (np.exp(4.0 * c2 * trace * trace) - 1.0)
        if fibre > 0.0:
            W[lane] += 0.5 * c1 * (1.0 - delta) * (np.exp(4.0 * c3 * fibre * fibre) - 1.0)


@njit(cache=True, error_model="numpy")
def energy_stress(params, E, S):
    """S^w (3, 3, G) = dW/dE at E (3, 3, G)."""
    c0, c1, c2, c3, delta = params[0], params[1], params[2], params[3], params[4]
    S[:] = 0.0
    for lane in range(LANES):
        trace, fibre = _invariants(params, E, lane)
        matrix = c0 + 4.0 * c1 * delta * c2 * trace * np.exp(4.0 * c2 * trace * trace)
        for i in range(3):
            S[i, i, lane] = matrix
        if fibre > 0.0:
            _add_fibre(params, 4.0 * c1 * (1.0 - delta) * c3 * fibre * np.exp(4.0 * c3 * fibre * fibre), S, lane)


@njit(cache=True, error_model="numpy")
def energy_tangent(params, E, dE, dS):
    """dS^w (3, 3, G) = CC^w : dE at E, dE (3, 3, G)."""
    c1, c2, c3, delta = params[1], params[2], params[3], params[4]
    dS[:] = 0.0
    for lane in range(LANES):
        trace, fibre = _invariants(params, E, lane)
        d_trace, d_fibre = _invariants(params, dE, lane)
        matrix = 4.0 * c1 * delta * c2 * np.exp(4.0 * c2 * trace * trace) * (1.0 + 8.0 * c2 * trace * trace) * d_trace
        for i in range(3):
            dS[i, i, lane] = matrix
        if fibre > 0.0:
            stiffness = 4.0 * c1 * (1.0 - delta) * c3 * np.exp(4.0 * c3 * fibre * fibre) * (1.0 + 8.0 * c3 * fibre * fibre)
            _add_fibre(params, stiffness * d_fibre, dS, lane)
