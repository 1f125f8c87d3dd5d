"""The ``[material]`` table, chosen by ``model``.

Incompressible models (neo-Hookean, Mooney-Rivlin, Guccione) impose J = 1 exactly through
the lamina normal strain (thesis Technique 1), so they take no bulk modulus or Poisson
ratio. Parameter names follow the thesis; Guccione's C1..C4 are LS-DYNA MAT_128's
C, B1, B2, B3.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal, Union

from pydantic import Field, field_validator, model_validator

from .types import Positive, Real, Section, Vec3, tag_of


class CylindricalAxes(Section):
    """Material axes of a tube: 1 circumferential, 2 axial (along ``axis`` through
    ``origin``), 3 radial (the lamina normal)."""

    kind: Literal["cylindrical"]
    axis: Vec3 = (0.0, 0.0, 1.0)
    origin: Vec3 = (0.0, 0.0, 0.0)

    @field_validator("axis")
    @classmethod
    def _nonzero(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        return _nonzero_vector(v)


class FixedAxes(Section):
    """Material axis 1 along ``direction`` projected on the lamina; 3 is the lamina normal."""

    kind: Literal["fixed"]
    direction: Vec3

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        return _nonzero_vector(v)


Axes = Annotated[Union[CylindricalAxes, FixedAxes], Field(discriminator="kind")]


class LinearElastic(Section):
    """Isotropic linear elastic (small strain; St. Venant-Kirchhoff under Technique 1)."""

    model: Literal["linear_elastic"]
    E: Positive
    nu: Real
    density: Positive
    HYPERELASTIC: ClassVar[bool] = False
    ANISOTROPIC: ClassVar[bool] = False

    @field_validator("nu")
    @classmethod
    def _compressible(cls, nu: float) -> float:
        if not -1.0 < nu < 0.5:
            raise ValueError(
                f"a compressible model needs -1 < nu < 0.5, got {nu}; for incompressible "
                "tissue use model = 'neo_hookean', 'mooney_rivlin' or 'guccione'"
            )
        return nu


class NeoHookean(Section):
    """Incompressible neo-Hookean: W = C1 (I1 - 3)."""

    model: Literal["neo_hookean"]
    C1: Positive
    density: Positive
    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = False


class MooneyRivlin(Section):
    """Incompressible Mooney-Rivlin: W = C1 (I1 - 3) + C2 (I2 - 3), C1 > 0, C2 >= 0."""

    model: Literal["mooney_rivlin"]
    C1: Positive
    C2: Annotated[float, Field(strict=True, ge=0)]
    density: Positive
    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = False


class Guccione(Section):
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
    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = True

    @model_validator(mode="before")
    @classmethod
    def _default_axes(cls, data: object) -> object:
        # A tube is the common case; state the default so the resolved deck shows it.
        if isinstance(data, dict) and "axes" not in data:
            return data | {"axes": {"kind": "cylindrical"}}
        return data


Material = Annotated[
    Union[LinearElastic, NeoHookean, MooneyRivlin, Guccione], Field(discriminator="model")
]

MATERIALS = {
    tag_of(cls)[1]: cls
    for cls in (LinearElastic, NeoHookean, MooneyRivlin, Guccione)
}


def _nonzero_vector(v: tuple[float, float, float]) -> tuple[float, float, float]:
    if sum(c * c for c in v) == 0.0:
        raise ValueError("must not be the zero vector")
    return v
