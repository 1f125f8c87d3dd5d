"""Meshes from files, through meshio: any format it reads, as long as it holds 9-node
quadrilaterals (``quad9``; node order as gmsh and VTK, which is the element's).

Named sets come from
- cell sets (gmsh physical groups): on quad9 cells a surface set, on 3-node lines an edge
  set, on vertices a point set;
- point-data arrays ``set_<name>`` (nonzero = member; 1 point, 2 edge, 3 surface set), as
  :func:`shellsim.output.mesh_files.write_mesh_vtu` writes them.
Point data ``director`` (n, 3) and ``thickness`` (n,) are used when present.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MeshError
from ..mesh import NamedSet, edges_within

SET_PREFIX = "set_"
KIND_CODE = {"point": 1, "edge": 2, "surface": 3}
_KIND_OF_CODE = {v: k for k, v in KIND_CODE.items()}
_KIND_OF_CELL = {"quad9": "surface", "line3": "edge", "line": "edge", "vertex": "point"}


@dataclass(frozen=True)
class ImportedMesh:
    """What a file gives: x (n, 3), conn (ne, 9), sets, and optional director (n, 3) and
    thickness (n,)."""

    x: np.ndarray
    conn: np.ndarray
    sets: dict[str, NamedSet]
    director: np.ndarray | None
    thickness: np.ndarray | None


def _read(path: Path):
    import meshio

    if not path.is_file():
        raise MeshError(f"mesh file '{path}' not found")
    try:
        return meshio.read(path)
    except Exception as err:  # meshio raises many types for unreadable files
        raise MeshError(f"mesh file '{path}' could not be read: {err}") from None


def read_mesh(path: Path) -> ImportedMesh:
    """Read a quad9 mesh and its named sets; nodes not used by any quad are dropped."""
    m = _read(Path(path))
    blocks = [i for i, block in enumerate(m.cells) if block.type == "quad9"]
    if not blocks:
        found = ", ".join(sorted({b.type for b in m.cells})) or "no cells"
        raise MeshError(f"mesh file '{path}' has no 9-node quadrilaterals (quad9); found {found}")
    conn_raw = np.concatenate([m.cells[i].data for i in blocks])
    used = np.unique(conn_raw)
    index = np.full(len(m.points), -1)
    index[used] = np.arange(len(used))
    x = np.asarray(m.points, dtype=float)[used]
    if x.shape[1] == 2:
        x = np.column_stack([x, np.zeros(len(x))])
    conn = index[conn_raw]
    offsets = np.cumsum([0] + [len(m.cells[i].data) for i in blocks])

    sets: dict[str, NamedSet] = {}
    for name, per_block in m.cell_sets.items():
        if name.startswith("gmsh:"):
            continue
        for b, (block, cells) in enumerate(zip(m.cells, per_block)):
            kind = _KIND_OF_CELL.get(block.type)
            if kind is None or cells is None or len(cells) == 0:
                continue
            cells = np.asarray(cells, dtype=np.int64)  # meshio may give uint64
            if kind == "surface":
                k = blocks.index(b)
                elements = offsets[k] + cells
                sets[name] = NamedSet("surface", np.unique(conn[elements]), elements=elements)
            else:
                nodes = index[np.asarray(block.data[cells])]
                nodes = nodes[(nodes >= 0).all(axis=-1)] if nodes.ndim > 1 else nodes[nodes >= 0]
                sets[name] = _node_set(kind, np.unique(nodes), conn)
    for key, values in m.point_data.items():
        if key.startswith(SET_PREFIX):
            values = np.asarray(values)[used]
            code = int(values.max(initial=0))
            if code in _KIND_OF_CODE:
                sets[key[len(SET_PREFIX):]] = _node_set(_KIND_OF_CODE[code], np.flatnonzero(values), conn)

    def point_array(name: str, width: int | None) -> np.ndarray | None:
        if name not in m.point_data:
            return None
        values = np.asarray(m.point_data[name], dtype=float)[used]
        return values.reshape(len(used), width) if width else values.reshape(len(used))

    return ImportedMesh(x, conn, sets, point_array("director", 3), point_array("thickness", None))


def _node_set(kind: str, nodes: np.ndarray, conn: np.ndarray) -> NamedSet:
    if kind == "edge":
        return NamedSet("edge", nodes, edges=edges_within(conn, nodes))
    if kind == "surface":
        elements = np.flatnonzero(np.isin(conn, nodes).all(axis=1))
        return NamedSet("surface", nodes, elements=elements)
    return NamedSet("point", nodes)
