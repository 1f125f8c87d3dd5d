"""The whole model from the part a deck models: the viewing mesh and each frame's fields
reflected across the symmetry planes the deck names in ``output.mirror``, so a quarter
artery is written, and drawn, whole.

A plane is a ``symmetry`` boundary: its normal, through its set's nodes. k distinct planes
give 2^k copies, each y -> R y + b with R a product of reflections I - 2 n n. Vectors
(displacement, director, fibres) turn with R, tensors as R T R^T, scalars stay; a copy made
by an odd number of reflections has its cells' corners walked backwards, so every copy's
cells keep an outward orientation.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import combinations

import numpy as np

from ..deck import Deck
from ..mesh import Mesh
from .encoding import symmetric_columns, symmetric_tensors
from .fields import OutputMesh

#: Corner orders that reverse a quad's and a hexahedron's orientation.
REVERSED = {"quad": [0, 3, 2, 1], "hexahedron": [0, 3, 2, 1, 4, 7, 6, 5]}


@dataclass(frozen=True)
class Mirrors:
    """The copies of the modelled part: turns (c, 3, 3) R and shifts (c, 3) b, copy 0 the
    part itself; y -> R y + b."""

    turns: np.ndarray
    shifts: np.ndarray

    @property
    def count(self) -> int:
        return len(self.turns)


def mirror_planes(deck: Deck, mesh: Mesh) -> list[tuple[np.ndarray, float]]:
    """(unit normal n (3,), offset n . p) of each distinct symmetry plane named in
    ``deck.output.mirror``, p the first node of its set; planes equal within 1e-9 of the
    model's size count once."""
    size = float(np.ptp(mesh.x, axis=0).max()) or 1.0
    planes: list[tuple[np.ndarray, float]] = []
    for bc in deck.boundary:
        if bc.type != "symmetry" or bc.set not in (deck.output.mirror or []):
            continue
        normal = np.asarray(bc.normal, dtype=float)
        offset = float(normal @ mesh.x[mesh.sets[bc.set].nodes[0]])
        if not any(abs(abs(n @ normal) - 1.0) < 1e-9 and abs(o - np.sign(n @ normal) * offset) < 1e-9 * size
                   for n, o in planes):
            planes.append((normal, offset))
    return planes


def mirrors(planes: list[tuple[np.ndarray, float]]) -> Mirrors:
    """Every product of reflections across a subset of ``planes``, the empty one first."""
    turns, shifts = [np.eye(3)], [np.zeros(3)]
    for size in range(1, len(planes) + 1):
        for subset in combinations(planes, size):
            R, b = np.eye(3), np.zeros(3)
            for normal, offset in subset:  # reflect y -> y - 2 (n.y - offset) n after what came before
                reflection = np.eye(3) - 2.0 * np.outer(normal, normal)
                R, b = reflection @ R, reflection @ b + 2.0 * offset * normal
            turns.append(R)
            shifts.append(b)
    return Mirrors(np.array(turns), np.array(shifts))


def mirrored_mesh(mesh: OutputMesh, copies: Mirrors) -> OutputMesh:
    """``mesh`` with every copy's points and cells appended after the part's."""
    points = np.concatenate([mesh.points @ R.T + b for R, b in zip(copies.turns, copies.shifts)])
    reversed_cells = mesh.cells[:, REVERSED[mesh.cell_type]]
    cells = np.concatenate([(reversed_cells if np.linalg.det(R) < 0 else mesh.cells) + c * len(mesh.points)
                            for c, R in enumerate(copies.turns)])
    return replace(mesh, points=points, cells=cells)


def mirrored_values(values: np.ndarray, copies: Mirrors) -> np.ndarray:
    """A field's values (m,), (m, 3) or (m, 6) (a symmetric tensor's components) for every
    copy, the part's first: scalars repeated, vectors turned, tensors turned on both sides."""
    if values.ndim == 1:
        return np.tile(values, copies.count)
    if values.shape[1] == 3:
        return np.concatenate([values @ R.T for R in copies.turns])
    tensors = symmetric_tensors(values)
    return np.concatenate([symmetric_columns(R @ tensors @ R.T) for R in copies.turns])
