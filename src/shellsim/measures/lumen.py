"""A vessel's lumen volume: what a ``[output.lumen]`` table measures into history.csv (the
column ``lumen_volume``) and summary.json (its initial, final, smallest and largest
value, and the largest over the initial), a measure family (:mod:`shellsim.measures`).

The volume of a region bounded by the wall and by planes across the axis or through it
(cut ends, a mid-length or symmetry plane) is, by the divergence theorem with the field
(x - o) projected across the axis (divergence 2),

    V = 1/2 ∫_wall ((x - o) - ((x - o)·a) a) · n dA,

the planes adding nothing: across the axis n is along a, through it (x - o) is in the
plane. The wall's face is the element's biquadratic surface through its nodes' points on
that face, integrated exactly by the 3 x 3 Gauss rule (the integrand is of degree 5 in
each coordinate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import model_validator

from ..bundles import Model
from ..element.kinematics import fibre_point
from ..element.shape import gauss_rule_2d, shape, shape_derivatives
from ..mesh import FACES, Mesh
from ..table_types import Name, Section, Vec3, need_directions
from .column import Column


class Lumen(Section):
    """``[output.lumen]``: the volume a vessel's ``wall`` (a surface set) encloses about its
    ``axis`` through ``origin``, bounded by its ``face`` (``bottom``: the inner wall where
    the directors point out of the lumen) and by planes across the axis or through it
    (cut ends, symmetry planes: a quarter tube gives the quarter's volume); a closed end
    (a cap) belongs in ``wall``. Written as the column ``lumen_volume`` at every history
    sample; summary.json holds its initial, final, smallest and largest value and
    ``largest_over_initial``. A compliance is then the volume's change between two samples
    over the pressure's."""

    wall: Name = "all"
    face: Literal["bottom", "mid", "top"] = "bottom"
    axis: Vec3 = (0.0, 0.0, 1.0)
    origin: Vec3 = (0.0, 0.0, 0.0)

    @model_validator(mode="after")
    def _axis_has_direction(self) -> "Lumen":
        need_directions(self, "axis")
        return self


#: Its table: ``[output.lumen]``, one or none (:data:`shellsim.measures.FAMILIES`).
TABLE, OUTPUT_KEY, OUTPUT_FIELD = Lumen, "lumen", (Lumen | None, None)
#: The 3 x 3 Gauss rule: its weights (9,) and, at its points, the shape functions (9, 9)
#: and their derivatives (9 points, 9 nodes, d/dr d/ds).
_RS, _WEIGHTS = gauss_rule_2d(3)
_N, _DN = shape(_RS), shape_derivatives(_RS)


@dataclass
class LumenVolume:
    """The lumen's volume. conn : (m, 9) the wall's elements; thickness_coordinate : the
    face's (-1, 0, 1); axis : (3,) unit; origin : (3,)."""

    conn: np.ndarray
    thickness_coordinate: float
    axis: np.ndarray
    origin: np.ndarray

    NAME = "lumen"
    sparse = False
    columns = ["lumen_volume"]

    def sample(self, run) -> list[float]:
        state = run.sim.state
        return [self(state.x, state.d, state.h)]

    def record(self, run, output_seconds: float) -> dict:
        """The volume's initial, final, smallest and largest value, and the largest over the initial."""
        volumes = np.asarray(run.history["lumen_volume"])
        return {"initial": float(volumes[0]), "final": float(volumes[-1]), "min": float(np.nanmin(volumes)),
                "max": float(np.nanmax(volumes)), "largest_over_initial": float(np.nanmax(volumes) / volumes[0])}

    def __call__(self, x: np.ndarray, d: np.ndarray, h: np.ndarray) -> float:
        """The volume for nodes at x (n, 3) with directors d (n, 3) and fibre lengths h (n,)
        (nan while the positions are no numbers)."""
        if not np.isfinite(x).all():
            return math.nan
        face = fibre_point(x, d, h[:, None], self.thickness_coordinate)[self.conn] - self.origin  # (m, 9, 3)
        g = np.einsum("qad,eai->eqdi", _DN, face)
        normals = np.cross(g[:, :, 0], g[:, :, 1])  # (m, 9, 3): n dA per dr ds
        points = np.einsum("qa,eai->eqi", _N, face)
        across = points - np.einsum("eqi,i->eq", points, self.axis)[..., None] * self.axis
        return float(abs(0.5 * np.einsum("eqi,eqi,q->", across, normals, _WEIGHTS)))


def columns(deck) -> list[Column]:
    """The lumen's volume, named by shellsim."""
    return [] if deck.output.lumen is None else [Column("lumen_volume", "output.lumen", "the lumen's", "volume",
                                                        chosen=False)]


def named_sets(deck) -> list[tuple[str, str, tuple[str, ...]]]:
    """The wall, a surface set."""
    return [] if deck.output.lumen is None else [("output.lumen.wall", deck.output.lumen.wall, ("surface",))]


def resolve(deck, mesh: Mesh, model: Model) -> LumenVolume | None:
    """The deck's ``[output.lumen]`` placed on the mesh (None without one)."""
    table = deck.output.lumen
    if table is None:
        return None
    axis = np.asarray(table.axis, dtype=float)
    return LumenVolume(conn=model.conn[mesh.sets[table.wall].elements], thickness_coordinate=float(FACES[table.face]),
                       axis=axis / np.linalg.norm(axis), origin=np.asarray(table.origin, dtype=float))
