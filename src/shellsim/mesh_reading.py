"""Files read through meshio, every defect a :class:`~shellsim.errors.MeshError` that
names the file: a mesh in any format meshio reads, and a triangulated surface (STL, OBJ,
PLY, VTP, OFF) as points and triangles (a surface to remesh, a rigid tool's shape)."""

from __future__ import annotations

import contextlib
import io
import re
import sys
import warnings
from pathlib import Path

import numpy as np

from .errors import MeshError


def read_meshio(path: Path):
    """meshio's mesh of ``path``. meshio prints its complaints and calls ``sys.exit`` on a file
    it cannot parse (which would end a study's worker): both are caught and become the message."""
    import meshio

    if not path.is_file():
        raise MeshError(f"mesh file '{path}' not found")
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said), warnings.catch_warnings():
            # meshio takes an ASCII STL's first bytes for a facet count to test for binary
            warnings.simplefilter("ignore", RuntimeWarning)
            mesh = meshio.read(path)
    except (Exception, SystemExit) as err:  # meshio raises many types for unreadable files
        complaints = " ".join(line.strip() for line in said.getvalue().splitlines() if line.strip())
        reason = "; ".join(part for part in (complaints, str(err) if not isinstance(err, SystemExit) else "") if part)
        raise MeshError(f"mesh file '{path}' could not be read (truncated, or not a mesh?): {reason}") from None
    complaints = said.getvalue()
    unclosed = re.search(r"\$(\w*) not closed", complaints)
    if unclosed:  # meshio reads on past a cut-off section with only a warning
        section = f"${unclosed.group(1)} section" if unclosed.group(1) else "last section"
        raise MeshError(f"mesh file '{path}' is truncated: its {section} does not end")
    sys.stderr.write(complaints)
    return mesh


def read_triangles(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 3) and triangles (m, 3) of a surface file, unused points dropped and
    points at one place merged (an STL file lists each facet's corners anew)."""
    points, blocks, kinds = _vtp_cells(path) if path.suffix.lower() == ".vtp" else _meshio_cells(path)
    if not blocks or kinds - {"triangle", "vertex", "line"}:
        found = ", ".join(sorted(kinds)) or "no cells"
        raise MeshError(f"surface file '{path}' should hold triangles only; found {found}")
    triangles = np.concatenate(blocks)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    bad = np.flatnonzero(~np.all(np.isfinite(points), axis=1))
    if np.isin(bad, triangles).any():
        raise MeshError(f"surface file '{path}' has points that are not finite numbers, e.g. point {bad[0]}")
    used, triangles = np.unique(triangles, return_inverse=True)
    points = points[used]
    _, first, alike = np.unique(points, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # the merged points in the file's order: a file without repeats is kept as it is
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return points[first[order]], rank[alike.reshape(-1)][triangles].reshape(-1, 3)


def _meshio_cells(path: Path) -> tuple[np.ndarray, list[np.ndarray], set[str]]:
    """A file meshio reads: its points, triangle blocks and the kinds of cell it holds."""
    surface = read_meshio(path)
    blocks = [np.asarray(b.data, dtype=np.int64) for b in surface.cells if b.type == "triangle"]
    return np.asarray(surface.points, dtype=float), blocks, {b.type for b in surface.cells}


def _vtp_cells(path: Path) -> tuple[np.ndarray, list[np.ndarray], set[str]]:
    """A VTK polygonal data file (.vtp, which meshio does not read), through VTK: its
    points, triangles and the kinds of cell it holds."""
    import pyvista

    if not path.is_file():
        raise MeshError(f"surface file '{path}' not found")
    try:
        surface = pyvista.read(path)
    except Exception as err:  # VTK's reader raises several types for an unreadable file
        raise MeshError(f"surface file '{path}' could not be read (truncated, or not a VTP file?): {err}") from None
    if not isinstance(surface, pyvista.PolyData) or surface.n_points == 0:
        raise MeshError(f"surface file '{path}' holds no polygonal surface")
    kinds = {name for name, count in (("vertex", surface.n_verts), ("line", surface.n_lines),
                                      ("triangle_strip", surface.n_strips)) if count}
    blocks = []
    if surface.faces.size:
        if surface.is_all_triangles:
            kinds.add("triangle")
            blocks.append(np.asarray(surface.regular_faces, dtype=np.int64))
        else:
            kinds.add("polygon")
    return np.asarray(surface.points, dtype=float), blocks, kinds


def facet_normals(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 3) each facet's normal, (b - a) x (c - a) of its corners on ``points`` (n, 3):
    twice its area long, zero for a sliver."""
    corners = points[triangles]
    return np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
