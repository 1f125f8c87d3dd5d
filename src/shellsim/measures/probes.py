"""Probes: what a deck's ``[[output.probe]]`` reads from a running simulation, resolved
once on the mesh and read at every history sample; a measure family
(:mod:`shellsim.measures`) with a column per probe, its deck table here."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

import numpy as np
from pydantic import AfterValidator, model_validator

from ..bundles import Model
from ..element.kinematics import fibre_point
from ..element.sampling import nearest_integration_point, pressure_band, thickness_mean
from ..errors import MeshError
from ..mesh import FACES, Mesh
from ..table_types import Name, Section, Vec3, need_directions, repeated
from .column import Column


#: The probes' vocabulary (one place: the deck, the probes and the renders read it).
#: Quantities by kind; those read at the integration point nearest to a probe's set.
VECTOR_QUANTITIES = ("displacement", "position", "director", "reaction")
TENSOR_QUANTITIES = ("stress", "strain")
SCALAR_QUANTITIES = ("thickness", "pressure_band", "rotation")
POINT_QUANTITIES = ("stress", "strain", "pressure_band")
#: Global components: a vector's column, a tensor's (row, column).
VECTOR_COMPONENTS = {"x": 0, "y": 1, "z": 2}
TENSOR_COMPONENTS = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "yz": (1, 2), "zx": (2, 0)}


#: Components of a vector or tensor probe in cylindrical axes about ``axis`` (through
#: ``origin``), or along a given ``direction``; a tensor's is its normal component.
AXIS_COMPONENTS = ("radial", "circumferential", "axial", "along")


class Probe(Section):
    """A history written at every output step: ``quantity`` at the node of a point set
    (a set of several nodes gives their mean). ``stress`` (Cauchy), ``strain``
    (Green-Lagrange) and ``pressure_band`` (-trace(stress) / 3) are read at the integration
    point nearest to the set (mean through the thickness, global axes), as stress
    benchmarks compare values at Gauss points. ``reaction`` is the force the supports
    and prescribed motions exert on the set, summed over its nodes (each node's internal
    less external force along the directions it is held in: the load a test rig would
    measure). ``face`` reads a position or
    displacement on the bottom or top face (along the director, half the current fibre
    length from the mid-surface), e.g. the inner radius of a vessel.

    Vessel axes: ``radial``, ``circumferential`` and ``axial`` components are taken in the
    cylindrical axes about the line through ``origin`` along ``axis``, at the probe's
    initial place (a position's radial component is its distance from the axis, a
    stress's circumferential one the hoop stress); ``along`` takes the component along
    ``direction``. Over a set of several nodes, each node's component is averaged (a
    reaction's summed)."""

    name: Name
    quantity: Literal[VECTOR_QUANTITIES + TENSOR_QUANTITIES + SCALAR_QUANTITIES]
    set: Name
    component: Literal[(*VECTOR_COMPONENTS, "magnitude", *TENSOR_COMPONENTS, "scalar", *AXIS_COMPONENTS)] = "scalar"
    face: Literal["bottom", "mid", "top"] = "mid"
    axis: Vec3 = (0.0, 0.0, 1.0)
    origin: Vec3 = (0.0, 0.0, 0.0)
    direction: Vec3 | None = None

    @model_validator(mode="after")
    def _component_fits(self) -> "Probe":
        if self.face != "mid" and self.quantity not in ("position", "displacement"):
            raise ValueError(f"face = '{self.face}' reads a position or displacement, not {self.quantity}")
        allowed = (
            (*VECTOR_COMPONENTS, "magnitude", *AXIS_COMPONENTS) if self.quantity in VECTOR_QUANTITIES
            else (*TENSOR_COMPONENTS, *AXIS_COMPONENTS) if self.quantity in TENSOR_QUANTITIES
            else ("scalar",)
        )
        if self.component not in allowed:
            raise ValueError(
                f"component '{self.component}' does not fit quantity '{self.quantity}'; "
                f"expected one of {', '.join(allowed)}"
            )
        if (self.component == "along") != (self.direction is not None):
            raise ValueError("'direction' is needed with component = 'along', and only then")
        need_directions(self, "axis", "direction")
        return self


@dataclass
class PlacedProbe:
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


def axis_directions(table: Probe, places: np.ndarray) -> np.ndarray:
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


def resolve_probes(tables: list[Probe], mesh: Mesh, model: Model) -> list[PlacedProbe]:
    """The deck's probe tables placed on the mesh: nodes of their sets, for point
    quantities the integration point nearest to the set's centre, and the directions of
    axis components at those places."""
    probes = []
    gauss = model.rule.N[:len(model.rule.wq)]
    for p in tables:
        nodes = mesh.sets[p.set].nodes
        if p.quantity in POINT_QUANTITIES:
            element, point = nearest_integration_point(model.x0, model.conn, gauss, model.x0[nodes].mean(axis=0))
            probe = PlacedProbe(p.name, p.quantity, p.component, nodes, element, point)
            places = (gauss[point] @ model.x0[model.conn[element]])[None, :]
        else:
            probe = PlacedProbe(p.name, p.quantity, p.component, nodes, face=FACES[p.face])
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


def probe_value(sim, probe: PlacedProbe) -> float:
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

    def __init__(self, probes: list[PlacedProbe]):
        self.probes = probes
        self.columns = [p.name for p in probes]

    def sample(self, run) -> list[float]:
        return [probe_value(run.sim, p) for p in self.probes]

    def record(self, run, output_seconds: float) -> None:
        """Probes have no summary entry of their own: references read their columns."""


def _unique_names(probes: list[Probe]) -> list[Probe]:
    duplicates = repeated([p.name for p in probes])
    if duplicates:
        raise ValueError(f"probe names must be unique; repeated: {', '.join(duplicates)}")
    return probes


#: Its tables: ``[[output.probe]]``, a list (:data:`shellsim.measures.FAMILIES`).
TABLE, OUTPUT_KEY = Probe, "probe"
OUTPUT_FIELD = (Annotated[list[Probe], AfterValidator(_unique_names)], [])


def columns(deck) -> list[Column]:
    """Each probe's column, its name."""
    return [Column(p.name, f"output.probe[{i}].name", "a probe's", p.quantity) for i, p in enumerate(deck.output.probe)]


def named_sets(deck) -> list[tuple[str, str, tuple[str, ...]]]:
    """Each probe's set, of any kind."""
    return [(f"output.probe[{i}].set", p.set, ("surface", "edge", "point")) for i, p in enumerate(deck.output.probe)]


def resolve(deck, mesh: Mesh, model: Model) -> Probes | None:
    """The deck's probes on the mesh (None without any)."""
    probes = resolve_probes(deck.output.probe, mesh, model)
    return Probes(probes) if probes else None
