"""Meshes from files, through meshio: any format it reads, as long as it holds 9-node
quadrilaterals (``quad9``; node order as gmsh and VTK, which is the element's).

Named sets come from
- cell sets (gmsh physical groups, in the 2.2 and 4.x formats; a group over several
  entities is merged): on quad9 cells a surface set, on 3-node lines an edge set, on
  vertices a point set;
- point-data arrays ``set_<name>`` (nonzero = member; 1 point, 2 edge, 3 surface, 4 line
  set), as :func:`shellsim.output.mesh_files.write_mesh_vtu` writes them; the cables are the
  2-node lines marked by the cell data ``cable`` (their nodes kept though no shell has
  them), a line set's members its cells marked by its ``set_<name>`` cell data.
Point data ``director`` (n, 3) and ``thickness`` (n,) are used when present, and cell data
of three components on the quad9 cells (e.g. fibre directions) is kept by name.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import MeshError, id_list
from ..mesh import ImportedMesh, NamedSet, edges_within
from ..mesh_reading import read_meshio
from .file_checks import (
    GMSH_QUAD9, collapsed_problem, missing_nodes_problem, point_data_problems, repeated_node_problem,
)

SET_PREFIX = "set_"
KIND_CODE = {"point": 1, "edge": 2, "surface": 3, "line": 4}
#: The cell data that marks a line block's cells as cables (:func:`shellsim.output.mesh_files.write_mesh_vtu`).
CABLE_MARK = "cable"
_KIND_OF_CODE = {v: k for k, v in KIND_CODE.items()}
_KIND_OF_CELL = {"quad9": "surface", "line3": "edge", "line": "edge", "vertex": "point"}
_DIMENSION = {"quad9": 2, "line3": 1, "line": 1, "vertex": 0}
#: Surface and volume cells other than quad9: a file holding them is not a quad9 shell mesh.
_NOT_QUAD9 = {"triangle", "triangle6", "triangle7", "quad", "quad8", "polygon", "tetra", "tetra10", "hexahedron",
              "hexahedron20", "hexahedron27", "wedge", "pyramid"}


def read_mesh(path: Path) -> ImportedMesh:
    """Read a quad9 mesh and its named sets; nodes not used by any quad are dropped. A model
    file of another program (:data:`shellsim.foreign.READERS`) gives its shells' mesh.

    Raises MeshError, naming every defect with ids and places, for a file that is not a
    quad9 shell mesh or whose nodes, directors, thicknesses or elements cannot be used.
    """
    from ..foreign import READERS, read_foreign_mesh

    if Path(path).suffix.lower() in READERS:
        return read_foreign_mesh(Path(path))
    m = read_meshio(Path(path))
    blocks = [i for i, block in enumerate(m.cells) if block.type == "quad9"]
    others = sorted({b.type for b in m.cells if b.type in _NOT_QUAD9})
    if not blocks or others:
        found = ", ".join(sorted({b.type for b in m.cells})) or "no cells"
        what = "no 9-node quadrilaterals (quad9)" if not blocks else f"elements other than quad9 ({', '.join(others)})"
        raise MeshError(f"mesh file '{path}' has {what}; found {found}. To {GMSH_QUAD9}")
    _refuse(path, [p for block in m.cells
                   for p in missing_nodes_problem(block.type, np.asarray(block.data, dtype=np.int64), len(m.points))])
    conn_raw = np.concatenate([np.asarray(m.cells[i].data, dtype=np.int64) for i in blocks])
    cable_blocks = [i for i, block in enumerate(m.cells)
                    if block.type == "line" and np.any(np.asarray(m.cell_data.get(CABLE_MARK, [[]] * len(m.cells))[i]))]
    lines_raw = np.concatenate([np.zeros((0, 2), dtype=np.int64)]
                               + [np.asarray(m.cells[i].data, dtype=np.int64) for i in cable_blocks])
    own = np.setdiff1d(lines_raw, conn_raw)  # the cables' nodes that no shell has, kept last
    used = np.concatenate([np.unique(conn_raw), own])
    index = np.full(len(m.points), -1)
    index[used] = np.arange(len(used))
    x = np.asarray(m.points, dtype=float)[used]
    if x.shape[1] == 2:
        x = np.column_stack([x, np.zeros(len(x))])
    conn = index[conn_raw]
    offsets = np.cumsum([0] + [len(m.cells[i].data) for i in blocks])

    def point_array(name: str, width: int | None) -> np.ndarray | None:
        if name not in m.point_data:
            return None
        values = np.asarray(m.point_data[name], dtype=float)
        if values.size != len(m.points) * (width or 1):
            raise MeshError(f"mesh file '{path}': point data '{name}' has {values.size} values for "
                            f"{len(m.points)} nodes; expected {width or 1} per node")
        return values.reshape(len(m.points), width)[used] if width else values.reshape(len(m.points))[used]

    director, thickness = point_array("director", 3), point_array("thickness", None)
    shell = len(used) - len(own)  # a cable's own node has no thickness to check
    problems = repeated_node_problem(conn_raw) + point_data_problems(
        x[:shell], None if director is None else director[:shell], None if thickness is None else thickness[:shell],
        node_ids=used[:shell] + 1)
    if not problems:
        problems = collapsed_problem(x, conn)
    _refuse(path, problems)
    if director is not None:  # within the tolerance of unit length: made exactly unit
        director = director / np.linalg.norm(director, axis=1, keepdims=True)

    sets = _cell_sets(path, m, blocks, offsets, index, conn)
    lines = index[lines_raw]
    point_fields = {}
    for key in m.point_data:
        if key.startswith(SET_PREFIX):
            values = np.nan_to_num(point_array(key, None))
            code = int(values.max(initial=0))
            if _KIND_OF_CODE.get(code) == "line":
                members = np.concatenate([np.zeros(0)] + [np.asarray(m.cell_data[key][i]).reshape(-1)
                                                          for i in cable_blocks if key in m.cell_data])
                elements = np.flatnonzero(members)
                sets[key[len(SET_PREFIX):]] = NamedSet("line", np.unique(lines[elements]), elements=elements)
            elif code in _KIND_OF_CODE:
                sets[key[len(SET_PREFIX):]] = _node_set(_KIND_OF_CODE[code], np.flatnonzero(values), conn)
        elif key not in ("director", "thickness") and np.asarray(m.point_data[key]).size == len(m.points):
            point_fields[key] = _finite(path, "point", key, point_array(key, None), used + 1)
    vectors, cell_fields = _cell_arrays(path, m, blocks)
    return ImportedMesh(x, conn, sets, director, thickness, vectors, point_fields, cell_fields, lines)


def _finite(path: Path, where: str, name: str, values: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """``values`` of a scalar field, refused where they are not finite (naming the ids)."""
    bad = np.flatnonzero(~np.isfinite(values))
    if len(bad):
        raise MeshError(f"mesh file '{path}': {where} field '{name}' is not finite at {len(bad)} "
                        f"{'node' if where == 'point' else 'element'}(s): {id_list(ids[bad])}")
    return values


def _cell_arrays(path: Path, m, blocks: list[int]) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The numeric cell data on every quad9 block (integers too: a file may store unit
    fibre directions as integers), as floats: vectors of three components (ne, 3) by
    name, non-finite or zero ones refused naming the elements, and scalar fields (ne,),
    non-finite ones refused; gmsh's tags and the set markers are left to the sets."""
    vectors, scalars = {}, {}
    for name, per_block in m.cell_data.items():
        arrays = [np.asarray(per_block[i]) for i in blocks]
        if name.startswith((SET_PREFIX, "gmsh:")) or not all(a.dtype.kind in "fiu" for a in arrays):
            continue
        if all(a.ndim == 1 or (a.ndim == 2 and a.shape[1] == 1) for a in arrays):
            values = np.concatenate([a.reshape(-1) for a in arrays]).astype(float)
            scalars[name] = _finite(path, "cell", name, values, np.arange(len(values)) + 1)
            continue
        if not all(a.ndim == 2 and a.shape[1] == 3 for a in arrays):
            continue
        values = np.concatenate(arrays).astype(float)
        bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1) | (np.linalg.norm(values, axis=1) == 0.0))
        if len(bad):
            raise MeshError(f"mesh file '{path}': cell vectors '{name}' are not a direction (not finite, or zero) "
                            f"in {len(bad)} element(s): {id_list(bad + 1)}")
        vectors[name] = values
    return vectors, scalars


def _cell_sets(path: Path, m, blocks: list[int], offsets: np.ndarray, index: np.ndarray,
               conn: np.ndarray) -> dict[str, NamedSet]:
    """The named sets of the file's cell sets. A gmsh physical group over several entities
    (an edge of two curves, a surface of four patches) comes as one block per entity:
    their members are merged under the name. ``blocks`` are the quad9 blocks, ``offsets``
    their first elements, ``index`` a file node's number among the kept nodes (-1: unused)."""
    members: dict[str, dict[str, list[np.ndarray]]] = {}
    for name, per_block in _named_cells(m).items():
        for b, (block, cells) in enumerate(zip(m.cells, per_block)):
            kind = _KIND_OF_CELL.get(block.type)
            if kind is None or cells is None or len(cells) == 0:
                continue
            cells = np.asarray(cells, dtype=np.int64)  # meshio may give uint64
            if kind == "surface":
                found = offsets[blocks.index(b)] + cells
            else:
                nodes = index[np.asarray(block.data[cells])]
                found = nodes[(nodes >= 0).all(axis=-1)] if nodes.ndim > 1 else nodes[nodes >= 0]
            members.setdefault(name, {}).setdefault(kind, []).append(found.ravel())
    sets: dict[str, NamedSet] = {}
    for name, kinds in members.items():
        if len(kinds) > 1:
            raise MeshError(f"mesh file '{path}': the name '{name}' is given to {' and '.join(sorted(kinds))} "
                            "cells; a set is one kind (points, edges or a surface): give each group its own name")
        (kind, parts), = kinds.items()
        found = np.unique(np.concatenate(parts))
        sets[name] = (NamedSet("surface", np.unique(conn[found]), elements=found) if kind == "surface"
                      else _node_set(kind, found, conn))
    return sets


def _named_cells(m) -> dict[str, list[np.ndarray]]:
    """Each cell set's cells in every block of the meshio mesh ``m``. meshio gives gmsh's
    4.x physical groups as cell sets, but its 2.2 format only as a physical tag per cell
    and the groups' (tag, dimension) by name: the sets are then made from those."""
    named = {name: cells for name, cells in m.cell_sets.items() if not name.startswith("gmsh:")}
    tags = m.cell_data.get("gmsh:physical")
    if named or tags is None:
        return named
    return {name: [np.flatnonzero(np.asarray(block_tags) == tag) if _DIMENSION.get(block.type) == dim else None
                   for block, block_tags in zip(m.cells, tags)]
            for name, (tag, dim) in m.field_data.items()}


def _refuse(path: Path, problems: list[str]) -> None:
    """Raise MeshError listing ``problems``, if there are any."""
    if problems:
        count = f"{len(problems)} problem{'s' if len(problems) > 1 else ''}"
        raise MeshError(f"mesh file '{path}' cannot be used ({count}; ids count from 1 in the file's order):\n"
                        + "\n".join(f"  - {p}" for p in problems))


def _node_set(kind: str, nodes: np.ndarray, conn: np.ndarray) -> NamedSet:
    if kind == "edge":
        return NamedSet("edge", nodes, edges=edges_within(conn, nodes))
    if kind == "surface":
        elements = np.flatnonzero(np.isin(conn, nodes).all(axis=1))
        return NamedSet("surface", nodes, elements=elements)
    return NamedSet("point", nodes)
