"""Material axes of an anisotropic law: how the fibre direction is laid on the lamina, and
the base of the laws' deck tables."""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal, Union

from pydantic import Field, field_validator, model_validator

from .types import Section, Vec3


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


def _nonzero_vector(v: tuple[float, float, float]) -> tuple[float, float, float]:
    if sum(c * c for c in v) == 0.0:
        raise ValueError("must not be the zero vector")
    return v


class AnisotropicLaw(Section):
    """The base of an anisotropic hyperelastic law's ``[material]`` table, which declares
    ``axes: Axes`` among its own fields: cylindrical axes when the deck gives none."""

    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = True

    @model_validator(mode="before")
    @classmethod
    def _default_axes(cls, data: object) -> object:
        # A vessel is the common case; state the default so the resolved deck shows it.
        if isinstance(data, dict) and "axes" not in data:
            return data | {"axes": {"kind": "cylindrical"}}
        return data
