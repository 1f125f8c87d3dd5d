"""Isotropic linear elasticity reduced for the shell lamina (thesis 3.9, 3.9.1).

The deck's ``model = "linear_elastic"`` (small strain; St. Venant-Kirchhoff under
Technique 1, :mod:`shellsim.materials.st_venant_kirchhoff`). Strains and stresses use
the five lamina components (11, 22, 12, 13, 23), shears as engineering strains: the
normal component 33 is removed by static condensation (sigma_33 = 0, thesis Eq 3.23) or,
in plane strain through the thickness, by eps_33 = 0.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from pydantic import field_validator

from ..table_types import Positive, Real
from .table import MaterialTable

#: Transverse shear correction factor on the 13 and 23 shear moduli (Reissner-Mindlin,
#: the value Hughes-Liu shells and LS-DYNA's SHRF default use). The thesis does not state
#: one; the Mindlin plate reference of Test 1 assumes 5/6.
SHEAR_FACTOR = 5.0 / 6.0


class LinearElastic(MaterialTable):
    """Isotropic linear elastic (small strain; St. Venant-Kirchhoff under Technique 1)."""

    model: Literal["linear_elastic"]
    E: Positive
    nu: Real
    density: Positive
    HYPERELASTIC: ClassVar[bool] = False
    ANISOTROPIC: ClassVar[bool] = False
    #: The models incompressible tissue takes instead, named in the message of a nu out of
    #: range: the law registry above this module fills it in (:mod:`.laws`).
    INCOMPRESSIBLE_MODELS: ClassVar[tuple[str, ...]] = ()

    @field_validator("nu")
    @classmethod
    def _compressible(cls, nu: float) -> float:
        if not -1.0 < nu < 0.5:
            raise ValueError(f"a compressible model needs -1 < nu < 0.5, got {nu}; for incompressible "
                             f"tissue use model = {' | '.join(repr(m) for m in cls.INCOMPRESSIBLE_MODELS)}")
        return nu


def hooke_3d(E: float, nu: float) -> np.ndarray:
    """3D Hooke matrix (6, 6) in Voigt order (11, 22, 33, 12, 13, 23), engineering shears."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    G = E / (2 * (1 + nu))
    C = np.zeros((6, 6))
    C[:3, :3] = lam
    C[[0, 1, 2], [0, 1, 2]] = lam + 2 * G
    C[3, 3] = C[4, 4] = C[5, 5] = G
    return C


def reduced_lamina_matrix(E: float, nu: float, plane_strain: bool = False,
                          shear_factor: float = SHEAR_FACTOR) -> np.ndarray:
    """C~ (5, 5) relating (s11, s22, s12, s13, s23) to (e11, e22, 2e12, 2e13, 2e23).

    Zero normal stress: C~_ij = C_ij - C_i3 C_3j / C_33 (thesis 3.9.1); plane strain:
    the rows and columns of 33 are dropped. Transverse shears are scaled by
    ``shear_factor``.
    """
    C = hooke_3d(E, nu)
    keep = [0, 1, 3, 4, 5]
    reduced = C[np.ix_(keep, keep)].copy()
    if not plane_strain:
        reduced -= np.outer(C[keep, 2], C[2, keep]) / C[2, 2]
    reduced[3, 3] *= shear_factor
    reduced[4, 4] *= shear_factor
    return reduced

