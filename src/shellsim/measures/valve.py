"""Valve measures: what a deck's ``[output.valve]`` reads from a running simulation, resolved
once on the mesh and read at the history samples it asks for; a measure family
(:mod:`shellsim.measures`) measured at some samples only.

The orifice is read on a raster of the plane across the valve's axis: the inside of the
annulus (its nodes' ring seen along the axis) less the leaflets' shadow. A leaflet's shadow
is its solid's, drawn as each element's top and bottom faces and the walls along its four
edges (a solid's shadow is its boundary's), so two leaflets pressed together leave no slit
between their mid-surfaces, and a leaflet seen edge-on still covers its thickness.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit
from pydantic import Field, model_validator
from scipy.ndimage import distance_transform_edt

from ..bundles import Model
from ..element.kinematics import fibre_point
from ..element.sampling import integration_points
from ..element.shape import EDGES
from ..loads import ToolForces
from ..mesh import Mesh, node_areas
from ..table_types import Name, Section, Vec3, need_directions
from .column import Column

class Valve(Section):
    """``[output.valve]``: a valve's measures in history.csv (columns ``orifice_area``,
    ``regurgitant_gap``, ``coaptation_area``, ``coaptation_height``,
    ``peak_principal_stress``) and their final, smallest and largest values in
    summary.json, for the ``leaflets`` (a surface set) hanging from the ``annulus`` (an edge
    set), the valve's ``axis`` pointing downstream.

    ``orifice_area``: the geometric orifice area, the inside of the annulus seen along the
    axis that no leaflet's solid covers (read on a raster of ``resolution`` pixels across
    the annulus: to about half a pixel along the orifice's edge); ``regurgitant_gap``: the
    widest opening, the diameter of the largest disc that fits through the orifice (0 when
    shut; to about a pixel); ``coaptation_area``: half the leaflets' surface carrying
    contact force (each pair of coapting surfaces once); ``coaptation_height``: the extent
    along the axis of the nodes in contact within a quarter of the annulus radius of the
    axis, where the leaflets meet in the middle; ``peak_principal_stress``: the largest
    principal Cauchy stress at the leaflets' integration points, every layer;
    ``peak_principal_stress_away``: the same at the points farther from the annulus (on the
    initial mid-surface) than ``stress_clearance`` times the annulus radius. Where a clamped
    attachment meets a free edge the stress is singular and its peak grows with each
    refinement; away from the annulus it converges. A measurement costs a raster and a
    stress evaluation, so it is taken at ``samples`` evenly spaced times (the history
    samples between hold nan in its columns)."""

    #: The measures' history columns, each with what it measures (for units).
    COLUMNS: ClassVar[dict[str, str]] = {"orifice_area": "area", "regurgitant_gap": "length",
                                         "coaptation_area": "area", "coaptation_height": "length",
                                         "peak_principal_stress": "stress", "peak_principal_stress_away": "stress"}

    leaflets: Name = "all"
    annulus: Name
    axis: Vec3 = (0.0, 0.0, 1.0)
    resolution: int = Field(default=400, ge=50, le=10000)
    samples: int = Field(default=200, ge=1, le=100000)
    stress_clearance: float = Field(default=0.1, ge=0.0, le=1.0)

    @model_validator(mode="after")
    def _axis_has_direction(self) -> "Valve":
        need_directions(self, "axis")
        return self


#: The measures' history columns, each with what it measures (for units).
VALVE_COLUMNS = Valve.COLUMNS
#: An element's boundary nodes in order around it (corner, mid-side, corner, ...).
RIM = EDGES[:, :2].ravel()
#: The halves of the element's edges, (node, next node along the edge) each. Shape (8, 2).
EDGE_HALVES = np.concatenate([EDGES[:, :2], EDGES[:, 1:]])
#: Share of the annulus radius about the axis within which the coaptation height is read.
CENTRAL = 0.25


@dataclass
class ValveMeasures:
    """Where the valve measures read.

    elements : (m,) the leaflets' elements; nodes : their nodes; annulus : (k,) the annulus nodes in order
    around the axis; frame : (3, 3) rows e1, e2 across the axis and the axis; resolution :
    the raster's pixels across the annulus; areas : (n,) each node's share of the initial
    mid-surface; radius : the annulus' mean initial distance from its centre, across the
    axis; every : the simulated time between measurements, next_time : when the next is
    due; contact : the contact forces at the nodes (whose nodes touch); away : (m, nq) bool,
    the in-plane integration points clear of the annulus.
    """

    elements: np.ndarray
    nodes: np.ndarray
    annulus: np.ndarray
    frame: np.ndarray
    resolution: int
    areas: np.ndarray
    radius: float
    every: float
    contact: ToolForces
    away: np.ndarray
    next_time: float = 0.0

    NAME = "valve"
    sparse = True
    columns = list(VALVE_COLUMNS)

    def sample(self, run) -> list[float]:
        """The measures at a sample where they are due (:meth:`due`), NaN at the others."""
        measured = self(run.sim) if self.due(run.sim.state.t) else dict.fromkeys(VALVE_COLUMNS, math.nan)
        return list(measured.values())

    def record(self, run, output_seconds: float) -> dict:
        """Each measure's last, smallest and largest value over the samples measured
        (None for all three when none was)."""
        record = {}
        for column in VALVE_COLUMNS:
            values = np.asarray(run.history[column])
            measured = values[~np.isnan(values)]
            record[column] = ({"final": float(measured[-1]), "min": float(measured.min()),
                               "max": float(measured.max())} if len(measured) else dict.fromkeys(("final", "min", "max")))
        return record

    def due(self, t: float) -> bool:
        """Whether the sample at time t is measured (each ``every``, the first from t = 0),
        the next measurement then being due one ``every`` on."""
        if t < self.next_time * (1.0 - 1e-12):
            return False
        self.next_time = (math.floor(t / self.every + 1e-9) + 1.0) * self.every
        return True

    def __call__(self, sim) -> dict[str, float]:
        """The measures now in ``sim`` (a :class:`shellsim.solver.simulation.Simulation`),
        by column name: see :class:`Valve`; nan for each while the
        positions are no numbers (a run breaking down, its stability check next)."""
        state, conn = sim.state, sim.model.conn[self.elements]
        if not np.isfinite(state.x).all():
            return dict.fromkeys(VALVE_COLUMNS, math.nan)
        open_pixels, pixel = self.opening(state.x, state.d, state.h, conn)
        forces = self.contact.at_nodes(state.t, state.fields.shape)
        touching = self.nodes[np.linalg.norm(forces[self.nodes], axis=1) > 0.0]
        principal = largest_principal(sim.point_tensors(self.elements)[1])  # (m, nq, nt)
        away = principal[self.away]
        return {
            "orifice_area": float(open_pixels.sum() * pixel**2),
            "regurgitant_gap": widest_opening(open_pixels) * pixel,
            "coaptation_area": float(0.5 * self.areas[touching].sum()),
            "coaptation_height": self.central_extent(state.x, touching),
            "peak_principal_stress": float(principal.max()),
            "peak_principal_stress_away": float(away.max()) if away.size else math.nan,
        }

    def central_extent(self, x: np.ndarray, touching: np.ndarray) -> float:
        """The extent along the axis of the ``touching`` nodes within CENTRAL of the annulus
        radius of the axis through the annulus' centre: the coaptation height where the
        leaflets meet in the middle (0 where none touch there)."""
        local = (x[touching] - x[self.annulus].mean(axis=0)) @ self.frame.T
        central = local[np.hypot(local[:, 0], local[:, 1]) <= CENTRAL * self.radius, 2]
        return float(np.ptp(central)) if len(central) else 0.0

    def opening(self, x: np.ndarray, d: np.ndarray, h: np.ndarray, conn: np.ndarray) -> tuple[np.ndarray, float]:
        """(open (rows, columns) bool, pixel size): the raster of the annulus' inside seen
        along the axis that none of the elements ``conn`` (m, 9) covers, for nodes at x
        (n, 3) with directors d (n, 3) and fibre lengths h (n,). A pixel is inside a shape
        when its centre is."""
        ring = x[self.annulus] @ self.frame[:2].T
        low, high = ring.min(axis=0), ring.max(axis=0)
        pixel = float((high - low).max()) / self.resolution
        columns, rows = (int(n) + 2 for n in np.ceil((high - low) / pixel))

        def raster(points: np.ndarray) -> np.ndarray:  # (..., 3) -> (..., 2) pixel units, a pixel's margin
            return (points @ self.frame[:2].T - low) / pixel + 1.0

        inside = np.zeros((rows, columns), dtype=bool)
        fill_triangles(inside, fan(raster(x[self.annulus])))
        covered = np.zeros((rows, columns), dtype=bool)
        fill_triangles(covered, shadow_triangles(raster(fibre_point(x, d, h[:, None], 1.0))[conn],
                                                 raster(fibre_point(x, d, h[:, None], -1.0))[conn]))
        return inside & ~covered, pixel


def fan(ring: np.ndarray) -> np.ndarray:
    """Triangles (k, 3, 2) from the centroid of the closed polygon ``ring`` (k, 2) to each
    of its sides: the polygon, when it is star-shaped about its centroid."""
    centre = np.broadcast_to(ring.mean(axis=0), ring.shape)
    return np.stack([centre, ring, np.roll(ring, -1, axis=0)], axis=1)


def shadow_triangles(top: np.ndarray, bottom: np.ndarray) -> np.ndarray:
    """Triangles (m * 32, 3, 2) covering the shadow of elements whose nodes' top and
    bottom face points are ``top`` and ``bottom`` (m, 9, 2) in the plane: each face as
    eight triangles from its centre node to its rim, each half of each edge's wall
    between the faces as two."""
    faces = [np.stack([np.repeat(face[:, 8:], 8, axis=1), face[:, RIM], face[:, np.roll(RIM, -1)]], axis=2)
             for face in (top, bottom)]
    a, b = EDGE_HALVES[:, 0], EDGE_HALVES[:, 1]
    walls = [np.stack([top[:, a], top[:, b], bottom[:, b]], axis=2), np.stack([top[:, a], bottom[:, b], bottom[:, a]], axis=2)]
    return np.concatenate(faces + walls, axis=1).reshape(-1, 3, 2)


@njit(cache=True)
def fill_triangles(pixels: np.ndarray, triangles: np.ndarray) -> None:
    """Set the ``pixels`` (rows, columns) whose centres lie in any of ``triangles``
    (T, 3, 2), given in pixel units (x along the columns, y along the rows: pixel (r, c)
    is centred at (c + 0.5, r + 0.5)); a centre on an edge is inside."""
    rows, columns = pixels.shape
    for k in range(triangles.shape[0]):
        (ax, ay), (bx, by), (cx, cy) = triangles[k, 0], triangles[k, 1], triangles[k, 2]
        twice_area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if twice_area == 0.0:
            continue
        sign = 1.0 if twice_area > 0.0 else -1.0
        first_column = max(int(math.ceil(min(ax, bx, cx) - 0.5)), 0)
        last_column = min(int(math.floor(max(ax, bx, cx) - 0.5)), columns - 1)
        for r in range(max(int(math.ceil(min(ay, by, cy) - 0.5)), 0),
                       min(int(math.floor(max(ay, by, cy) - 0.5)), rows - 1) + 1):
            py = r + 0.5
            for c in range(first_column, last_column + 1):
                px = c + 0.5
                if (sign * ((bx - ax) * (py - ay) - (by - ay) * (px - ax)) >= 0.0
                        and sign * ((cx - bx) * (py - by) - (cy - by) * (px - bx)) >= 0.0
                        and sign * ((ax - cx) * (py - cy) - (ay - cy) * (px - cx)) >= 0.0):
                    pixels[r, c] = True


def largest_principal(tensors: np.ndarray) -> np.ndarray:
    """The largest eigenvalue of each symmetric (..., 3, 3) tensor, in closed form: the
    trigonometric solution of the deviator's characteristic cubic (Smith 1961, Commun.
    ACM 4:168), about six times faster than eigvalsh's loop over small matrices."""
    mean = (tensors[..., 0, 0] + tensors[..., 1, 1] + tensors[..., 2, 2]) / 3.0
    d = tensors - mean[..., None, None] * np.eye(3)
    size = np.sqrt(np.einsum("...ij,...ij->...", d, d) / 6.0)
    det = (d[..., 0, 0] * (d[..., 1, 1] * d[..., 2, 2] - d[..., 1, 2] * d[..., 2, 1])
           - d[..., 0, 1] * (d[..., 1, 0] * d[..., 2, 2] - d[..., 1, 2] * d[..., 2, 0])
           + d[..., 0, 2] * (d[..., 1, 0] * d[..., 2, 1] - d[..., 1, 1] * d[..., 2, 0]))
    cosine = det / np.where(size > 0.0, 2.0 * size**3, 1.0)
    return mean + 2.0 * size * np.cos(np.arccos(np.clip(cosine, -1.0, 1.0)) / 3.0)


def distances_to_edges(points: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(p,) each of ``points`` (p, 3)'s distance to the nearest of the segments from
    ``starts`` to ``ends`` (s, 3) (a segment of no length is its point)."""
    along = ends - starts
    lengths = np.maximum(np.einsum("si,si->s", along, along), np.finfo(float).tiny)
    nearest = np.empty(len(points))
    for first in range(0, len(points), 2048):  # (2048, s, 3) at a time
        offsets = points[first:first + 2048, None, :] - starts
        share = np.clip(np.einsum("psi,si->ps", offsets, along) / lengths, 0.0, 1.0)
        gaps = offsets - share[..., None] * along
        nearest[first:first + 2048] = np.sqrt(np.einsum("psi,psi->ps", gaps, gaps).min(axis=1))
    return nearest


def widest_opening(open_pixels: np.ndarray) -> float:
    """The diameter, in pixels, of the largest disc inside the ``open_pixels``: twice the
    largest distance from an open pixel to a closed one (0 when none is open)."""
    rows, columns = np.nonzero(open_pixels)
    if not len(rows):
        return 0.0
    window = np.pad(open_pixels[rows.min():rows.max() + 1, columns.min():columns.max() + 1], 1)
    return float(2.0 * distance_transform_edt(window).max())


#: Its table: ``[output.valve]``, one or none (:data:`shellsim.measures.FAMILIES`).
TABLE, OUTPUT_KEY, OUTPUT_FIELD = Valve, "valve", (Valve | None, None)


def columns(deck) -> list[Column]:
    """The valve's measures, named by shellsim."""
    valve = deck.output.valve
    return [] if valve is None else [Column(name, "output.valve", "a valve measure's", quantity, chosen=False)
                                     for name, quantity in valve.COLUMNS.items()]


def named_sets(deck) -> list[tuple[str, str, tuple[str, ...]]]:
    """The leaflets (a surface set) and the annulus (an edge or point set)."""
    valve = deck.output.valve
    return [] if valve is None else [("output.valve.leaflets", valve.leaflets, ("surface",)),
                                     ("output.valve.annulus", valve.annulus, ("edge", "point"))]


def resolve(deck, mesh: Mesh, model: Model) -> ValveMeasures | None:
    """The deck's ``[output.valve]`` placed on the mesh (None without one)."""
    return resolve_valve(deck.output.valve, mesh, model, deck.solver.end_time)


def resolve_valve(table: Valve | None, mesh: Mesh, model: Model, end_time: float) -> ValveMeasures | None:
    """A ``[output.valve]`` table placed on the mesh of a run to ``end_time`` (None without
    one): the leaflets' elements, the annulus nodes ordered by angle about the axis through
    their centre, and a frame across the axis."""
    if table is None:
        return None
    axis = np.asarray(table.axis, dtype=float) / np.linalg.norm(table.axis)
    e1 = np.cross(axis, (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0))
    e1 /= np.linalg.norm(e1)
    frame = np.array([e1, np.cross(axis, e1), axis])
    nodes = mesh.sets[table.annulus].nodes
    across = (model.x0[nodes] - model.x0[nodes].mean(axis=0)) @ frame[:2].T
    order = np.argsort(np.arctan2(across[:, 1], across[:, 0]))
    elements = mesh.sets[table.leaflets].elements
    radius = float(np.linalg.norm(across, axis=1).mean())
    return ValveMeasures(elements=elements, nodes=np.unique(model.conn[elements]), annulus=nodes[order], frame=frame,
                         resolution=table.resolution, areas=node_areas(model.x0, model.conn), radius=radius,
                         every=end_time / table.samples, contact=ToolForces(model, []),
                         away=clear_of_annulus(model, elements, nodes, table.stress_clearance * radius))


def clear_of_annulus(model: Model, elements: np.ndarray, annulus: np.ndarray, clearance: float) -> np.ndarray:
    """(m, nq) bool: which in-plane integration points of ``elements`` (m,) lie farther than
    ``clearance`` from the ``annulus`` nodes and the element edge halves between them, on
    the initial mid-surface."""
    conn = model.conn[elements]
    points = integration_points(model.x0, conn, model.rule.N[:len(model.rule.wq)])
    halves = conn[:, EDGE_HALVES.ravel()].reshape(-1, 2)
    halves = halves[np.isin(halves, annulus).all(axis=1)]
    starts = np.concatenate([model.x0[halves[:, 0]], model.x0[annulus]])
    ends = np.concatenate([model.x0[halves[:, 1]], model.x0[annulus]])
    return (distances_to_edges(points.reshape(-1, 3), starts, ends) > clearance).reshape(points.shape[:2])
