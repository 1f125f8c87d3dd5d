"""The mesh as a VTK file: biquadratic quads (VTK type 28, node order = the element's) with
directors, thickness and named sets as data, readable back by
:func:`shellsim.geometry.importing.read_mesh`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..geometry.importing import KIND_CODE, SET_PREFIX
from ..mesh import Mesh


def write_mesh_vtu(mesh: Mesh, path: Path, with_thickness: bool = True) -> None:
    """Write ``mesh`` to ``path`` (.vtu). Each named set becomes a point-data array
    ``set_<name>`` (1 point, 2 edge, 3 surface set; 0 outside) and, for surface sets, a
    cell-data array of the same name; per-element vectors and scalar fields are point and
    cell data by their names. Without ``with_thickness`` the nodal thickness is left out, so
    that a deck reading the file takes its ``[section] thickness``."""
    import meshio

    point_data = {"director": mesh.director} | ({"thickness": mesh.thickness} if with_thickness else {})
    point_data |= mesh.point_fields
    cell_data = {name: [values] for name, values in (mesh.cell_vectors | mesh.cell_fields).items()}
    for name, named in mesh.sets.items():
        member = np.zeros(mesh.n_nodes, dtype=np.uint8)
        member[named.nodes] = KIND_CODE[named.kind]
        point_data[SET_PREFIX + name] = member
        if named.kind == "surface":
            cells = np.zeros(mesh.n_elements, dtype=np.uint8)
            cells[named.elements] = 1
            cell_data[SET_PREFIX + name] = [cells]
    try:
        meshio.write(
            path,
            meshio.Mesh(mesh.x, [("quad9", mesh.conn)], point_data=point_data, cell_data=cell_data),
            file_format="vtu",
        )
    except OSError as err:
        raise OutputError(f"cannot write '{path}': {err.strerror or err}") from None
