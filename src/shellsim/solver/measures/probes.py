"""Probes: what a deck's ``[[output.probe]]`` reads from a running simulation, resolved
once on the mesh and read at every history sample; a measure family
(:mod:`shellsim.solver.measures`) with a column per probe."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...deck.schema import AXIS_COMPONENTS, POINT_QUANTITIES, TENSOR_COMPONENTS, VECTOR_COMPONENTS
from ...deck.schema import Probe as ProbeTable
from ...element.kinematics import fibre_point
from ...element.sampling import nearest_integration_point, pressure_band, thickness_mean
from ...errors import MeshError
from ...mesh import FACES, Mesh
from ...model import Model


@dataclass
class Probe:
    """Where a deck's probe reads: its nodes, quantity and component; for stress, the
    integration point (element, in-plane point) nearest to the nodes."""

    name: str
    quantity: str
    component: str
    nodes: np.ndarray
    element: int = -1
    point: int = -1
    face: float = 0.0  # thickness coordinate t of a position or displacement: -1, 0, +1
    #: unit vectors of an axis component: (k, 3), one per node, or (3,) at the point
    directions: np.ndarray | None = None
    origin: np.ndarray | None = None  # (3,) of the axis, from which positions are taken


def axis_directions(table: ProbeTable, places: np.ndarray) -> np.ndarray:
    """Unit vectors (k, 3) of ``table.component`` (one of AXIS_COMPONENTS) at the initial
    ``places`` (k, 3): radial, circumferential (axis x radial) or axial about the table's
    axis through its origin, or its ``direction``. Raises MeshError for a place on the
    axis, where radial and circumferential are not defined."""
    if table.component == "along":
        return np.tile(np.asarray(table.direction) / np.linalg.norm(table.direction), (len(places), 1))
    axis = np.asarray(table.axis) / np.linalg.norm(table.axis)
    if table.component == "axial":
        return np.tile(axis, (len(places), 1))
    off_axis = places - np.asarray(table.origin)
    off_axis -= np.outer(off_axis @ axis, axis)
    distance = np.linalg.norm(off_axis, axis=1)
    if (distance <= 1e-9 * max(np.abs(places).max(), 1.0)).any():
        raise MeshError(f"output.probe '{table.name}': set '{table.set}' has a point on the probe's axis, where "
                        f"'{table.component}' has no direction; move the set or the axis (axis, origin)")
    radial = off_axis / distance[:, None]
    return radial if table.component == "radial" else np.cross(axis, radial)


def resolve_probes(tables: list[ProbeTable], mesh: Mesh, model: Model) -> list[Probe]:
    """The deck's probe tables placed on the mesh: nodes of their sets, for point
    quantities the integration point nearest to the set's centre, and the directions of
    axis components at those places."""
    probes = []
    gauss = model.rule.N[:len(model.rule.wq)]
    for p in tables:
        nodes = mesh.sets[p.set].nodes
        if p.quantity in POINT_QUANTITIES:
            element, point = nearest_integration_point(model.x0, model.conn, gauss, model.x0[nodes].mean(axis=0))
            probe = Probe(p.name, p.quantity, p.component, nodes, element, point)
            places = (gauss[point] @ model.x0[model.conn[element]])[None, :]
        else:
            probe = Probe(p.name, p.quantity, p.component, nodes, face=FACES[p.face])
            places = model.x0[nodes]
        if p.component in AXIS_COMPONENTS:
            directions = axis_directions(p, places)
            probe.directions = directions[0] if p.quantity in POINT_QUANTITIES else directions
            probe.origin = np.asarray(p.origin, dtype=float)
        probes.append(probe)
    return probes


def held(projector: np.ndarray, force: np.ndarray) -> np.ndarray:
    """The parts (k, 3) of nodal forces ``force`` (k, 3) along the directions the supports
    hold, of nodes whose allowed translations ``projector`` (k, 3, 3) projects onto."""
    return force - np.einsum("kij,kj->ki", projector, force)


def probe_value(sim, probe: Probe) -> float:
    """The probe's current value in ``sim`` (a :class:`shellsim.solver.simulation.Simulation`;
    the mean over the probe's nodes)."""
    s, m = sim.state, sim.model
    nodes = probe.nodes
    if probe.quantity in POINT_QUANTITIES:
        e, p = probe.element, probe.point
        _, cauchy, green = sim.point_tensors(slice(e, e + 1), slice(p, p + 1))
        tensor = thickness_mean((green if probe.quantity == "strain" else cauchy)[0, 0], m.rule.wt, axis=0)
        if probe.quantity == "pressure_band":
            return float(pressure_band(tensor))
        if probe.directions is not None:
            return float(probe.directions @ tensor @ probe.directions)
        return float(tensor[TENSOR_COMPONENTS[probe.component]])
    if probe.quantity == "thickness":
        return float(s.h[nodes].mean())
    if probe.quantity == "rotation":
        return float(np.linalg.norm(s.theta[nodes], axis=1).mean())
    if probe.quantity == "reaction":
        vectors = held(m.constraints.projector[nodes], s.f_int[nodes] - s.f_ext[nodes])
        if probe.directions is not None:
            return float(np.einsum("ki,ki->", vectors, probe.directions))
        total = vectors.sum(axis=0)
        return float(np.linalg.norm(total) if probe.component == "magnitude" else total[VECTOR_COMPONENTS[probe.component]])
    if probe.quantity == "director":
        vectors = s.d[nodes]
    else:  # a position or displacement on the probe's face
        position = fibre_point(s.x[nodes], s.d[nodes], s.h[nodes, None], probe.face)
        start = fibre_point(m.x0[nodes], m.d0[nodes], m.h0[nodes, None], probe.face)
        vectors = position if probe.quantity == "position" else position - start
    if probe.directions is not None:  # each node's own component, then their mean
        if probe.quantity == "position":
            vectors = vectors - probe.origin
        return float(np.einsum("ki,ki->k", vectors, probe.directions).mean())
    vector = vectors.mean(axis=0)
    if probe.component == "magnitude":
        return float(np.linalg.norm(vector))
    return float(vector[VECTOR_COMPONENTS[probe.component]])


class Probes:
    """The probes' columns, each probe's value at every sample."""

    NAME = "probes"
    sparse = False

    def __init__(self, probes: list[Probe]):
        self.probes = probes
        self.columns = [p.name for p in probes]

    def sample(self, run) -> list[float]:
        return [probe_value(run.sim, p) for p in self.probes]

    def record(self, run, output_seconds: float) -> None:
        """Probes have no summary entry of their own: references read their columns."""


def resolve(deck, mesh: Mesh, model: Model) -> Probes | None:
    """The deck's probes on the mesh (None without any)."""
    probes = resolve_probes(deck.output.probe, mesh, model)
    return Probes(probes) if probes else None
