"""Cables (chordae tendineae): two-node elements that carry tension only, either from the
nodes of a shell set to a tip point (a papillary muscle's), each chord in ``segments``
elements, or the line elements of a mesh file's line set (an imported model's).

A ``[[cable]]`` table with a ``tip`` adds its nodes to the mesh (:func:`extend_mesh`): the
interior nodes of every chord and one tip node shared by the table's chords, as the point
set ``<name>_tip`` (so that a ``[[boundary]]`` may hold it or move it on a curve), and its
elements as the line set ``<name>``. A cable node that belongs to no shell has its
director fixed (a cable has no bending).

An element of rest length L, initial cross-section A and law P(lambda) (:mod:`.cable_laws`)
pulls its ends together with the tension N = A P(l / L) along its current direction e;
its weight rho A L g is lumped half at each end. Its stiffness is
K = A P'(lambda) / L e e^T + N / l (I - e e^T). Its masses (rho A L / 2 at each end, and a
rod's rotary inertia, so that a node with no shell has some) are added to the shell's;
its critical step with the element's own lumped masses, sqrt(m / K), bounds the step
(Irons' element bound: the assembly's highest frequency is no higher than its elements').
The cables' strain energy counts as work of external forces in the energy balance.
"""

from __future__ import annotations

import dataclasses
from typing import ClassVar, Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import model_validator

from ..errors import MeshError
from ..mesh import Mesh, NamedSet
from ..table_types import Count, Name, Positive, Vec3
from .cable_laws import CableLaw, code_and_parameters, nominal_stress
from .table import LoadTable


class Cable(LoadTable):
    """Chords from every node of ``set`` to the point ``tip``, each in ``segments``
    elements (or, without a ``tip``, the elements of the mesh file's line set ``set``), of
    cross-section ``area`` [length^2] and ``density`` [mass/length^3], with
    the 1D ``law``; ``rest_length``: each chord's rest length over its initial length
    (above 1 slack, below 1 pre-tensioned); ``gravity`` [length/time^2]: the acceleration
    its weight follows (the shell's weight is a ``body_force`` load). The table adds the
    line set ``name`` (its elements and nodes) and the point set ``<name>_tip`` (its tip
    node: hold it, or move it on a curve, with a ``[[boundary]]``; free, it moves with the
    chords' masses). Its strain energy counts as work of external forces. A static solve
    (or preload) takes one segment per chord, and a free tip needs holding across the
    chords (a string at rest has no lateral stiffness). ``min_step`` [time]: each element
    whose own critical step is shorter is made heavier until it is this, at the start and
    again at each later step estimate as it stiffens (never lighter: Abaqus'
    ``*VARIABLE MASS SCALING, TYPE=BELOW MIN`` on the set): a chord's short stiff segments
    then no longer set an explicit run's step, however far they stretch."""

    type: Literal["cable"] = "cable"
    name: Name
    set: Name
    tip: Vec3 | None = None
    segments: Count = 1
    area: Positive
    density: Positive
    law: CableLaw
    rest_length: Positive = 1.0
    gravity: Vec3 = (0.0, 0.0, 0.0)
    min_step: Positive | None = None
    DECK_KEY: ClassVar[str] = "cable"
    SET_KINDS: ClassVar[tuple[str, ...]] = ("point", "edge", "surface", "line")
    FEATURES: ClassVar[tuple[str, ...]] = ("cables",)

    @model_validator(mode="after")
    def _segments_need_a_tip(self) -> "Cable":
        if self.tip is None and self.segments != 1:
            raise ValueError(f"segments = {self.segments} divides chords made to a tip; a mesh file's line set "
                             "brings its own elements (give a tip, or leave segments out)")
        return self

    @property
    def summary(self) -> str:
        """One line for ``shellsim check``."""
        law = ", ".join(f"{k}={_numbers(v)}" for k, v in self.law.model_dump().items() if k != "model")
        slack = f", rest length x {self.rest_length:g}" if self.rest_length != 1.0 else ""
        chords = (f"the line elements of '{self.set}'" if self.tip is None else
                  f"a chord from each node of '{self.set}' to {list(self.tip)} in {self.segments} segment(s)")
        heavier = f", elements of a step below {self.min_step:g} made heavier to it" if self.min_step else ""
        return f"'{self.name}': {chords}, area {self.area:g}, {self.law.model} ({law}){slack}{heavier}"

    @property
    def declared_sets(self) -> dict[str, str]:
        """The sets the table adds to the mesh, with their kinds (none without a tip)."""
        return {} if self.tip is None else {self.name: "line", f"{self.name}_tip": "point"}

    @property
    def elements(self) -> str:
        """The line set that holds the table's elements."""
        return self.set if self.tip is None else self.name


def _numbers(value: float | list[float]) -> str:
    """A law's parameter for a line: 2.5, or [1, 2.5] for one of several terms."""
    return f"[{', '.join(f'{v:g}' for v in value)}]" if isinstance(value, list) else f"{value:g}"


TABLES = (Cable,)


def untensioned_hanging_nodes(tables: list[Cable], mesh: Mesh, projector: np.ndarray) -> np.ndarray:
    """The nodes (k,) that hang on ``tables``' chords alone with none of them in tension at
    the start (rest length at least the initial one), on no shell element, and free to
    move (their support projector (n, 3, 3)) in some direction across every chord they
    end: a string at rest is stiff only along itself, so a static tangent is singular
    there until the chords are stretched."""
    on_chords = [mesh.lines[mesh.sets[t.elements].elements] for t in tables]
    tensioned = [chords.ravel() for t, chords in zip(tables, on_chords) if t.rest_length < 1.0]
    chords = np.concatenate(on_chords or [np.zeros((0, 2), dtype=np.int64)])
    candidates = np.setdiff1d(chords.ravel(), np.concatenate([mesh.conn.ravel(), *tensioned]))
    along = mesh.x[chords[:, 1]] - mesh.x[chords[:, 0]]
    hanging = []
    for node in candidates:
        free = projector[node]
        stiff = free @ along[(chords == node).any(axis=1)].T  # each chord's direction, as far as it is free
        if np.linalg.matrix_rank(stiff, tol=1e-9 * np.abs(stiff).max(initial=1.0)) < np.linalg.matrix_rank(free):
            hanging.append(node)
    return np.asarray(hanging, dtype=np.int64)


def extend_mesh(table: Cable, mesh: Mesh) -> Mesh:
    """``mesh`` with ``table``'s chords: their new nodes appended (directors along the
    chord, no thickness, 0 in the point fields), their elements appended to ``mesh.lines``,
    and the sets :attr:`Cable.declared_sets`; without a tip, ``mesh`` itself, once its set
    is found to be a line set (MeshError otherwise)."""
    kind = mesh.sets[table.set].kind
    if (kind == "line") != (table.tip is None):
        need = "a tip to run its chords to" if table.tip is None else "no tip: its line elements are the chords"
        raise MeshError(f"cable '{table.name}': set '{table.set}' is a {kind} set, which needs {need}")
    if table.tip is None:
        return mesh
    starts = mesh.sets[table.set].nodes
    tip = np.asarray(table.tip, dtype=float)
    chords = tip - mesh.x[starts]
    lengths = np.linalg.norm(chords, axis=1)
    size = float(np.ptp(mesh.x, axis=0).max()) or 1.0
    if np.any(lengths <= 1e-9 * size):
        node = starts[np.argmin(lengths)]
        raise MeshError(f"cable '{table.name}': its tip {list(table.tip)} is at node {node + 1} of set '{table.set}' "
                        "(numbered from 1), which leaves that chord no length")
    n, s = mesh.n_nodes, table.segments
    tip_node = n
    interior = tip_node + 1 + np.arange(len(starts) * (s - 1)).reshape(len(starts), s - 1)
    shares = np.arange(1, s) / s
    points = (mesh.x[starts][:, None, :] + shares[None, :, None] * chords[:, None, :]).reshape(-1, 3)
    chains = np.column_stack([starts, interior, np.full(len(starts), tip_node)])
    ends = np.stack([chains[:, :-1], chains[:, 1:]], axis=-1).reshape(-1, 2)
    new_x = np.vstack([tip[None, :], points])
    along = np.repeat(chords / lengths[:, None], s - 1, axis=0)
    new_d = np.vstack([(chords / lengths[:, None]).mean(axis=0, keepdims=True), along])
    new_d /= np.linalg.norm(new_d, axis=1, keepdims=True)
    added = len(new_x)
    elements = len(mesh.lines) + np.arange(len(ends))
    sets = mesh.sets | {
        table.name: NamedSet("line", np.unique(ends), elements=elements),
        f"{table.name}_tip": NamedSet("point", np.array([tip_node])),
    }
    return dataclasses.replace(
        mesh, x=np.vstack([mesh.x, new_x]), director=np.vstack([mesh.director, new_d]),
        thickness=np.concatenate([mesh.thickness, np.zeros(added)]),
        lines=np.vstack([mesh.lines, ends]).astype(np.int64), sets=sets,
        point_fields={name: np.concatenate([values, np.zeros(added)]) for name, values in mesh.point_fields.items()})


class Bundle(NamedTuple):
    """Cable elements (L): nodes (L, 2) their ends; rest (L,) rest lengths [length];
    area (L,) initial cross-sections [length^2]; density (L,) [mass/length^3], raised in
    place to hold ``min_step`` (L,) [time] (0: none); law (L,) and params (L, PARAMETERS)
    of :mod:`.cable_laws`; gravity (L, 3) [length/time^2]."""

    nodes: np.ndarray
    rest: np.ndarray
    area: np.ndarray
    density: np.ndarray
    min_step: np.ndarray
    law: np.ndarray
    params: np.ndarray
    gravity: np.ndarray


def build(table: Cable, scene) -> Bundle:
    """The elements :func:`extend_mesh` made for ``table``, at rest ``rest_length`` times
    their initial length."""
    mesh = scene.mesh
    nodes = mesh.lines[mesh.sets[table.elements].elements]
    count = len(nodes)
    code, params = code_and_parameters(table.law)
    rest = table.rest_length * np.linalg.norm(mesh.x[nodes[:, 1]] - mesh.x[nodes[:, 0]], axis=1)
    bundle = Bundle(nodes=nodes, rest=rest, area=np.full(count, table.area), density=np.full(count, table.density),
                    min_step=np.full(count, table.min_step or 0.0), law=np.full(count, code, dtype=np.int64),
                    params=np.tile(params, (count, 1)), gravity=np.tile(np.asarray(table.gravity, dtype=float), (count, 1)))
    hold_min_step(scene.initial, bundle)  # the elements quicker than min_step at the start made heavier
    return bundle


@njit(cache=True, inline="always")
def _tension(x, cables, k, e):
    """(N, l, lambda, P') of element k at positions x (n, 3): the tension [force], the
    current length, the stretch and the law's slope; e (3,) receives the unit direction
    from its first end to its second."""
    a, b = cables.nodes[k, 0], cables.nodes[k, 1]
    length = 0.0
    for i in range(3):
        e[i] = x[b, i] - x[a, i]
        length += e[i] * e[i]
    length = np.sqrt(length)
    for i in range(3):
        e[i] /= length
    stretch = length / cables.rest[k]
    p, dp = nominal_stress(cables.law[k], cables.params[k], stretch)
    return cables.area[k] * p, length, stretch, dp


@njit(cache=True)
def add_forces(t, model, shape, cables, f, g):
    """Each element's tension and weight added to the translational forces f (n, 3)."""
    e = np.empty(3)
    for k in range(cables.nodes.shape[0]):
        tension = _tension(shape.x, cables, k, e)[0]
        half_weight = 0.5 * cables.density[k] * cables.area[k] * cables.rest[k]
        a, b = cables.nodes[k, 0], cables.nodes[k, 1]
        for i in range(3):
            f[a, i] += tension * e[i] + half_weight * cables.gravity[k, i]
            f[b, i] += -tension * e[i] + half_weight * cables.gravity[k, i]


@njit(cache=True)
def couplings(t, model, shape, cables, step_u, nodes, blocks):
    """The derivative of each taut element's forces by its ends' translations, exact:
    nodes (K, 10) its two ends (the rest repeat the first, with zero blocks) and blocks
    (K, 30, 30) dF/dx, filled from the top. Returns how many elements are taut (at rest
    length included: the law's slope holds there)."""
    e = np.empty(3)
    count = 0
    for k in range(cables.nodes.shape[0]):
        tension, length, stretch, dp = _tension(shape.x, cables, k, e)
        if stretch < 1.0:
            continue
        axial = cables.area[k] * dp / cables.rest[k]
        lateral = tension / length
        nodes[count, :] = cables.nodes[k, 0]
        nodes[count, 1] = cables.nodes[k, 1]
        blocks[count] = 0.0
        for i in range(3):
            for j in range(3):
                stiffness = (axial - lateral) * e[i] * e[j] + (lateral if i == j else 0.0)
                # the force on the first end grows with the second's motion, falls with its own
                blocks[count, i, j] = -stiffness
                blocks[count, i, 3 + j] = stiffness
                blocks[count, 3 + i, j] = stiffness
                blocks[count, 3 + i, 3 + j] = -stiffness
        count += 1
    return count


@njit(cache=True)
def element_states(x, cables, stretch, tension):
    """Each element's stretch and tension [force] (L,) at positions x (n, 3), into the
    given arrays (the output's fields)."""
    e = np.empty(3)
    for k in range(cables.nodes.shape[0]):
        tension[k], _, stretch[k], _ = _tension(x, cables, k, e)


def add_masses(cables: Bundle, mt: np.ndarray, mr: np.ndarray) -> None:
    """Each element's mass rho A L, half at each end, added to the translational masses
    mt (n,), and a rod's rotary inertia (m / 2) L^2 / 12 to mr (n,)."""
    half = 0.5 * cables.density * cables.area * cables.rest
    for end in range(2):
        np.add.at(mt, cables.nodes[:, end], half)
        np.add.at(mr, cables.nodes[:, end], half * cables.rest ** 2 / 12.0)


@njit(cache=True)
def _own_step(x, cables, k, e):
    """Element k's critical step on its own lumped mass, sqrt(m / k) with m = rho A L and k
    the larger of the axial and lateral stiffness, the law's slope taken at a stretch of
    at least 1 (a slack element stiffens as soon as it is taut); +inf without stiffness."""
    tension, length, stretch, dp = _tension(x, cables, k, e)
    if stretch < 1.0:  # slack: the slope it takes up as soon as it is taut
        dp = nominal_stress(cables.law[k], cables.params[k], 1.0)[1]
    stiffness = max(cables.area[k] * dp / cables.rest[k], tension / length)
    if stiffness <= 0.0:
        return np.inf
    return np.sqrt(cables.density[k] * cables.area[k] * cables.rest[k] / stiffness)


@njit(cache=True)
def critical_step(shape, cables):
    """The smallest of the elements' own critical steps (:func:`_own_step`); +inf for none."""
    e = np.empty(3)
    smallest = np.inf
    for k in range(cables.nodes.shape[0]):
        smallest = min(smallest, _own_step(shape.x, cables, k, e))
    return smallest


@njit(cache=True)
def hold_min_step(shape, cables):
    """Each element whose own critical step on ``shape`` is below its ``min_step`` made
    heavier until it is that (its density raised in place, never lowered)."""
    e = np.empty(3)
    for k in range(cables.nodes.shape[0]):
        if cables.min_step[k] > 0.0:
            own = _own_step(shape.x, cables, k, e)
            if own < cables.min_step[k]:
                cables.density[k] *= (cables.min_step[k] / own) ** 2
