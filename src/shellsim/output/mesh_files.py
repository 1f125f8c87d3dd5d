"""The mesh as a VTK file: biquadratic quads (VTK type 28, node order = the element's) and
its cables as lines, with directors, thickness and named sets as data, readable back by
:func:`shellsim.geometry.importing.read_mesh`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .folder import replacing
from ..geometry.importing import CABLE_MARK, KIND_CODE, SET_PREFIX
from ..mesh import Mesh


def write_mesh_vtu(mesh: Mesh, path: Path, with_thickness: bool = True) -> None:
    """Write ``mesh`` to ``path`` (.vtu). Each named set becomes a point-data array
    ``set_<name>`` (1 point, 2 edge, 3 surface, 4 line set; 0 outside) and, for surface and
    line sets, a cell-data array of the same name; per-element vectors and scalar fields
    are point and cell data by their names (0 on the cables). The cables are a block of
    lines marked by the cell data ``cable``. Without ``with_thickness`` the nodal thickness
    is left out, so that a deck reading the file takes its ``[section] thickness``."""
    import meshio

    point_data = {"director": mesh.director} | ({"thickness": mesh.thickness} if with_thickness else {})
    point_data |= mesh.point_fields
    shells, cables = dict(mesh.cell_vectors | mesh.cell_fields), {}  # cell data by name on each block
    for name, named in mesh.sets.items():
        member = np.zeros(mesh.n_nodes, dtype=np.uint8)
        member[named.nodes] = KIND_CODE[named.kind]
        point_data[SET_PREFIX + name] = member
        if named.kind in ("surface", "line"):
            cells = np.zeros(len(mesh.lines) if named.kind == "line" else mesh.n_elements, dtype=np.uint8)
            cells[named.elements] = 1
            (cables if named.kind == "line" else shells)[SET_PREFIX + name] = cells
    blocks = [("quad9", mesh.conn)]
    cell_data = {name: [values] for name, values in shells.items()}
    if len(mesh.lines):
        blocks.append(("line", mesh.lines))
        cables[CABLE_MARK] = np.ones(len(mesh.lines), dtype=np.uint8)
        cell_data = {name: [_or_zeros(shells.get(name), cables.get(name), mesh.n_elements),
                            _or_zeros(cables.get(name), shells.get(name), len(mesh.lines))]
                     for name in shells | cables}
    with replacing(path) as partial:
        meshio.write(partial, meshio.Mesh(mesh.x, blocks, point_data=point_data, cell_data=cell_data), file_format="vtu")


def _or_zeros(values: np.ndarray | None, other: np.ndarray, count: int) -> np.ndarray:
    """A cell array's ``values`` on one block, or ``count`` zeros shaped as its ``other``
    block's values where it has none there (VTK wants every array on every block)."""
    return values if values is not None else np.zeros((count, *other.shape[1:]), dtype=other.dtype)
