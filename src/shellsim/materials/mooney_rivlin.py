"""Incompressible Mooney-Rivlin (neo-Hookean: C2 = 0).

    W = C1 (I1 - 3) + C2 (I2 - 3),  I1 = tr C,  I2 = (I1^2 - tr C^2) / 2,  C = 2E + I.

With dI1/dC = I and dI2/dC = I1 I - C, the stress S^w = dW/dE = 2 dW/dC is

    S^w = 2 (C1 + C2 I1) I - 2 C2 C,

and its derivative in a direction dE (dC = 2 dE, dI1 = 2 tr dE)

    CC^w : dE = 4 C2 (tr dE I - dE).

Parameters (C1, C2) [stress]; the incompressibility and zero normal stress are
:mod:`shellsim.materials.zero_normal_stress`'s. Arrays (3, 3, G) carry one strain per lane
of an element group (:mod:`shellsim.lanes`).
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..table_types import Positive
from ..lanes import LANES
from .table import MaterialTable



class NeoHookean(MaterialTable):
    """Incompressible neo-Hookean: W = C1 (I1 - 3)."""

    model: Literal["neo_hookean"]
    C1: Positive
    density: Positive
    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = False


class MooneyRivlin(MaterialTable):
    """Incompressible Mooney-Rivlin: W = C1 (I1 - 3) + C2 (I2 - 3), C1 > 0, C2 >= 0."""

    model: Literal["mooney_rivlin"]
    C1: Positive
    C2: Annotated[float, Field(strict=True, ge=0)]
    density: Positive
    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = False


INCOMPRESSIBLE = True
#: The deck's material models this law serves.
MODELS = (NeoHookean, MooneyRivlin)


def parameters(material) -> np.ndarray:
    """(C1, C2) of a deck's neo-Hookean or Mooney-Rivlin ``[material]``."""
    return np.array([material.C1, getattr(material, "C2", 0.0)])


@njit(cache=True, error_model="numpy")
def energy(params, E, W):
    """W (G,) of the strains E (3, 3, G)."""
    C1, C2 = params[0], params[1]
    for lane in range(LANES):
        I1 = 3.0 + 2.0 * (E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane])
        trC2 = 0.0
        for i in range(3):
            for j in range(3):
                c = 2.0 * E[i, j, lane] + (1.0 if i == j else 0.0)
                trC2 += c * c
        W[lane] = C1 * (I1 - 3.0) + C2 * (0.5 * (I1 * I1 - trC2) - 3.0)


@njit(cache=True, error_model="numpy")
def energy_stress(params, E, S):
    """S^w (3, 3, G) = dW/dE at E (3, 3, G)."""
    C1, C2 = params[0], params[1]
    for i in range(3):
        for j in range(3):
            for lane in range(LANES):
                S[i, j, lane] = -2.0 * C2 * (2.0 * E[i, j, lane] + (1.0 if i == j else 0.0))
    for lane in range(LANES):
        I1 = 3.0 + 2.0 * (E[0, 0, lane] + E[1, 1, lane] + E[2, 2, lane])
        for i in range(3):
            S[i, i, lane] += 2.0 * (C1 + C2 * I1)


@njit(cache=True, error_model="numpy")
def energy_tangent(params, E, dE, dS):
    """dS^w (3, 3, G) = CC^w : dE at E, dE (3, 3, G)."""
    C2 = params[1]
    for i in range(3):
        for j in range(3):
            for lane in range(LANES):
                dS[i, j, lane] = -4.0 * C2 * dE[i, j, lane]
    for lane in range(LANES):
        trace = dE[0, 0, lane] + dE[1, 1, lane] + dE[2, 2, lane]
        for i in range(3):
            dS[i, i, lane] += 4.0 * C2 * trace
