"""What an output frame holds: the viewing mesh and the field arrays on it.

Each element is cut into one sub-cell per integration point (3 x 3 in the plane; with
``solid``, times the layers through the thickness), the cuts laid at the Gauss weights'
boundaries (-1, -4/9, 4/9, 1), so each sub-cell holds its own point's value and stress
jumps between and inside elements stay visible, as in the thesis' pressure-band figures.
Sub-cell corners are not shared between elements. The shell view sits on the
mid-surface with thickness-mean values (von Mises: the largest over the layers), and point fields ``<name>_nodal`` beside the cell
fields carry a smoothed version (Gauss values extrapolated to the element's nodes, averaged
over the elements sharing a node). The solid view places the corners on the layer
boundaries (top, bottom and between) from directors and fibre lengths. Fibre directions
(``fibres``) are unit cell vectors per family, ``fibre_1``, ``fibre_2``: every layer's in
the solid view, the middle layer's in the shell view.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..deck.schema import WRITTEN_AS
from ..element.sampling import pressure_band, thickness_mean
from ..element.shape import NODE_RS, gauss_rule, shape
from ..materials.laws import LAWS
from ..mesh import node_areas
from ..model import Model
from ..solver.simulation import Simulation
from ..loads import ToolForces
from ..loads.cable import element_states
from .derived import (VESSEL_STRESSES, current_material_frames, deformation_gradients, normal_components,
                      principal_stresses, second_piola_in, vessel_frames)
from .encoding import symmetric_columns
from .units import NODAL_SUFFIX

POINT_FIELDS = ("displacement", "director", "thickness")
CELL_FIELDS = ("cauchy_stress", "lamina_stress", "pressure_band", "green_lagrange_strain", "von_mises", "pk2_stress",
               "material_stress")
#: Tensor fields in the material's axes: the second Piola-Kirchhoff stress in the initial
#: ones, the Cauchy stress in the current ones.
PK2, MATERIAL_STRESS = "pk2_stress", "material_stress"
#: Fields derived from the Cauchy stress, cells only: principal_stress_k and
#: principal_direction_k (k = 1, 2, 3, largest first); hoop_, axial_ and radial_stress.
PRINCIPAL, VESSEL = "principal_stress", "vessel_stress"
#: The output field of fibre directions, written as one cell vector per family:
#: fibre_1, fibre_2, ...; and of their stretches, fibre_stretch_1, ...
FIBRES, FIBRE_PREFIX, FIBRE_STRETCH = "fibres", "fibre_", "fibre_stretch"
CONTACT_PRESSURE, CONTACT_GAP = "contact_pressure", "contact_gap"
#: Fields the shell view shows as their largest value through the thickness (a bent
#: shell's equivalent stress peaks at its faces); the others as the thickness mean.
LARGEST_THROUGH_THICKNESS = ("von_mises",)

#: Sub-cell boundaries along r or s: the 3-point Gauss weights laid end to end.
SUB_BOUNDS = -1.0 + np.concatenate([[0.0], np.cumsum(gauss_rule(3)[1])])
#: Natural coordinates of the 4 x 4 sub-cell corners, r fastest. Shape (16, 2).
CORNER_RS = np.array([(r, s) for s in SUB_BOUNDS for r in SUB_BOUNDS])
#: Shape functions at the corners. Shape (16, 9).
CORNER_N = shape(CORNER_RS)
#: Piecewise-bilinear weights at the corners, each from the 2 x 2 nodes of the quarter of
#: the element it lies in. Shape (16, 9). Never outside those nodes' range: a contact's
#: pressure, which drops to zero within an element, read through the quadratic would dip
#: below zero beside it.
CORNER_HATS = np.prod(np.clip(1.0 - np.abs(CORNER_RS[:, None, :] - NODE_RS[None]), 0.0, None), axis=2)
#: Corners of the sub-cell of in-plane point q = i_r + 3 i_s (counter-clockwise). Shape (9, 4).
SUB_QUADS = np.array([[c, c + 1, c + 5, c + 4] for c in (4 * j + i for j in range(3) for i in range(3))])


def is_fibre_direction(name: str) -> bool:
    """Whether a written array ``name`` is a fibre family's direction (fibre_1, not fibre_stretch_1)."""
    return name.startswith(FIBRE_PREFIX) and name[len(FIBRE_PREFIX):].isdigit()


@dataclass(frozen=True)
class OutputMesh:
    """The viewing mesh of a model.

    points (P, 3): initial positions, P = ne * L * 16; cells (C, 4) quads (shell) or (C, 8)
    hexahedra (solid), C = ne * 9 * nt for the solid, ne * 9 for the shell; layers (L,):
    thickness coordinates of the corner layers ([0] for the shell); gauss_to_nodes (9, 9):
    the element's nodal values of the biquadratic through its 3 x 3 Gauss values;
    elements_at_node (n,): how many elements share each node; node_areas (n,): each
    node's share of the initial mid-surface, int N_a dA.
    """

    points: np.ndarray
    cells: np.ndarray
    cell_type: str
    layers: np.ndarray
    gauss_to_nodes: np.ndarray
    elements_at_node: np.ndarray
    node_areas: np.ndarray

    @property
    def solid(self) -> bool:
        return self.cell_type == "hexahedron"


def _at_corners(nodal: np.ndarray, conn: np.ndarray, layers: int, weights: np.ndarray = CORNER_N) -> np.ndarray:
    """Nodal values (n, ...) interpolated to the sub-cell corners of each element by
    ``weights`` (16, 9) and repeated on each of ``layers`` corner layers: (ne * layers *
    16, ...). A NaN (no value) reaches only the corners whose weight on it is not zero."""
    at_nodes = nodal[conn]
    missing = np.isnan(at_nodes)
    values = np.einsum("ca,ea...->ec...", weights, np.where(missing, 0.0, at_nodes))
    if missing.any():
        values[np.einsum("ca,ea...->ec...", (weights != 0.0).astype(float), missing.astype(float)) > 0.0] = np.nan
    return np.repeat(values[:, None], layers, axis=1).reshape(-1, *nodal.shape[1:])


def _corner_points(x: np.ndarray, d: np.ndarray, h: np.ndarray, conn: np.ndarray, layers: np.ndarray) -> np.ndarray:
    """Positions (ne * L * 16, 3) of the sub-cell corners on each layer t of ``layers``
    (L,): mid-surface plus t times half the fibre."""
    t = np.tile(np.repeat(layers, 16), len(conn))[:, None]
    return _at_corners(x, conn, len(layers)) + t * _at_corners(0.5 * h[:, None] * d, conn, len(layers))


def output_mesh(model: Model, solid: bool = False) -> OutputMesh:
    """The shell view (mid-surface quads) or the solid view (hexahedra through the
    thickness) of ``model``."""
    ne = model.n_elements
    if solid:
        layers = -1.0 + np.concatenate([[0.0], np.cumsum(model.rule.wt)])
        bottom = (np.arange(len(model.rule.wt))[:, None, None] * 16 + SUB_QUADS[None]).reshape(-1, 4)
        local = np.hstack([bottom, bottom + 16])
    else:
        layers = np.zeros(1)
        local = SUB_QUADS
    cells = (np.arange(ne)[:, None, None] * len(layers) * 16 + local[None]).reshape(-1, local.shape[1])
    points = _corner_points(model.x0, model.d0, model.h0, model.conn, layers)
    return OutputMesh(points, cells, "hexahedron" if solid else "quad", layers,
                      gauss_to_nodes=np.linalg.inv(model.rule.N[:len(model.rule.wq)]),
                      elements_at_node=np.bincount(model.conn.ravel(), minlength=model.n_nodes),
                      node_areas=node_areas(model.x0, model.conn))


class CableMesh(NamedTuple):
    """The cables' view: points (m, 3) their nodes' initial positions, cells (L, 2) their
    elements over those points, ``nodes`` (m,) the model's node of each point."""

    points: np.ndarray
    cells: np.ndarray
    nodes: np.ndarray
    cell_type: str = "line"


def cable_mesh(model: Model) -> CableMesh | None:
    """The cables of ``model`` as line cells; None without any."""
    if model.loads.cable is None:
        return None
    ends = model.loads.cable.nodes
    nodes, cells = np.unique(ends, return_inverse=True)
    return CableMesh(points=model.x0[nodes], cells=cells.reshape(ends.shape), nodes=nodes)


def cable_fields(sim: Simulation, mesh: CableMesh) -> tuple[dict, dict]:
    """(point_data, cell_data) of the cables now: ``displacement`` (m, 3) at their nodes,
    ``stretch`` (current over rest length) and ``tension`` [force] (L,) of each element."""
    cables = sim.model.loads.cable
    stretch, tension = np.empty(len(cables.nodes)), np.empty(len(cables.nodes))
    element_states(sim.state.x, cables, stretch, tension)
    return {"displacement": sim.state.x[mesh.nodes] - mesh.points}, {"stretch": stretch, "tension": tension}


def von_mises(sigma: np.ndarray) -> np.ndarray:
    """sqrt(3/2 s:s), s the deviator of each (..., 3, 3) stress."""
    deviator = sigma - np.trace(sigma, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", deviator, deviator))


def _point_values(sim: Simulation, tensors: tuple[np.ndarray, ...], fields: list[str]) -> dict[str, np.ndarray]:
    """Each requested cell field at every integration point, (ne, nq, nt, ...), from the
    (lamina, Cauchy, Green-Lagrange) tensors there."""
    lamina, cauchy, green = tensors
    values = {"cauchy_stress": cauchy, "lamina_stress": lamina, "green_lagrange_strain": green,
              "pressure_band": pressure_band(cauchy)}
    if "von_mises" in fields:
        values["von_mises"] = von_mises(cauchy)
    if {PK2, MATERIAL_STRESS} & set(fields):
        F, jac = deformation_gradients(sim, list(range(len(sim.model.rule.tz))))
        frames0 = sim.model.material.axes0
        if PK2 in fields:
            values[PK2] = second_piola_in(frames0, F, cauchy)
        if MATERIAL_STRESS in fields:
            frames = current_material_frames(frames0, F, jac)
            values[MATERIAL_STRESS] = frames @ cauchy @ np.swapaxes(frames, -1, -2)
    return {name: values[name] for name in fields if name in CELL_FIELDS}


def contact_pressure(sim: Simulation, mesh: OutputMesh) -> np.ndarray:
    """(n,) the contact tools' force on each node over the node's share of the initial
    mid-surface (``mesh.node_areas``): the pressure the tools put on the shell; 0 at a
    cable's own node, which has no share."""
    forces = np.linalg.norm(ToolForces(sim.model, []).at_nodes(sim.state.t, sim.state.fields.shape), axis=1)
    return np.divide(forces, mesh.node_areas, out=np.zeros_like(forces), where=mesh.node_areas > 0.0)


def fibre_vectors(sim: Simulation, layers: list[int]) -> list[np.ndarray]:
    """Each fibre family's current vector F a0 at every in-plane integration point of the
    ``layers`` (indices into the thickness rule), (ne, nq, len(layers), 3) per family: its
    initial unit direction a0 (the law's ``fibres`` in the initial material frame) carried
    by the deformation gradient (:func:`~shellsim.output.derived.deformation_gradients`);
    its length is the fibre's stretch, sqrt(I4)."""
    model = sim.model
    F, _ = deformation_gradients(sim, layers)
    frames = model.material.axes0[:, :, layers]  # rows: material axes 1, 2, 3
    return [np.einsum("eqkij,eqkj->eqki", F, c * frames[..., 0, :] + s * frames[..., 1, :])
            for c, s in LAWS[model.material.law].fibres(model.material.params)]


def _smoothed(model: Model, mesh: OutputMesh, cell_values: np.ndarray) -> np.ndarray:
    """Nodal version (ne * 16, ...) at the shell view's corners of per-point values
    (ne, 9, ...): the biquadratic through an element's 3 x 3 Gauss values, read at its
    nodes, averaged over the elements sharing each node, interpolated back to the corners."""
    at_nodes = np.einsum("aq,eq...->ea...", mesh.gauss_to_nodes, cell_values)
    total = np.zeros((model.n_nodes, *cell_values.shape[2:]))
    np.add.at(total, model.conn, at_nodes)
    count = np.maximum(mesh.elements_at_node, 1)  # a cable's own node is on no element
    return _at_corners(total / count.reshape(-1, *([1] * (total.ndim - 1))), model.conn, 1)


def _columns(values: np.ndarray) -> np.ndarray:
    """(m, 1) -> (m,): scalars are written as 1D arrays."""
    return values[:, 0] if values.shape[1] == 1 else values


def _on_cells(values: np.ndarray, mesh: OutputMesh) -> np.ndarray:
    """Values (ne, nq, L, ...) at the integration points of the view's L layers as cell
    values (C, ...): the solid view's cells run over elements, layers, points."""
    return np.swapaxes(values, 1, 2).reshape(len(mesh.cells), *values.shape[3:])


def _stress_measures(sim: Simulation, cauchy: np.ndarray, depths: np.ndarray, fields: list[str], vessel_axes,
                     mesh: OutputMesh, suffix: str = "") -> dict[str, np.ndarray]:
    """The principal and vessel stresses asked for, as cell arrays named with ``suffix``,
    of the Cauchy stresses (ne, nq, L, 3, 3) on the view's L layers at thickness
    coordinates ``depths`` (L,)."""
    measures = {}
    if PRINCIPAL in fields:
        values, directions = principal_stresses(cauchy)
        for k, name in enumerate(WRITTEN_AS[PRINCIPAL]):
            measures[name + suffix] = _on_cells(values[..., k], mesh)
            measures[f"principal_direction_{k + 1}{suffix}"] = _on_cells(directions[..., k, :], mesh)
    if VESSEL in fields:
        frames = vessel_frames(sim, vessel_axes, depths)
        for name, values in zip(VESSEL_STRESSES, np.moveaxis(normal_components(cauchy, frames), -1, 0)):
            measures[name + suffix] = _on_cells(values, mesh)
    return measures


def frame_fields(sim: Simulation, mesh: OutputMesh, fields: list[str], vessel_axes=None,
                 faces: tuple[str, ...] = ()) -> tuple[dict, dict]:
    """(point_data, cell_data) of the current state for the requested ``fields``: arrays
    of shape (P,), (P, 3) or (P, 6) on the points, (C,), (C, 3) or (C, 6) on the cells;
    the tensors, all symmetric, as their six components (:data:`SYMMETRIC_PAIRS`);
    ``vessel_axes`` (a tube's or centreline's axes) for ``vessel_stress``. In the shell
    view, each stress and strain field also at the integration layer nearest each of the
    ``faces`` ("bottom", "top"), as ``<name>_bottom``, ``<name>_top``."""
    model, state = sim.model, sim.state
    point_data: dict[str, np.ndarray] = {}
    if "displacement" in fields:
        point_data["displacement"] = _corner_points(state.x, state.d, state.h, model.conn, mesh.layers) - mesh.points
    if "director" in fields:
        director = _at_corners(state.d, model.conn, len(mesh.layers))
        point_data["director"] = director / np.linalg.norm(director, axis=1, keepdims=True)
    if "thickness" in fields:
        point_data["thickness"] = _at_corners(state.h, model.conn, len(mesh.layers))
    cell_data: dict[str, np.ndarray] = {}
    tensors = sim.point_tensors() if set(fields) & {*CELL_FIELDS, PRINCIPAL, VESSEL} else None
    flats = {name: symmetric_columns(values) if values.ndim == 5 else values[..., None]  # (ne, nq, nt, 6 or 1)
             for name, values in (_point_values(sim, tensors, fields) if tensors is not None else {}).items()}
    for name, flat in flats.items():
        if mesh.solid:
            cell_data[name] = _columns(_on_cells(flat, mesh))
        else:
            through = flat.max(axis=2) if name in LARGEST_THROUGH_THICKNESS else thickness_mean(flat, model.rule.wt, axis=2)
            cell_data[name] = _columns(through.reshape(len(mesh.cells), -1))
            point_data[name + NODAL_SUFFIX] = _columns(_smoothed(model, mesh, through))
    if CONTACT_PRESSURE in fields:
        point_data[CONTACT_PRESSURE] = _at_corners(contact_pressure(sim, mesh), model.conn, len(mesh.layers),
                                                   CORNER_HATS)
    if CONTACT_GAP in fields:
        gaps = ToolForces(sim.model, []).gaps(sim.state.t, sim.state.fields.shape)
        point_data[CONTACT_GAP] = _at_corners(gaps, model.conn, len(mesh.layers), CORNER_HATS)
    if {PRINCIPAL, VESSEL} & set(fields):  # of each layer's stress in the solid view, of the mean in the shell view
        cauchy = tensors[1] if mesh.solid else thickness_mean(tensors[1], model.rule.wt, axis=2)[:, :, None]
        cell_data |= _stress_measures(sim, cauchy, model.rule.tz if mesh.solid else np.zeros(1), fields, vessel_axes,
                                      mesh)
    for face in () if mesh.solid else faces:  # the integration layer nearest the face
        k = 0 if face == "bottom" else len(model.rule.tz) - 1
        for name, flat in flats.items():
            cell_data[f"{name}_{face}"] = _columns(flat[:, :, k].reshape(len(mesh.cells), -1))
        if {PRINCIPAL, VESSEL} & set(fields):
            cell_data |= _stress_measures(sim, tensors[1][:, :, k:k + 1], model.rule.tz[k:k + 1], fields,
                                          vessel_axes, mesh, f"_{face}")
    if {FIBRES, FIBRE_STRETCH} & set(fields):  # every layer's in the solid view, the middle layer's in the shell view
        nt = len(model.rule.tz)
        for family, vectors in enumerate(fibre_vectors(sim, list(range(nt)) if mesh.solid else [nt // 2]), start=1):
            stretch = np.linalg.norm(vectors, axis=-1)
            if FIBRES in fields:
                cell_data[f"{FIBRE_PREFIX}{family}"] = _on_cells(vectors / stretch[..., None], mesh)
            if FIBRE_STRETCH in fields:
                cell_data[f"{FIBRE_STRETCH}_{family}"] = _on_cells(stretch, mesh)
    return point_data, cell_data
