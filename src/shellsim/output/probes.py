"""Probes: what a deck's ``[[output.probe]]`` reads from a running simulation, resolved
once on the mesh and read at every history sample."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..deck.schema import Probe as ProbeTable
from ..element.kinematics import fibre_point
from ..element.sampling import nearest_integration_point, pressure_band, thickness_mean
from ..mesh import Mesh
from ..model import FACES, Model

#: Quantities read at the integration point nearest to the probe's set.
POINT_QUANTITIES = ("stress", "strain", "pressure_band")
#: Tensor components of a probe as (row, column) of the global tensor.
TENSOR_COMPONENTS = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "yz": (1, 2), "zx": (2, 0)}


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


def resolve_probes(tables: list[ProbeTable], mesh: Mesh, model: Model) -> list[Probe]:
    """The deck's probe tables placed on the mesh: nodes of their sets, and for point
    quantities the integration point nearest to the set's centre."""
    probes = []
    for p in tables:
        nodes = mesh.sets[p.set].nodes
        if p.quantity in POINT_QUANTITIES:
            element, point = nearest_integration_point(model.x0, model.conn, model.rule.N[:len(model.rule.wq)],
                                                       model.x0[nodes].mean(axis=0))
            probes.append(Probe(p.name, p.quantity, p.component, nodes, element, point))
        else:
            probes.append(Probe(p.name, p.quantity, p.component, nodes, face=FACES[p.face]))
    return probes


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
        return float(tensor[TENSOR_COMPONENTS[probe.component]])
    if probe.quantity == "thickness":
        return float(s.h[nodes].mean())
    if probe.quantity == "rotation":
        return float(np.linalg.norm(s.theta[nodes], axis=1).mean())
    if probe.quantity == "director":
        vector = s.d[nodes].mean(axis=0)
    else:  # a position or displacement on the probe's face
        position = fibre_point(s.x[nodes], s.d[nodes], s.h[nodes, None], probe.face)
        start = fibre_point(m.x0[nodes], m.d0[nodes], m.h0[nodes, None], probe.face)
        vector = (position if probe.quantity == "position" else position - start).mean(axis=0)
    if probe.component == "magnitude":
        return float(np.linalg.norm(vector))
    return float(vector["xyz".index(probe.component)])
