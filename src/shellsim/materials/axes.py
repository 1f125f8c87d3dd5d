"""Material axes of an anisotropic law: how the fibre direction is laid on the lamina (a
rule, or vectors from the mesh file, turned by an angle that may vary through the
thickness), and the base of the laws' deck tables."""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal, Union

import numpy as np
from pydantic import Field, field_validator, model_validator

from ..errors import MeshError
from ..table_types import Name, Section, Vec3
from .table import MaterialTable

#: An angle of material axis 1 about the lamina normal (degrees).
Angle = Annotated[float, Field(strict=True, ge=-180.0, le=180.0, allow_inf_nan=False)]


class TurnedAxes(Section):
    """Axis 1 turned about the lamina normal, toward axis 2, by ``angle_deg``: one angle,
    or a list of angles at evenly spaced depths from the bottom face to the top face
    (linear between them), e.g. a vessel wall's helical fibres [-60, 60].

    Each kind gives ``preferred(position, cell_vectors)``: the direction (ne, q, 3) that
    axis 1 follows at the points ``position`` (ne, q, 3), before it is projected on the
    lamina; ``cell_vectors`` are the mesh's per-element vectors by name."""

    angle_deg: Union[Angle, Annotated[list[Angle], Field(min_length=2)]] = 0.0
    #: Whether the preferred direction may vanish, axis 1 then falling back to the
    #: element's own first direction: a rule about an axis gives none on the axis (a tube's
    #: cap); a direction the deck or the mesh gives always has one. Along the lamina
    #: normal it is refused either way (:func:`shellsim.model.material_frames`).
    MAY_MEET_NORMAL: ClassVar[bool] = True

    def angles(self, depths: np.ndarray) -> np.ndarray:
        """The angle (radians) at each thickness coordinate of ``depths`` (nt,), -1 the
        bottom face and +1 the top."""
        values = np.atleast_1d(np.asarray(self.angle_deg, dtype=float))
        if len(values) == 1:
            return np.radians(np.full(len(depths), values[0]))
        return np.radians(np.interp(depths, np.linspace(-1.0, 1.0, len(values)), values))


class CylindricalAxes(TurnedAxes):
    """Material axes of a tube: 1 circumferential, 2 axial (along ``axis`` through
    ``origin``), 3 radial (the lamina normal)."""

    kind: Literal["cylindrical"]
    axis: Vec3 = (0.0, 0.0, 1.0)
    origin: Vec3 = (0.0, 0.0, 0.0)

    @field_validator("axis")
    @classmethod
    def _nonzero(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        return _nonzero_vector(v)

    def preferred(self, position: np.ndarray, cell_vectors: dict) -> np.ndarray:
        """axis x (p - origin): circumferential."""
        return np.cross(np.asarray(self.axis, dtype=float), position - np.asarray(self.origin))


class FixedAxes(TurnedAxes):
    """Material axis 1 along ``direction`` projected on the lamina; 3 is the lamina normal."""

    MAY_MEET_NORMAL: ClassVar[bool] = False

    kind: Literal["fixed"]
    direction: Vec3

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        return _nonzero_vector(v)

    def preferred(self, position: np.ndarray, cell_vectors: dict) -> np.ndarray:
        """``direction`` everywhere."""
        return np.broadcast_to(np.asarray(self.direction, dtype=float), position.shape)


class CentrelineAxes(TurnedAxes):
    """Material axes of a curved vessel: about the polyline ``points`` (its centreline,
    at least two points), 1 circumferential, 2 along the nearest centreline segment, 3 the
    lamina normal."""

    kind: Literal["centreline"]
    points: Annotated[list[Vec3], Field(min_length=2)]

    @field_validator("points")
    @classmethod
    def _segments(cls, points: list) -> list:
        if any(a == b for a, b in zip(points, points[1:])):
            raise ValueError("consecutive centreline points must differ")
        return points

    def preferred(self, position: np.ndarray, cell_vectors: dict) -> np.ndarray:
        """t x (p - c): c the centreline's point nearest p, t its segment's unit direction."""
        ends = np.asarray(self.points, dtype=float)
        start, step = ends[:-1], np.diff(ends, axis=0)  # (S, 3)
        p = position[..., None, :]
        along = np.clip(np.sum((p - start) * step, axis=-1) / np.sum(step * step, axis=-1), 0.0, 1.0)
        nearest = start + along[..., None] * step  # (..., S, 3)
        segment = np.argmin(np.linalg.norm(p - nearest, axis=-1), axis=-1)[..., None, None]
        c = np.take_along_axis(nearest, segment, axis=-2)[..., 0, :]
        t = step[segment[..., 0, 0]]
        return np.cross(t / np.linalg.norm(t, axis=-1, keepdims=True), position - c)


class MeshAxes(TurnedAxes):
    """Material axis 1 along the mesh file's per-element vectors ``field`` (cell data of 3
    components), projected on the lamina; 3 is the lamina normal."""

    MAY_MEET_NORMAL: ClassVar[bool] = False

    kind: Literal["mesh"]
    field: Name

    def preferred(self, position: np.ndarray, cell_vectors: dict) -> np.ndarray:
        """The element's vector ``field`` at each of its points."""
        if self.field not in cell_vectors:
            there = ", ".join(f"'{n}'" for n in cell_vectors) or ("none (a mesh file's cell data gives them, and the "
                                                                    "aortic valve builder 'along_free_edge')")
            raise MeshError(f"material.axes.field = '{self.field}': the mesh has no per-element vectors of that "
                            f"name; it has {there}")
        return np.broadcast_to(cell_vectors[self.field][:, None], position.shape)


Axes = Annotated[Union[CylindricalAxes, CentrelineAxes, FixedAxes, MeshAxes], Field(discriminator="kind")]


def _nonzero_vector(v: tuple[float, float, float]) -> tuple[float, float, float]:
    if sum(c * c for c in v) == 0.0:
        raise ValueError("must not be the zero vector")
    return v


class AnisotropicLaw(MaterialTable):
    """The base of an anisotropic hyperelastic law's ``[material]`` table, which declares
    ``axes: Axes`` among its own fields: cylindrical axes when the deck gives none. Its
    :attr:`isotropic` says where the constants leave the law no direction (Lee-Sacks at
    delta = 1): axes that cannot be laid (a mesh field missing, an axis along a normal)
    are then not demanded."""

    HYPERELASTIC: ClassVar[bool] = True
    ANISOTROPIC: ClassVar[bool] = True

    @property
    def isotropic(self) -> bool:
        """Whether these constants make the law isotropic (no fibre term); False unless
        the law says."""
        return False

    @model_validator(mode="before")
    @classmethod
    def _default_axes(cls, data: object) -> object:
        # A vessel is the common case; state the default so the resolved deck shows it.
        if isinstance(data, dict) and "axes" not in data:
            return data | {"axes": {"kind": "cylindrical"}}
        return data
