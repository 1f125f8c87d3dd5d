"""A follower pressure whose amplitude varies over the surface as a field of the mesh
file: ``value * field(x) * curve(t)``, the regional loading of image-based models (a
wall-pressure map from a flow solution, a region's own pulse amplitude). A nodal field
is interpolated with the element's shape functions at the face's Gauss points; an
element field is constant over each element. It runs as a follower pressure."""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np

from ..errors import MeshError
from ..mesh import FACES
from ..table_types import Name, Real
from . import pressure
from .table import LoadTable


class MappedPressure(LoadTable):
    """Follower pressure ``value * field * curve(t)`` on one face of a surface set, with
    ``field`` the name of a scalar point or cell field of the mesh file (VTU point or cell
    data, gmsh node or element data read by meshio); sign and faces as ``pressure``."""

    type: Literal["mapped_pressure"]
    set: Name = "all"
    field: Name
    value: Real = 1.0
    curve: Name | None = None
    face: Literal["bottom", "mid", "top"] = "mid"
    SET_KINDS: ClassVar[tuple[str, ...]] = ("surface",)
    FEATURES: ClassVar[tuple[str, ...]] = ("follower_pressure",)
    QUANTITY: ClassVar[str] = "pressure"


TABLES = (MappedPressure,)


def build(table: MappedPressure, scene) -> pressure.Bundle:
    """The faces of the set with the field's pressure at their Gauss points (P, nq)."""
    mesh, rule = scene.mesh, scene.rule
    elements = mesh.sets[table.set].elements
    if table.field in mesh.point_fields:
        nodal = mesh.point_fields[table.field][mesh.conn[elements]]  # (P, 9)
        amplitude = nodal @ rule.N[:len(rule.wq)].T
    elif table.field in mesh.cell_fields:
        amplitude = np.repeat(mesh.cell_fields[table.field][elements][:, None], len(rule.wq), axis=1)
    else:
        known = sorted(mesh.point_fields) + sorted(mesh.cell_fields)
        raise MeshError(f"field '{table.field}' is not a scalar field of the mesh; it has "
                        + (", ".join(f"'{name}'" for name in known) if known else "none (only a mesh file carries fields)"))
    return pressure.faces(elements, FACES[table.face], table.value * amplitude, scene.curve_index(table.curve))
