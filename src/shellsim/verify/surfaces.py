"""Triangulated test surfaces, as a segmentation tool would export them: the tubes the
remesher is checked on (tests, ``benchmarks/remesh_sizes.py``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def tube_facets(inlet: float, outlet: float, length: float, around: int, along: int) -> tuple[np.ndarray, np.ndarray]:
    """An open tube about z, z in [0, length], its radius going linearly from ``inlet`` to
    ``outlet``: points (around (along + 1), 3) and 2 x around x along facets (m, 3)."""
    phi = np.linspace(0.0, 2 * np.pi, around, endpoint=False)
    z = np.linspace(0.0, length, along + 1)
    radius = inlet + (outlet - inlet) * z / length
    points = np.array([[r * np.cos(p), r * np.sin(p), h] for r, h in zip(radius, z) for p in phi])
    a = (np.arange(along)[:, None] * around + np.arange(around)[None]).ravel()
    b = (np.arange(along)[:, None] * around + (np.arange(around)[None] + 1) % around).ravel()
    return points, np.concatenate([np.column_stack([a, b, b + around]), np.column_stack([a, b + around, a + around])])


def write_facets(path: Path, points: np.ndarray, triangles: np.ndarray) -> Path:
    """``points`` (n, 3) and ``triangles`` (m, 3) written to ``path`` (STL, or any format
    meshio writes triangles in); facets collapsed to a line or a point are written too."""
    import meshio

    with np.errstate(invalid="ignore"):  # meshio divides by a collapsed facet's zero normal
        meshio.write(path, meshio.Mesh(points, [("triangle", triangles)]))
    return path
