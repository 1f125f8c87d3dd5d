"""Contact between shells: a surface set that folds onto itself (self-contact) or meets
another set, by penalty, node against face both ways (the search is
:mod:`shellsim.loads.contact_search`).

The shell's faces are its mid-surface offset by half the fibre length on each side (the
shell thickness offset of LS-DYNA's contacts): a node y of one side and the nearest point
p of a face of the other are in contact when their distance is less than
``offset`` (h_y + h_p) / 2, h the initial fibre lengths (h_p interpolated on the face).
The contact's thickness does not follow the shell's thinning (LS-DYNA's default,
THKCHG = 0): a thickness that changed under a held contact would store or release spring
energy that no force accounts for (a closed valve held under pressure crept, its balance
error growing to 6% in 0.16 s; docs/verification.md).
The gap g = |y - p| - offset (h_y + h_p) / 2 is then negative and the node is pushed
out along n = (y - p) / |y - p| by F = -k g n, the face's nine nodes back by N_a(p) F
(the face's shape functions where p is). Both sides are tested: each node of the set
against the faces of the other, and each node of the other against the faces of the set,
so neither side's nodes pass through; a node takes the nearest face it penetrates, never
one that holds it, nor one it overlapped in the initial shape (neighbours of a thick
shell, or two sets meshed overlapping; found once, when the model is built), as
LS-DYNA's ``IGNORE`` does. The forces act at
the mid-surface, on the translations only. With ``friction`` mu, the node's velocity
relative to the face point, tangent to the face, is opposed by mu times the push, spread
back to the face's nodes by N_a (:func:`add_friction`).

The penalty is the soft constraint of explicit codes: a spring between the node (mass
m_y) and the face point (the face's masses m_a weighted by N_a^2) of
k = s / (dt_c^2 (1/m_y + sum_a N_a^2 / m_a)) raises the highest frequency squared by
at most s / dt_c^2 per pass; with both passes in parallel the critical step is taken as
dt_c / sqrt(1 + s / 2). The springs' scale is fixed when the run starts
(:func:`calibrate`), so the forces are conservative but for the nearest point's slide
along the face.

The search keeps each contact node's list of the faces it may touch (Verlet's neighbour
lists, Phys. Rev. 159, 98, 1967): those whose box lies within the contact's reach
and a skin more (:data:`SKIN`), found on the bucket grid. While the nodes and the faces'
boxes have moved less than the skin since the lists were made, no face outside a node's
list can come within its reach, so an evaluation tests only the listed faces, against
the reach as it is, and finds the same faces the grid would; beyond that the lists are
made again. On two stacked plates whose every node touches, a grid cell held some 74
faces for a node and 2.2 of them within reach.
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
import scipy.sparse as sp
from numba import njit, prange
from scipy.sparse.csgraph import connected_components

from ..array_copy import copy_into
from ..bundles import Shape
from ..element.shape import GRID
from ..errors import MeshError
from ..table_types import Name, NonNegative, Positive
from . import penalty_law
from .penalty_law import TOUCHING
from .contact_search import cell_faces, face_boxes, fill_grid, near_box, nearest_point, projection_scratch
from .table import ContactTable


class ShellContact(ContactTable):
    """Contact of the faces of the surface set ``set`` with those of ``against`` (leaflet on
    leaflet), or with its own (no ``against``: self-contact, a strip rolling over itself).
    ``offset``: the share of the half thicknesses kept between mid-surfaces (1: the faces
    touch). ``penalty``: the soft constraint's scale s (the critical step falls by the
    factor 1 / sqrt(1 + s / 2)). ``friction``: Coulomb's mu between the faces.
    ``own_surface_limit``: where a surface meets itself (self-contact), a node's contact
    thickness is at most this share of the shortest spacing of the nodes around it, as
    LS-DYNA limits a single-surface contact's to 40% of the shortest edge (SSTHK = 0); 0:
    the shell's thickness (SSTHK = 1). ``name``: the history column of the contact force
    (the sum of the contact forces' magnitudes, both ways)."""

    type: Literal["shells"]
    against: Name | None = None
    offset: Positive = 1.0
    own_surface_limit: NonNegative = 0.4

    @property
    def named_sets(self) -> dict[str, str]:
        """The sets the table names, by key."""
        return {"set": self.set} | ({"against": self.against} if self.against else {})

    @property
    def summary(self) -> str:
        """One line for ``shellsim check``."""
        other = f"'{self.against}'" if self.against else "itself"
        limit = (f" (against its own surface at most {self.own_surface_limit:g} x the node spacing)"
                 if self.against is None and self.own_surface_limit else "")
        return (f"'{self.name}': shell faces of '{self.set}' against {other}, both ways, {self.offset:g} x the half "
                f"thicknesses apart{limit}; penalty {self.penalty:g}, the critical step x "
                f"{share_of(self.penalty):.3f}{self.friction_summary}")


TABLES = (ShellContact,)

#: The contact nodes are searched in this many chunks shared among the threads (a count
#: the compiled code may not read from the threading layer and still be cached).
CHUNKS = 64

#: The most separate surfaces of a self-contact's set taken each against each (more are
#: taken as one surface, each node with one face), and the passes a table may have.
MOST_SURFACES = 16
PASSES = MOST_SURFACES**2

#: The most faces a node may overlap in the initial shape (those it never meets).
IGNORED = 32

#: The most faces a contact node's list holds; a node near more is searched on the grid.
NEAR = 32
#: How much farther than the contact's reach the lists look, a share of the largest
#: reach: the nodes and faces may move this far (together) before they are made again.
SKIN = 0.5

#: How much farther than the contact's reach the gaps are looked for (an output's, not
#: the search's: the clearance up to about a thickness shows where faces come close).
GAP_REACH = 2.0

#: The history column of this kind is the sum of its forces' magnitudes; a contact has
#: nodes on both sides.
FORCE_TOTAL, SIDES = "magnitudes", 2


class Bundle(NamedTuple):
    """The contact nodes (K,) and faces (F,) of every shell contact.

    nodes (K,): each contact node; tool (K,): its table's place among the deck's
    contacts; group (K,): the faces it is tested against (those of the same group);
    offset, penalty, friction (K,): the table's; spring (K,): s / dt_c^2 and
    inverse_mass (K,): 1/m (0 until :func:`calibrate`); ignored (K, :data:`IGNORED`): the elements whose
    faces the node overlaps in the initial shape (-1 after the last), and initial_depth
    (K,) how deep it is into the deepest of them [length] (0: none); held (K,) each
    contact node's face row while the pairs are held (:func:`hold_pairs`; -1: none) and
    holding (1,) whether they are (1) or searched at every evaluation (0). faces (F, 9): each
    face's nodes; face_elements (F,) their elements; face_group (F,);
    face_inverse_mass (F, 9) (0 until :func:`calibrate`). Scratch: touches (K,) each
    contact node's face row (-1: none) and touch_forces (K, 10, 3) the forces on it and
    the face's nodes; of the search, reach (F,), boxes (F, 6), start (2 F + 1 per table,),
    entries (8 F,). The faces' lists (the module's text): near (K, :data:`NEAR`) each
    contact node's face rows and near_count (K,) how many (-1: more than fit, searched on
    the grid), listed_at (K, 3) where the node was when they were made, listed_boxes
    (F, 6) and listed_reach (F,) each face's box and the reach they were made with (the
    contact's and the skin), and listed (1,) whether they are made (1) or are to be (0)."""

    nodes: np.ndarray
    tool: np.ndarray
    group: np.ndarray
    offset: np.ndarray
    penalty: np.ndarray
    friction: np.ndarray
    spring: np.ndarray
    inverse_mass: np.ndarray
    ignored: np.ndarray
    initial_depth: np.ndarray
    held: np.ndarray
    holding: np.ndarray
    faces: np.ndarray
    face_elements: np.ndarray
    face_group: np.ndarray
    face_inverse_mass: np.ndarray
    touches: np.ndarray
    touch_forces: np.ndarray
    reach: np.ndarray
    boxes: np.ndarray
    start: np.ndarray
    entries: np.ndarray
    near: np.ndarray
    near_count: np.ndarray
    listed_at: np.ndarray
    listed_boxes: np.ndarray
    listed_reach: np.ndarray
    listed: np.ndarray


def build(table: ShellContact, scene) -> Bundle:
    """One table's contact: the nodes of its set against the faces of the other, and (a
    pair) the other's nodes against the set's faces; each node's faces it overlaps in
    the initial shape found once. A set of a few separate surfaces (three leaflets)
    in self-contact is taken as every surface's nodes against each surface's faces, so
    that a node may touch a face of each (where three leaflets meet, a node with one
    face flipped between the other two leaflets' and pushed only one of them)."""
    sets = scene.mesh.sets
    mine = sets[table.set]
    if table.against is None:
        surfaces = _surfaces(mine.elements, scene.mesh.conn)
        if not 1 < len(surfaces) <= MOST_SURFACES:
            surfaces = [mine.elements]
        passes = [(np.unique(scene.mesh.conn[nodes_of]), faces_of) for nodes_of in surfaces for faces_of in surfaces]
        own = [i == j for i in range(len(surfaces)) for j in range(len(surfaces))]
    else:
        theirs = sets[table.against]
        passes = [(mine.nodes, theirs.elements), (theirs.nodes, mine.elements)]
        own = [False, False]
    loads = _passes(passes, scene.mesh.conn, place=scene.place, table=table)
    if table.own_surface_limit:
        on_own = np.concatenate([np.full(len(nodes), mine_too) for (nodes, _), mine_too in zip(passes, own)])
        _limit_own_surface(loads, on_own, table.own_surface_limit, scene)
    crowded = _initial_overlaps(scene.initial, loads)
    if crowded >= 0:
        raise MeshError(f"node {loads.nodes[crowded]} overlaps more than {IGNORED} faces in the initial shape: the "
                        "shell is much thicker than its elements there; give a smaller offset or a coarser mesh")
    return loads


def _limit_own_surface(loads: Bundle, on_own: np.ndarray, limit: float, scene) -> None:
    """Where a node meets its own surface (on_own (K,)), its offset scaled so that its
    contact thickness is at most ``limit`` times the shortest spacing of the nodes around
    it (in place). Otherwise a surface finer than it is thick touches itself: a node
    finds the faces of its neighbours' neighbours within its reach as soon as the mesh
    is squeezed along it (a tricuspid valve of 0.26 mm elements under 0.4 mm shells
    closing: 3,400 nodes touching, one flung out at 3,800 mm/s, at 1% of the pressure)."""
    spacing = node_spacing(scene.initial.x, scene.mesh.conn)
    nodes = loads.nodes[on_own]
    loads.offset[on_own] *= np.minimum(1.0, limit * spacing[nodes] / scene.initial.h[nodes])


def node_spacing(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """(n,) each node's shortest distance to a node next to it along an element's grid
    lines (the 3 x 3 nodes of a 9-node quad: 12 segments each), +inf off the elements.
    x (n, 3) positions, conn (ne, 9)."""
    grid = conn[:, GRID]  # (ne, 3, 3) the nodes as they lie
    segments = np.concatenate([np.stack([grid[:, :, :-1], grid[:, :, 1:]], -1).reshape(len(conn), -1, 2),
                               np.stack([grid[:, :-1, :], grid[:, 1:, :]], -1).reshape(len(conn), -1, 2)], axis=1)
    ends = segments.reshape(-1, 2)
    lengths = np.linalg.norm(x[ends[:, 0]] - x[ends[:, 1]], axis=1)
    spacing = np.full(len(x), np.inf)
    np.minimum.at(spacing, ends[:, 0], lengths)
    np.minimum.at(spacing, ends[:, 1], lengths)
    return spacing


def _surfaces(elements: np.ndarray, conn: np.ndarray) -> list[np.ndarray]:
    """The ``elements`` (f,) as the separate surfaces they make (joined through shared
    nodes), each its elements."""
    rows = np.repeat(np.arange(len(elements)), conn.shape[1])
    incidence = sp.csr_matrix((np.ones(len(rows)), (rows, conn[elements].ravel())),
                              shape=(len(elements), conn.max() + 1))
    count, labels = connected_components(incidence @ incidence.T, directed=False)
    return [elements[labels == label] for label in range(count)]


def _passes(passes: list, conn: np.ndarray, place: int, table: ShellContact) -> Bundle:
    """A :class:`Bundle` of one table's passes, each (nodes (k,), elements (f,)) whose faces
    the nodes meet, group ``PASSES`` place + the pass."""
    def joined(parts, dtype=np.int64):
        return np.concatenate(parts).astype(dtype) if parts else np.zeros(0, dtype=dtype)

    nodes = joined([n for n, _ in passes])
    elements = joined([e for _, e in passes])
    k, f = len(nodes), len(elements)
    return Bundle(
        nodes=nodes, tool=np.full(k, place, dtype=np.int64),
        group=joined([np.full(len(n), PASSES * place + i) for i, (n, _) in enumerate(passes)]),
        offset=np.full(k, table.offset), penalty=np.full(k, table.penalty), friction=np.full(k, table.friction),
        spring=np.zeros(k),
        inverse_mass=np.zeros(k), ignored=np.full((k, IGNORED), -1, dtype=np.int64), initial_depth=np.zeros(k),
        held=np.full(k, -1, dtype=np.int64), holding=np.zeros(1, dtype=np.int64),
        faces=conn[elements].astype(np.int64).reshape(-1, 9), face_elements=elements,
        face_group=joined([np.full(len(e), PASSES * place + i) for i, (_, e) in enumerate(passes)]),
        face_inverse_mass=np.zeros((f, 9)), touches=np.full(k, -1, dtype=np.int64),
        touch_forces=np.zeros((k, 10, 3)), reach=np.zeros(f), boxes=np.zeros((f, 6)),
        start=np.zeros(2 * f + 1 if f else 0, dtype=np.int64), entries=np.zeros(8 * f, dtype=np.int64),
        near=np.zeros((k, NEAR), dtype=np.int32), near_count=np.zeros(k, dtype=np.int64),
        listed_at=np.zeros((k, 3)), listed_boxes=np.zeros((f, 6)), listed_reach=np.zeros(f),
        listed=np.zeros(1, dtype=np.int64))


def calibrate(loads: Bundle, masses: np.ndarray, rotary: np.ndarray, h: np.ndarray, dt: float) -> None:
    """Set the springs' scale s / dt^2 and the inverse masses (n,) of the contact nodes
    and the faces' nodes, in place, from the structure's critical step dt."""
    loads.spring[:] = loads.penalty / (dt * dt)
    loads.inverse_mass[:] = 1.0 / masses[loads.nodes]
    loads.face_inverse_mass[:] = 1.0 / masses[loads.faces]


def step_share(loads: Bundle) -> float:
    """The share of the structure's critical step that stays stable with the springs."""
    return share_of(loads.penalty.max())


def share_of(penalty: float) -> float:
    """The share of the critical step that stays stable with both passes' springs of scale
    ``penalty``: 1 / sqrt(1 + s / 2)."""
    return float(1.0 / np.sqrt(1.0 + penalty / 2.0))


@njit(cache=True)
def _at_initial_thickness(model, shape):
    """``shape`` as the contact sees it: its faces at the initial fibre lengths."""
    return Shape(shape.x, shape.d, shape.e1, model.body.h0)


@njit(cache=True)
def _work():
    """The scratch of a contact's geometry: (rs (2,), point (3,), normal (3,)) of the
    nearest point, :func:`shellsim.loads.contact_search.projection_scratch`, and the
    deepest face's (N (9,), normal (3,), (depth, smoothing) (2,)) as :func:`_touched`
    keeps them (:func:`_keep`)."""
    return (np.empty(2), np.empty(3), np.empty(3)), projection_scratch(), (np.empty(9), np.empty(3), np.empty(2))


@njit(cache=True, inline="always")
def _keep(work, depth, smoothing):
    """Keep the last face's shape functions and normal at its nearest point, its depth
    and smoothing in work[2] (:func:`_work`): the pair's forces are those of the deepest
    face, which the search projected onto already (projecting again took a third of the
    projections)."""
    N, normal, pair = work[2]
    copy_into(work[1][0], N)
    copy_into(work[0][2], normal)
    pair[0], pair[1] = depth, smoothing


@njit(cache=True, inline="always")
def _depth(x, h, loads, m, row, work):
    """How deep contact node m is into face row ``row``, the shape (x (n, 3), h (n,))
    given: offset (h_y + h_p) / 2 less their distance (-gap), and the width of the
    penalty's smoothing there (:data:`TOUCHING` of that offset). work = (contact,
    scratch) of :func:`_work`: the nearest point's (rs (2,), point (3,), normal (3,)) and
    its shape functions left in scratch[0]."""
    (rs, point, normal), scratch = work[0], work[1]
    nodes = loads.faces[row]
    node = loads.nodes[m]
    distance = nearest_point(x, nodes, x[node], rs, point, normal, scratch)
    N = scratch[0]
    thickness = 0.0
    for a in range(9):
        thickness += N[a] * h[nodes[a]]
    reach = 0.5 * loads.offset[m] * (h[node] + thickness)
    return reach - distance, TOUCHING * reach


@njit(cache=True)
def _holds(nodes, node):
    """Whether a face's nodes (9,) hold ``node``."""
    for a in range(9):
        if nodes[a] == node:
            return True
    return False


@njit(cache=True)
def _grid(shape, loads, widening):
    """The search grid of the faces on the current shape (:func:`_bounds`, the reach times
    ``widening``). Returns (width, origin) (:func:`fill_grid`)."""
    _bounds(shape, loads, widening)
    return fill_grid(loads.reach, (loads.boxes, loads.start, loads.entries))


@njit(cache=True)
def _bounds(shape, loads, widening):
    """Each face's box on the current shape into loads.boxes, and its reach into
    loads.reach: the largest of the nodes tested against it (those of its pass: half their
    largest fibre length times offset, and the face's own largest times their largest
    offset, and the smoothing), times ``widening``.
    Per pass, not over the table: a surface against itself reaches a few tenths of its
    node spacing (``own_surface_limit``), against another surface the whole thickness,
    and with the whole thickness every face of its own surface near a node had its
    nearest point searched (on a near-closed valve, contact was 88% of the step)."""
    h = shape.h
    passes = 0
    for m in range(loads.nodes.shape[0]):
        passes = max(passes, loads.group[m] + 1)
    for f in range(loads.faces.shape[0]):
        passes = max(passes, loads.face_group[f] + 1)
    deepest, widest = np.zeros(passes), np.zeros(passes)
    for m in range(loads.nodes.shape[0]):
        g = loads.group[m]
        deepest[g] = max(deepest[g], loads.offset[m] * h[loads.nodes[m]])
        widest[g] = max(widest[g], loads.offset[m])
    for f in range(loads.faces.shape[0]):
        thickest = 0.0
        for a in range(9):
            thickest = max(thickest, h[loads.faces[f, a]])
        g = loads.face_group[f]
        loads.reach[f] = 0.5 * (deepest[g] + widest[g] * thickest) * (1.0 + TOUCHING) * widening
    face_boxes(shape.x, loads.faces, loads.boxes)


@njit(cache=True)
def _candidates(shape, loads, m, grid, work, ignoring):
    """The face row contact node m is deepest into on ``shape`` (-1: none); ``grid``
    (width, origin) of :func:`_grid`. Faces that hold the node are passed over, and so
    are the node's ``ignored`` faces where ``ignoring``. With ``ignoring`` false, the
    faces it is into by more than the smoothing width are listed in loads.ignored[m]
    instead (the initial overlaps, the deepest's depth in loads.initial_depth[m]), and
    -2 - count returned when more than fit."""
    width, origin = grid
    node = loads.nodes[m]
    y = shape.x[node]
    first, stop = cell_faces(y, width, origin, loads.start)
    best, deepest, listed = -1, -np.inf, 0
    for entry in range(first, stop):
        row = loads.entries[entry]
        # :func:`_may_touch` written out: called here, even inlined, it doubled the search's time
        if loads.face_group[row] != loads.group[m] or not near_box(y, loads.boxes, row, loads.reach[row]) \
                or _holds(loads.faces[row], node) or (ignoring and _ignored(loads, m, row)):
            continue
        depth, smoothing = _depth(shape.x, shape.h, loads, m, row, work)
        if depth <= -smoothing:
            continue
        if not ignoring:
            if depth > smoothing:  # more than touching
                if listed == IGNORED:
                    return -2 - listed
                loads.ignored[m, listed] = loads.face_elements[row]
                loads.initial_depth[m] = max(loads.initial_depth[m], depth)
                listed += 1
        elif depth > deepest:
            best, deepest = row, depth
            _keep(work, depth, smoothing)
    return best


def hold_pairs(loads: Bundle, holding: bool) -> None:
    """Hold each contact node to the face it touched at the last evaluation (and a node
    touching none to none), or search again at every evaluation (``holding`` false). A
    Newton step's iterations hold them once they have settled: where three leaflets meet,
    a node's deepest face flipped between two from one iterate to the next, and the
    residual with it, for as long as the iterations ran."""
    if holding and not loads.holding[0]:
        loads.held[:] = loads.touches
    loads.holding[0] = int(holding)


def pairs(loads: Bundle) -> np.ndarray:
    """(K,) each contact node's face row at the last evaluation (-1: none), a copy."""
    return loads.touches.copy()


def overlaps_at_rest(loads: Bundle, tables: list, x: np.ndarray) -> list[str]:
    """One line per contact table whose nodes overlap faces in the initial shape (x (n, 3)):
    how many nodes, the deepest overlap and where; those faces are never pushed against."""
    lines = []
    for place in np.unique(loads.tool):
        mine = (loads.tool == place) & (loads.initial_depth > 0.0)
        if not mine.any():
            continue
        deepest = int(np.flatnonzero(mine)[np.argmax(loads.initial_depth[mine])])
        node = int(loads.nodes[deepest])
        lines.append(f"contact '{tables[place].name}': {len(np.unique(loads.nodes[mine])):,} node(s) overlap faces of "
                     f"the other side at rest, by up to {loads.initial_depth[deepest]:.3g} (node {node + 1} at "
                     f"{', '.join(f'{v:.4g}' for v in x[node])}): the faces a node overlaps at rest are never "
                     "pushed against (initial penetrations ignored, as LS-DYNA's IGNORE); where the shells should "
                     "touch there, a smaller offset or the mesh moved apart brings the contact back")
    return lines


@njit(cache=True, inline="always")
def _may_touch(loads, m, row, y, reach, ignoring):
    """Whether contact node m, at y (3,), is tested against face row ``row``: a face of its
    group within ``reach`` (F,) of it (the search's, or the lists') that does not hold it
    (nor, where ``ignoring``, one it overlapped in the initial shape)."""
    return loads.face_group[row] == loads.group[m] and near_box(y, loads.boxes, row, reach[row]) \
        and not _holds(loads.faces[row], loads.nodes[m]) and not (ignoring and _ignored(loads, m, row))


@njit(cache=True)
def _ignored(loads, m, row):
    """Whether contact node m overlapped face row ``row`` in the initial shape."""
    element = loads.face_elements[row]
    for k in range(IGNORED):
        if loads.ignored[m, k] == element:
            return True
        if loads.ignored[m, k] < 0:
            return False
    return False


@njit(cache=True)
def _touched(shape, loads, m, grid, work):
    """The face row contact node m is deepest into on the current shape (-1: none), of
    the faces that neither hold it nor overlapped it in the initial shape: of its list
    (:func:`_search`), or of ``grid``'s cell where the list could not hold them; that
    face's nearest point kept in work[2] (:func:`_keep`)."""
    count = loads.near_count[m]
    if count < 0:
        return _candidates(shape, loads, m, grid, work, True)
    y = shape.x[loads.nodes[m]]
    best, deepest = -1, -np.inf
    for k in range(count):
        row = loads.near[m, k]
        if not near_box(y, loads.boxes, row, loads.reach[row]):
            continue
        depth, smoothing = _depth(shape.x, shape.h, loads, m, row, work)
        if depth > -smoothing and depth > deepest:
            best, deepest = row, depth
            _keep(work, depth, smoothing)
    return best


@njit(cache=True)
def _search(shape, loads):
    """The boxes and reach of the faces on the current shape (:func:`_bounds`), each
    contact node's list of faces made again where the nodes and boxes have moved more
    than the lists' skin (the module's text). Returns the grid (width, origin) that the
    nodes whose lists overflowed read (:func:`_touched`): made with the lists, or on the
    current shape where they hold; none (0, inf) where every list holds its faces, or
    while the pairs are held (:func:`hold_pairs`: nothing is searched)."""
    if loads.holding[0]:
        return 0.0, np.full(3, np.inf)
    _bounds(shape, loads, 1.0)
    if loads.listed[0] and _lists_hold(shape, loads):
        for m in range(loads.nodes.shape[0]):
            if loads.near_count[m] < 0:
                return fill_grid(loads.reach, (loads.boxes, loads.start, loads.entries))
        return 0.0, np.full(3, np.inf)
    skin = 0.0
    for f in range(loads.faces.shape[0]):
        skin = max(skin, SKIN * loads.reach[f])
    for f in range(loads.faces.shape[0]):
        loads.listed_reach[f] = loads.reach[f] + skin
    copy_into(loads.boxes, loads.listed_boxes)
    grid = fill_grid(loads.listed_reach, (loads.boxes, loads.start, loads.entries))
    _list_faces(shape, loads, grid)
    loads.listed[0] = 1
    return grid


@njit(cache=True)
def _lists_hold(shape, loads):
    """Whether every face that may be within a contact node's reach on the current shape
    is in its list: the node's move since they were made plus the largest move of a face
    box's bounds (each axis' larger of its two) is less than the skin, the least of the
    lists' reach over the current one."""
    skin = np.inf
    for f in range(loads.faces.shape[0]):
        skin = min(skin, loads.listed_reach[f] - loads.reach[f])
    boxes_moved = 0.0
    for f in range(loads.faces.shape[0]):
        squared = 0.0
        for i in range(3):
            bound = max(abs(loads.boxes[f, i] - loads.listed_boxes[f, i]),
                        abs(loads.boxes[f, 3 + i] - loads.listed_boxes[f, 3 + i]))
            squared += bound * bound
        boxes_moved = max(boxes_moved, squared)
    nodes_moved = 0.0
    for m in range(loads.nodes.shape[0]):
        y = shape.x[loads.nodes[m]]
        nodes_moved = max(nodes_moved, (y[0] - loads.listed_at[m, 0]) ** 2 + (y[1] - loads.listed_at[m, 1]) ** 2
                          + (y[2] - loads.listed_at[m, 2]) ** 2)
    # the distance of a node from a box moves by at most the two moves together
    return np.sqrt(nodes_moved) + np.sqrt(boxes_moved) < skin


@njit(cache=True, parallel=True)
def _list_faces(shape, loads, grid):
    """Each contact node's list of the faces it may touch (:func:`_list_node`), the
    nodes shared among the threads. (The node's loop, with its break, written out in the
    parallel loop left every list empty: numba 0.68's parallel lowering.)"""
    count = loads.nodes.shape[0]
    chunks = min(count, CHUNKS)
    for c in prange(chunks):
        for m in range(c * count // chunks, (c + 1) * count // chunks):
            _list_node(shape, loads, m, grid)


@njit(cache=True)
def _list_node(shape, loads, m, grid):
    """Contact node m's list of the faces it may touch (those of its group that do not
    hold it and that it did not overlap at rest) within their listed reach of it, of
    ``grid``'s cell (made with that reach), into loads.near[m] and loads.near_count[m]
    (-1 where more than :data:`NEAR`), and where it is into loads.listed_at[m]."""
    width, origin = grid
    node = loads.nodes[m]
    y = shape.x[node]
    first, stop = cell_faces(y, width, origin, loads.start)
    listed = 0
    for entry in range(first, stop):
        row = loads.entries[entry]
        if not _may_touch(loads, m, row, y, loads.listed_reach, True):
            continue
        if listed == NEAR:
            listed = -1
            break
        loads.near[m, listed] = row
        listed += 1
    loads.near_count[m] = listed
    copy_into(y, loads.listed_at[m])


@njit(cache=True)
def _initial_overlaps(initial, loads):
    """Each contact node's faces it overlaps on the ``initial`` shape into loads.ignored.
    Returns the first contact node that overlaps more than :data:`IGNORED`, or -1."""
    if loads.nodes.shape[0] == 0:
        return -1
    grid = _grid(initial, loads, 1.0)
    work = _work()
    for m in range(loads.nodes.shape[0]):
        if _candidates(initial, loads, m, grid, work, False) < -1:
            return m
    return -1


@njit(cache=True, inline="always")
def _pair_spring(x, h, loads, m, row, work):
    """(depth, smoothing, spring) of contact node m against face row ``row``, the shape
    (x, h) given: :func:`_depth`'s and the pair's spring k (the module's text; 0 where they
    are apart or the springs are not set yet)."""
    depth, smoothing = _depth(x, h, loads, m, row, work)
    if depth <= -smoothing:
        return depth, smoothing, 0.0
    return depth, smoothing, _spring(loads, m, row, work[1][0])


@njit(cache=True, inline="always")
def _spring(loads, m, row, N):
    """The spring k of contact node m against face row ``row`` whose shape functions at
    the nearest point are N (9,) (the module's text; 0 while the springs are not set)."""
    if loads.spring[m] == 0.0:
        return 0.0
    weight = loads.inverse_mass[m]
    for a in range(9):
        weight += N[a] * N[a] * loads.face_inverse_mass[row, a]
    return loads.spring[m] / weight


@njit(cache=True)
def _pair_forces(x, h, loads, m, row, out, work):
    """out (10, 3): the force on contact node m and on the nine nodes of face row ``row``,
    the shape (x, h) given: the node pushed out along the normal by k times its depth d
    (the spring of the module's text), the face's nodes back by N_a times that. Within
    the smoothing width w of touching the push is :mod:`shellsim.loads.penalty_law`'s
    (a body resting on another has a stiffness before it penetrates)."""
    depth, smoothing, spring = _pair_spring(x, h, loads, m, row, work)
    _push(spring, depth, smoothing, work[1][0], work[0][2], out)


@njit(cache=True, inline="always")
def _push(spring, depth, smoothing, N, normal, out):
    """out (10, 3): :func:`_pair_forces` of a pair whose spring, depth and smoothing are
    given, N (9,) and normal (3,) at its face's nearest point."""
    out[:] = 0.0
    if spring == 0.0:
        return
    push = penalty_law.push(spring, depth, smoothing)
    for i in range(3):
        out[0, i] = push * normal[i]
        for a in range(9):
            out[1 + a, i] = -N[a] * push * normal[i]


@njit(cache=True, parallel=True)
def _contact_forces(model, shape, loads):
    """Each contact node's face on the current shape into loads.touches (K,) (-1: none)
    and the ten nodes' forces of its contact into loads.touch_forces (K, 10, 3), the
    nodes shared among the threads (each node's contact is its own)."""
    grid = _search(shape, loads)
    count = loads.nodes.shape[0]
    chunks = min(count, CHUNKS)
    for c in prange(chunks):
        _contact_chunk(c * count // chunks, (c + 1) * count // chunks, shape, loads, grid)


@njit(cache=True)
def _contact_chunk(first, stop, shape, loads, grid):
    """:func:`_contact_forces` of contact nodes first..stop-1 (the held pairs' faces while
    they are held)."""
    work = _work()
    N, normal, pair = work[2]
    for m in range(first, stop):
        if loads.holding[0]:
            row = loads.held[m]
            if row >= 0:
                _pair_forces(shape.x, shape.h, loads, m, row, loads.touch_forces[m], work)
        else:
            row = _touched(shape, loads, m, grid, work)
            if row >= 0:
                _push(_spring(loads, m, row, N), pair[0], pair[1], N, normal, loads.touch_forces[m])
        loads.touches[m] = row
        if row < 0:
            loads.touch_forces[m] = 0.0


@njit(cache=True)
def add_forces(t, model, shape, loads, f, g):
    """f (n, 3) += the contact forces on the current ``shape`` (none on the directors, g)."""
    shape = _at_initial_thickness(model, shape)
    if loads.nodes.shape[0] == 0:
        return
    _contact_forces(model, shape, loads)
    for m in range(loads.nodes.shape[0]):
        row = loads.touches[m]
        if row < 0:
            continue
        for i in range(3):
            f[loads.nodes[m], i] += loads.touch_forces[m, 0, i]
            for a in range(9):
                f[loads.faces[row, a], i] += loads.touch_forces[m, 1 + a, i]


@njit(cache=True)
def add_friction(t, model, shape, loads, f, g, v, w):
    """f (n, 3) += the friction of the contacts :func:`add_forces` found on this ``shape``
    (it reads what that left in loads.touches and loads.touch_forces), the nodes moving
    at v (n, 3) (:func:`_pair_friction`). w (n, 2) unread: the forces act at the
    mid-surface."""
    out, scratch = np.empty((10, 3)), (np.empty(3), np.empty(9))
    for m in range(loads.nodes.shape[0]):
        row = loads.touches[m]
        if row < 0 or loads.friction[m] == 0.0:
            continue
        _pair_friction(loads.touch_forces[m], v, loads, m, row, out, scratch)
        for i in range(3):
            f[loads.nodes[m], i] += out[0, i]
            for a in range(9):
                f[loads.faces[row, a], i] += out[1 + a, i]


@njit(cache=True)
def _pair_friction(pushed, v, loads, m, row, out, scratch):
    """out (10, 3): the friction on contact node m and the nine nodes of face ``row``
    pushed by ``pushed`` (10, 3) (:func:`_pair_forces`), the nodes moving at v (n, 3):
    against the node's velocity relative to the face point (N_a v_a), tangent to the
    face, the smaller of mu times the push and the stick damper times that velocity (the
    relative motion's mass over the critical step, 1 / (dt_c (1/m_y + sum_a N_a^2 /
    m_a)): it stops the slip within a critical step, as sticking does), on the node and
    back on the face's nodes by N_a. scratch: (3,) and (9,) arrays."""
    slip, shares = scratch
    out[:] = 0.0
    push = np.sqrt(pushed[0, 0] ** 2 + pushed[0, 1] ** 2 + pushed[0, 2] ** 2)
    if push == 0.0:
        return
    copy_into(v[loads.nodes[m]], slip)
    weight = loads.inverse_mass[m]
    for a in range(9):  # N_a from the face's share of the push
        shares[a] = -(pushed[1 + a, 0] * pushed[0, 0] + pushed[1 + a, 1] * pushed[0, 1]
                      + pushed[1 + a, 2] * pushed[0, 2]) / (push * push)
        weight += shares[a] * shares[a] * loads.face_inverse_mass[row, a]
        for i in range(3):
            slip[i] -= shares[a] * v[loads.faces[row, a], i]
    along = (slip[0] * pushed[0, 0] + slip[1] * pushed[0, 1] + slip[2] * pushed[0, 2]) / push
    for i in range(3):
        slip[i] -= along * pushed[0, i] / push
    speed = np.sqrt(slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2])
    if speed == 0.0:
        return
    critical = np.sqrt(loads.penalty[m] / loads.spring[m])
    drag = min(loads.friction[m] * push, speed / (critical * weight)) / speed
    for i in range(3):
        out[0, i] = -drag * slip[i]
        for a in range(9):
            out[1 + a, i] = shares[a] * drag * slip[i]


@njit(cache=True)
def item_forces(t, model, shape, loads, out):
    """out (K, 3): the force on each contact node (for the history)."""
    shape = _at_initial_thickness(model, shape)
    _contact_forces(model, shape, loads)
    copy_into(loads.touch_forces[:, 0], out)


@njit(cache=True)
def deepest(t, model, shape, loads):
    """(item, share): the contact node deepest into the face it touches on the current
    ``shape``, by the share of the offset between them it has gone through (0: the faces
    touch; 1: the node on the face's mid-surface); (-1, 0.0) where none touches."""
    shape = _at_initial_thickness(model, shape)
    best, share = -1, 0.0
    if loads.nodes.shape[0] == 0:
        return best, share
    _contact_forces(model, shape, loads)
    work = _work()
    for m in range(loads.nodes.shape[0]):
        if loads.touches[m] >= 0:
            depth, smoothing = _depth(shape.x, shape.h, loads, m, loads.touches[m], work)
            if depth * TOUCHING / smoothing > share:
                best, share = m, depth * TOUCHING / smoothing
    return best, share


@njit(cache=True)
def item_energies(t, model, shape, loads, out):
    """out (K,): the energy stored in each contact node's spring on the current shape, its
    push integrated over the depth (:func:`shellsim.loads.penalty_law.stored`), of the
    pairs :func:`item_forces` found on this shape (it reads loads.touches: a search
    again doubled the cost of a history sample)."""
    shape = _at_initial_thickness(model, shape)
    if loads.nodes.shape[0] == 0:
        return
    work = _work()
    for m in range(loads.nodes.shape[0]):
        out[m] = 0.0
        if loads.touches[m] < 0:
            continue
        depth, w, spring = _pair_spring(shape.x, shape.h, loads, m, loads.touches[m], work)
        out[m] = penalty_law.stored(spring, depth, w)


@njit(cache=True)
def _nearest_face(shape, loads, m, grid, work):
    """(row, gap): the face nearest contact node m of those it may touch within the reach
    of ``grid`` (:func:`_grid`), and the node's gap to it (-1, +inf for none)."""
    width, origin = grid
    y = shape.x[loads.nodes[m]]
    first, stop = cell_faces(y, width, origin, loads.start)
    nearest, gap = -1, np.inf
    for entry in range(first, stop):
        row = loads.entries[entry]
        if _may_touch(loads, m, row, y, loads.reach, True):
            depth = _depth(shape.x, shape.h, loads, m, row, work)[0]
            if -depth < gap:
                nearest, gap = row, -depth
    return nearest, gap


@njit(cache=True)
def item_gaps(t, model, shape, loads, out):
    """out (K,): each contact node's gap on the current ``shape``, its distance from the
    nearest face it may touch less the offset (:func:`_depth`'s depth, negated), +inf
    where none is within :data:`GAP_REACH` times the contact's reach (a clearance of
    about a thickness)."""
    shape = _at_initial_thickness(model, shape)
    if loads.nodes.shape[0] == 0:
        return
    grid = _grid(shape, loads, GAP_REACH)
    work = _work()
    for m in range(loads.nodes.shape[0]):
        out[m] = _nearest_face(shape, loads, m, grid, work)[1]


@njit(cache=True)
def farthest_moved(t, model, shape, loads, before):
    """(item, share): of the contact nodes that end near a face (within the reach of
    :func:`item_gaps`), the one that moved farthest relative to the nearest face's
    nearest point, from their places in ``before`` (n, 3) to the current ``shape``, by
    the share of its distance from that face's mid-surface (the offset when touching) it
    moved; (-1, 0.0) for none. A node passing through the face would have moved more
    than that distance: parts that move together (a strip's neighbouring elements
    rolling up) count nothing."""
    shape = _at_initial_thickness(model, shape)
    best, share = -1, 0.0
    if loads.nodes.shape[0] == 0:
        return best, share
    grid = _grid(shape, loads, GAP_REACH)
    work = _work()
    moved = np.empty(3)
    for m in range(loads.nodes.shape[0]):
        row, gap = _nearest_face(shape, loads, m, grid, work)
        if row < 0:
            continue
        smoothing = _depth(shape.x, shape.h, loads, m, row, work)[1]  # again: the search left another face's
        N = work[1][0]  # the shape functions at the face's nearest point
        node = loads.nodes[m]
        for i in range(3):
            moved[i] = shape.x[node, i] - before[node, i]
            for a in range(9):
                moved[i] -= N[a] * (shape.x[loads.faces[row, a], i] - before[loads.faces[row, a], i])
        distance = gap + smoothing / TOUCHING  # from the face's mid-surface
        relative = np.sqrt(moved[0] ** 2 + moved[1] ** 2 + moved[2] ** 2) / distance
        if relative > share:
            best, share = m, relative
    return best, share


@njit(cache=True)
def couplings(t, model, shape, loads, step_u, nodes, blocks):
    """The derivative of each touching pair's forces with respect to its ten nodes'
    translations (central differences of step ``step_u``; the pair and the fibre lengths
    held): nodes (K, 10) the node numbers and blocks (K, 30, 30) dF/dx, filled from the
    top. Returns how many pairs touch (or are held)."""
    return _differenced_pairs(model, shape, loads, (np.empty((0, 3)), 0.0), step_u, nodes, blocks, False)


@njit(cache=True)
def friction_couplings(t, model, shape, loads, motion, step_u, nodes, blocks):
    """The derivative of each touching pair's friction as :func:`couplings`'s, ``motion``
    (v, rate): the nodes moving at v (n, 3) whose derivative by the translations is
    ``rate`` (an implicit step's gamma / (beta dt)), so that a node moved by the step
    moves by ``rate`` times it. Returns how many pairs with friction touch (or are held)."""
    return _differenced_pairs(model, shape, loads, motion, step_u, nodes, blocks, True)


@njit(cache=True)
def _differenced_pairs(model, shape, loads, motion, step_u, nodes, blocks, friction):
    """:func:`couplings` of the pairs' forces, or (``friction``) of their friction at the
    velocities of ``motion`` (v (n, 3), rate) of the pairs with friction."""
    shape = _at_initial_thickness(model, shape)
    grid = _search(shape, loads)
    work = _work()
    pushed, plus, minus = np.empty((10, 3)), np.empty((10, 3)), np.empty((10, 3))
    scratch = (np.empty(3), np.empty(9))
    x, (v, rate) = shape.x, motion
    count = 0
    for m in range(loads.nodes.shape[0]):
        if friction and loads.friction[m] == 0.0:
            continue
        row = loads.held[m] if loads.holding[0] else _touched(shape, loads, m, grid, work)
        if row < 0:
            continue
        nodes[count, 0] = loads.nodes[m]
        copy_into(loads.faces[row], nodes[count, 1:])
        for j in range(30):
            node, i = nodes[count, j // 3], j % 3
            kept = x[node, i]
            kept_v = v[node, i] if friction else 0.0
            for side in range(2):
                sign, out = (1.0, plus) if side == 0 else (-1.0, minus)
                x[node, i] = kept + sign * step_u
                if friction:
                    v[node, i] = kept_v + sign * rate * step_u
                    _pair_forces(x, shape.h, loads, m, row, pushed, work)
                    _pair_friction(pushed, v, loads, m, row, out, scratch)
                    v[node, i] = kept_v
                else:
                    _pair_forces(x, shape.h, loads, m, row, out, work)
            x[node, i] = kept
            for a in range(10):
                for k in range(3):
                    blocks[count, 3 * a + k, j] = (plus[a, k] - minus[a, k]) / (2.0 * step_u)
        count += 1
    return count
