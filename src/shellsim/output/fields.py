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
from functools import cached_property
from typing import NamedTuple

import numpy as np

from ..deck.output_fields import FIELD_KINDS, FIELDS, WRITTEN_AS
from ..element.sampling import pressure_band, thickness_mean
from ..element.shape import NODE_RS, gauss_rule, shape
from ..materials.laws import LAWS
from ..mesh import SOURCE_ELEMENT, SOURCE_NODE, Mesh, node_areas
from ..model import Model
from ..solver.simulation import Simulation
from ..loads import ToolForces
from ..loads.cable import element_states
from .derived import (VESSEL_STRESSES, current_material_frames, deformation_gradients, normal_components,
                      principal_stresses, second_piola_in, vessel_frames)
from .encoding import symmetric_columns
from .units import NODAL_SUFFIX

#: The output field of fibre directions, written as one cell vector per family:
#: fibre_1, fibre_2, ...; and of their stretches, fibre_stretch_1, ...
FIBRE_PREFIX = "fibre_"
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


#: Which element node each sub-cell corner is, where it is one (the element's corners): (16, 9).
CORNER_IS_NODE = np.all(np.isclose(CORNER_RS[:, None, :], NODE_RS[None], rtol=0.0, atol=1e-12), axis=2).astype(float)


def source_ids(mesh: Mesh, model: Model, view: OutputMesh) -> tuple[dict, dict]:
    """(point_data, cell_data) of a model file's numbers that ``mesh`` carries (an imported
    mesh's :data:`~shellsim.mesh.SOURCE_NODE` and ``SOURCE_ELEMENT``) on the
    view: a node's number at the points that are it (an element's corners; 0 elsewhere),
    an element's on each of its cells; empty where the mesh has none."""
    points, cells = {}, {}
    if SOURCE_NODE in mesh.point_fields:
        points[SOURCE_NODE] = _at_corners(mesh.point_fields[SOURCE_NODE], model.conn, len(view.layers), CORNER_IS_NODE)
    if SOURCE_ELEMENT in mesh.cell_fields:
        cells[SOURCE_ELEMENT] = np.repeat(mesh.cell_fields[SOURCE_ELEMENT], len(view.cells) // model.n_elements)
    return points, cells


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
    its length is the fibre's stretch, sqrt(I4). Family k of each part's law; NaN in the
    elements of a part whose law has fewer families."""
    material, part = sim.model.material, sim.model.body.part
    F, _ = deformation_gradients(sim, layers)
    frames = material.axes0[:, :, layers]  # rows: material axes 1, 2, 3
    directions = [LAWS[law].fibres(params) for law, params in zip(material.law, material.params)]
    vectors = []
    for family in range(max(len(fibres) for fibres in directions)):
        a0 = np.full(frames.shape[:-1], np.nan)
        for i, fibres in enumerate(directions):
            if family < len(fibres):
                c, s = fibres[family]
                mine = part == i
                own = frames[mine]
                a0[mine] = c * own[..., 0, :] + s * own[..., 1, :]
        vectors.append(np.einsum("eqkij,eqkj->eqki", F, a0))
    return vectors


def _smoothed(model: Model, mesh: OutputMesh, cell_values: np.ndarray) -> np.ndarray:
    """Nodal version (ne * 16, ...) at the shell view's corners of per-point values
    (ne, 9, ...): the biquadratic through an element's 3 x 3 Gauss values, read at its
    nodes, averaged over the elements sharing each node, interpolated back to the corners,
    and clipped to the range of the per-point values (each column's own): extrapolated
    to the nodes and read between them, a quadratic overshoots where a field turns
    sharply, and a von Mises stress below zero, or a peak above any the element holds,
    is not one to show."""
    at_nodes = np.einsum("aq,eq...->ea...", mesh.gauss_to_nodes, cell_values)
    total = np.zeros((model.n_nodes, *cell_values.shape[2:]))
    np.add.at(total, model.conn, at_nodes)
    count = np.maximum(mesh.elements_at_node, 1)  # a cable's own node is on no element
    corners = _at_corners(total / count.reshape(-1, *([1] * (total.ndim - 1))), model.conn, 1)
    return np.clip(corners, np.nanmin(cell_values, axis=(0, 1)), np.nanmax(cell_values, axis=(0, 1)))


def _columns(values: np.ndarray) -> np.ndarray:
    """(m, 1) -> (m,): scalars are written as 1D arrays."""
    return values[:, 0] if values.shape[1] == 1 else values


def _on_cells(values: np.ndarray, mesh: OutputMesh) -> np.ndarray:
    """Values (ne, nq, L, ...) at the integration points of the view's L layers as cell
    values (C, ...): the solid view's cells run over elements, layers, points."""
    return np.swapaxes(values, 1, 2).reshape(len(mesh.cells), *values.shape[3:])


class Frame:
    """What one frame's fields are computed from: the simulation ``sim`` now, the view
    ``mesh`` and the ``vessel_axes``; each intermediate the fields share (the tensors at
    the integration points, the fibres' vectors) computed once, when a field first asks."""

    def __init__(self, sim: Simulation, mesh: OutputMesh, vessel_axes=None):
        self.sim, self.mesh, self.vessel_axes = sim, mesh, vessel_axes

    @cached_property
    def tensors(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lamina stress, Cauchy stress, Green-Lagrange strain) at every integration point,
        (ne, nq, nt, 3, 3) each."""
        return self.sim.point_tensors()

    def cauchy(self, layer: int | None) -> tuple[np.ndarray, np.ndarray]:
        """(Cauchy stresses (ne, nq, L, 3, 3), their thickness coordinates (L,)) of the view
        (``layer`` None: every layer in the solid view, the thickness mean in the shell
        view) or of the integration layer ``layer``."""
        cauchy, rule = self.tensors[1], self.sim.model.rule
        if layer is not None:
            return cauchy[:, :, layer:layer + 1], rule.tz[layer:layer + 1]
        if self.mesh.solid:
            return cauchy, rule.tz
        return thickness_mean(cauchy, rule.wt, axis=2)[:, :, None], np.zeros(1)

    @cached_property
    def fibre_vectors(self) -> list[np.ndarray]:
        """Each fibre family's current vector (ne, nq, L, 3) on the view's layers: every
        layer in the solid view, the middle one in the shell view (:func:`fibre_vectors`)."""
        nt = len(self.sim.model.rule.tz)
        return fibre_vectors(self.sim, list(range(nt)) if self.mesh.solid else [nt // 2])

    def on_corners(self, nodal: np.ndarray, weights: np.ndarray = CORNER_N) -> np.ndarray:
        """Nodal values (n, ...) on the view's points (:func:`_at_corners`)."""
        return _at_corners(nodal, self.sim.model.conn, len(self.mesh.layers), weights)


# The fields' functions, one per field of :data:`shellsim.deck.output_fields.FIELDS`, by
# where it lives: a node field's gives its values on the view's points (P, ...); a point
# field's its values at every integration point (ne, nq, nt) or (ne, nq, nt, 3, 3); a
# cell field's, of the view (``layer`` None) or of one integration layer, its arrays by
# name, (ne, nq, L, ...) on the L layers.

def _displacement(frame: Frame) -> np.ndarray:
    state, model = frame.sim.state, frame.sim.model
    return _corner_points(state.x, state.d, state.h, model.conn, frame.mesh.layers) - frame.mesh.points


def _director(frame: Frame) -> np.ndarray:
    director = frame.on_corners(frame.sim.state.d)
    return director / np.linalg.norm(director, axis=1, keepdims=True)


def _contact_gap(frame: Frame) -> np.ndarray:
    sim = frame.sim
    return frame.on_corners(ToolForces(sim.model, []).gaps(sim.state.t, sim.state.fields.shape), CORNER_HATS)


def _material_stress(frame: Frame) -> np.ndarray:
    F, jac = deformation_gradients(frame.sim, list(range(len(frame.sim.model.rule.tz))))
    frames = current_material_frames(frame.sim.model.material.axes0, F, jac)
    return frames @ frame.tensors[1] @ np.swapaxes(frames, -1, -2)


def _pk2_stress(frame: Frame) -> np.ndarray:
    F, _ = deformation_gradients(frame.sim, list(range(len(frame.sim.model.rule.tz))))
    return second_piola_in(frame.sim.model.material.axes0, F, frame.tensors[1])


def _principal_stress(frame: Frame, layer: int | None) -> dict[str, np.ndarray]:
    values, directions = principal_stresses(frame.cauchy(layer)[0])
    arrays = {}
    for k, name in enumerate(WRITTEN_AS["principal_stress"]):
        arrays[name], arrays[f"principal_direction_{k + 1}"] = values[..., k], directions[..., k, :]
    return arrays


def _vessel_stress(frame: Frame, layer: int | None) -> dict[str, np.ndarray]:
    cauchy, depths = frame.cauchy(layer)
    stresses = normal_components(cauchy, vessel_frames(frame.sim, frame.vessel_axes, depths))
    return dict(zip(VESSEL_STRESSES, np.moveaxis(stresses, -1, 0)))


def _fibres(frame: Frame, layer: int | None) -> dict[str, np.ndarray]:
    return {f"{FIBRE_PREFIX}{family}": vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)
            for family, vectors in enumerate(frame.fibre_vectors, start=1)}


def _fibre_stretch(frame: Frame, layer: int | None) -> dict[str, np.ndarray]:
    return {f"fibre_stretch_{family}": np.linalg.norm(vectors, axis=-1)
            for family, vectors in enumerate(frame.fibre_vectors, start=1)}


#: Each field's function, by its name.
COMPUTE = {
    "displacement": _displacement,
    "director": _director,
    "thickness": lambda frame: frame.on_corners(frame.sim.state.h),
    "thickness_stretch": lambda frame: frame.on_corners(frame.sim.state.h / frame.sim.model.h0),
    "cauchy_stress": lambda frame: frame.tensors[1],
    "lamina_stress": lambda frame: frame.tensors[0],
    "pressure_band": lambda frame: pressure_band(frame.tensors[1]),
    "green_lagrange_strain": lambda frame: frame.tensors[2],
    "von_mises": lambda frame: von_mises(frame.tensors[1]),
    "pk2_stress": _pk2_stress,
    "material_stress": _material_stress,
    "contact_pressure": lambda frame: frame.on_corners(contact_pressure(frame.sim, frame.mesh), CORNER_HATS),
    "contact_gap": _contact_gap,
    "principal_stress": _principal_stress,
    "vessel_stress": _vessel_stress,
    "fibres": _fibres,
    "fibre_stretch": _fibre_stretch,
}
if set(COMPUTE) != set(FIELD_KINDS):  # a declared field without its function, or one the deck cannot ask for
    raise ImportError(f"output fields declared without a function: {sorted(set(FIELD_KINDS) - set(COMPUTE))}; "
                      f"functions of no declared field: {sorted(set(COMPUTE) - set(FIELD_KINDS))}")


def frame_fields(sim: Simulation, mesh: OutputMesh, fields: list[str], vessel_axes=None,
                 faces: tuple[str, ...] = ()) -> tuple[dict, dict]:
    """(point_data, cell_data) of the current state for the requested ``fields``: arrays
    of shape (P,), (P, 3) or (P, 6) on the points, (C,), (C, 3) or (C, 6) on the cells;
    the tensors, all symmetric, as their six components (:data:`SYMMETRIC_PAIRS`);
    ``vessel_axes`` (a tube's or centreline's axes) for ``vessel_stress``. A point field
    is written per sub-cell (the shell view: its thickness mean, or its largest value
    through the thickness, :data:`LARGEST_THROUGH_THICKNESS`) with a smoothed
    ``<name>_nodal``. In the shell view, each point field and each cell field with
    ``faces`` also at the integration layer nearest each of the ``faces`` ("bottom",
    "top"), as ``<name>_bottom``, ``<name>_top``."""
    frame, model = Frame(sim, mesh, vessel_axes), sim.model
    kinds = [kind for kind in FIELDS if kind.name in fields]
    point_data: dict[str, np.ndarray] = {}
    cell_data: dict[str, np.ndarray] = {}
    flats = {}  # each point field's values (ne, nq, nt, 6 or 1)
    for kind in kinds:
        values = COMPUTE[kind.name](frame) if kind.lives != "cell" else None
        if kind.lives == "node":
            point_data[kind.name] = values
        elif kind.lives == "point":
            flat = flats[kind.name] = symmetric_columns(values) if values.ndim == 5 else values[..., None]
            if mesh.solid:
                cell_data[kind.name] = _columns(_on_cells(flat, mesh))
            else:
                through = (flat.max(axis=2) if kind.name in LARGEST_THROUGH_THICKNESS
                           else thickness_mean(flat, model.rule.wt, axis=2))
                cell_data[kind.name] = _columns(through.reshape(len(mesh.cells), -1))
                point_data[kind.name + NODAL_SUFFIX] = _columns(_smoothed(model, mesh, through))
        else:
            arrays = COMPUTE[kind.name](frame, None)
            cell_data |= {name: _on_cells(array, mesh) for name, array in arrays.items()}
            if kind.measures == "stress" and not mesh.solid:  # the stresses' smoothed versions
                point_data |= {name + NODAL_SUFFIX: _smoothed(model, mesh, arrays[name][:, :, 0])
                               for name in kind.written_as}
    for face in () if mesh.solid else faces:  # the integration layer nearest the face
        k = 0 if face == "bottom" else len(model.rule.tz) - 1
        for name, flat in flats.items():
            cell_data[f"{name}_{face}"] = _columns(flat[:, :, k].reshape(len(mesh.cells), -1))
        for kind in kinds:
            if kind.lives == "cell" and kind.faces:
                cell_data |= {f"{name}_{face}": _on_cells(array, mesh)
                              for name, array in COMPUTE[kind.name](frame, k).items()}
    return point_data, cell_data
