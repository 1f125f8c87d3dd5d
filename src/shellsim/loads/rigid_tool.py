"""Contact of the shell's faces with a rigid tool: an analytic plane, sphere or cylinder
(the rigid walls of LS-DYNA), or a triangulated surface read from a file (a stent, a
catheter, a balloon: :mod:`shellsim.loads.tool_surface`), that a curve may move, by
penalty.

Each node of the contact set is tested on the faces it offers, the points
y = x + t h/2 d (t = -1 bottom, +1 top, 0 the mid-surface), against the tool's signed
distance phi(y) (positive on the side the shell belongs to). Where phi < 0 the face point
is pushed out along the tool's normal n with the force -k phi n (smoothed within
TOUCHING h/2 of touching, :mod:`shellsim.loads.penalty_law`: without it a static solve
cycled around the kink where a ring lay flat along a plate), which acts where the face
is: on the node's translations and, through its lever arm t h/2, on its director (as a
face pressure does). With ``friction`` mu, the face point's velocity relative to
the tool, tangent to it, is opposed by mu times the push (:func:`add_friction`).

The penalty is the soft constraint of explicit codes: each node's spring is
k = s / (dt_c^2 (1/m + (h/2)^2 / m_r)), dt_c the structure's critical step, m and m_r the
node's translational and rotary masses (the face point moves by both), s =
``penalty``. Adding such springs raises the highest frequency squared by at most
s / dt_c^2 = (s / 4) omega_max^2, so the critical step is taken as dt_c / sqrt(1 + s / 4)
(0.988 dt_c for the default s = 0.1): contact never lowers it by more. The springs are
set once, when the run starts (:func:`calibrate`), so the contact force is conservative:
its work, counted with the external work, is the spring energy (and friction's work is
counted there too).
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar, Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import model_validator

from ..array_copy import copy_into
from ..curve_tables import factor, rate
from ..element.frames import cross
from ..element.tangent import moved_node
from ..table_types import Name, Positive, Vec3, need_directions
from . import penalty_law
from .penalty_law import TOUCHING
from .table import ContactTable
from .tool_surface import read_tool, search_grid, signed_distance

#: Codes of the tools' shapes.
SHAPES = {"plane": 0, "sphere": 1, "cylinder": 2, "surface": 3}
#: (first, last) face of each ``faces`` choice, stepped by 2.
FACE_RANGES = {"both": (-1, 1), "bottom": (-1, -1), "top": (1, 1), "mid": (0, 0)}


class RigidTool(ContactTable):
    """A rigid tool the faces of a surface set may not pass: ``shape = "plane"`` through
    ``point`` with unit ``normal`` pointing to the shell's side; ``"sphere"`` of
    ``radius`` centred at ``point``; ``"cylinder"`` of ``radius`` about the line through
    ``point`` along ``axis``; ``"surface"``: the triangulated surface in ``file`` (STL,
    OBJ, PLY, VTP, OFF; a path relative to the deck, its coordinates shifted by
    ``point``). The shell is kept ``outside`` the sphere, cylinder or surface (a punch,
    a stent's outside; a surface's outside is the side its triangles' normals face) or
    ``inside`` it (a vessel in a tube). The tool moves by ``motion * curve(t)``.
    ``faces``: the shell's faces that touch it (``both``, ``bottom``, ``top`` or the
    ``mid`` surface). ``penalty``: the soft constraint's scale s (the critical step
    falls by the factor 1 / sqrt(1 + s / 4)). ``friction``: Coulomb's mu between the
    shell and the tool. ``name``: the history column of the force the tool takes (its
    magnitude)."""

    type: Literal["rigid_tool"]
    shape: Literal["plane", "sphere", "cylinder", "surface"]
    file: str | None = None
    point: Vec3 = (0.0, 0.0, 0.0)
    normal: Vec3 | None = None
    axis: Vec3 | None = None
    radius: Positive | None = None
    side: Literal["outside", "inside"] = "outside"
    motion: Vec3 = (0.0, 0.0, 0.0)
    curve: Name | None = None
    faces: Literal["both", "bottom", "top", "mid"] = "both"
    FILE_KEYS: ClassVar[tuple[str, ...]] = ("file",)

    @model_validator(mode="after")
    def _shape_keys(self) -> "RigidTool":
        needs = {"plane": ("normal",), "sphere": ("radius",), "cylinder": ("axis", "radius"),
                 "surface": ("file",)}[self.shape]
        missing = [key for key in needs if getattr(self, key) is None]
        extra = [key for key in ("normal", "axis", "radius", "file") if key not in needs and getattr(self, key) is not None]
        if missing or extra:
            raise ValueError(f"shape = '{self.shape}' takes {', '.join(needs)}"
                             + (f"; missing {', '.join(missing)}" if missing else "")
                             + (f"; {', '.join(extra)} is not for it" if extra else ""))
        need_directions(self, "normal", "axis")
        if self.shape == "plane" and self.side != "outside":
            raise ValueError("a plane keeps the shell on its normal's side; give the normal that way round")
        return self

    @property
    def moving_curve(self) -> str | None:
        """The curve of the tool's motion where it moves on one."""
        return self.curve if any(self.motion) else None

    @property
    def summary(self) -> str:
        """One line for ``shellsim check``: the tool, its motion, the faces and the cost."""
        where = {"plane": f"through {list(self.point)} facing {list(self.normal or ())}",
                 "sphere": f"of radius {self.radius} at {list(self.point)}, the shell {self.side}",
                 "cylinder": f"of radius {self.radius} about {list(self.axis or ())} through {list(self.point)}, "
                             f"the shell {self.side}",
                 "surface": f"'{self.file}' shifted by {list(self.point)}, the shell {self.side}"}[self.shape]
        moving = f", moving by {list(self.motion)}" + (f" x curve '{self.curve}'" if self.curve else "") \
            if any(self.motion) else ""
        return (f"'{self.name}': rigid {self.shape} {where}{moving}; {self.faces} faces of '{self.set}'; "
                f"penalty {self.penalty:g}, the critical step x {share_of(self.penalty):.3f}{self.friction_summary}")


TABLES = (RigidTool,)

#: The history column of this kind is the magnitude of the force's resultant on the tool;
#: its contacts are on one side of the shell.
FORCE_TOTAL, SIDES = "resultant", 1


class Bundle(NamedTuple):
    """The contact nodes (K,) of every rigid tool: nodes; tool (K,) the tool's place among
    the deck's contacts; shape (K,) code of SHAPES; point, direction (K, 3) the tool's
    point and its plane normal or cylinder axis (unit); radius, side (K,) (+1 outside, -1
    inside); motion (K, 3) and curve (K,) its motion; faces (K, 2) the first and last face
    tested; penalty (K,) the scale s; friction (K,) Coulomb's mu; stiffness (K,) the
    springs k [force/length] and stick (K,) the damper [force/velocity] that stops a slip
    within the critical step, k dt_c / s (0 until :func:`calibrate`).

    The surface tools' triangles (T,), in their files' frames: corners (T, 3, 3),
    pseudo (T, 7, 3) their pseudo-normals, owner (T,) their tool's place; their search
    grid, one over every surface tool, made by :func:`calibrate`: boxes (T, 6), start
    (2 T + 1 per tool,), entries (8 T,), and grid (K, 5) its cell width, origin corner
    (3,) and reach (the largest fibre length of the tools' nodes), alike for every item."""

    nodes: np.ndarray
    tool: np.ndarray
    shape: np.ndarray
    point: np.ndarray
    direction: np.ndarray
    radius: np.ndarray
    side: np.ndarray
    motion: np.ndarray
    curve: np.ndarray
    faces: np.ndarray
    penalty: np.ndarray
    friction: np.ndarray
    stiffness: np.ndarray
    stick: np.ndarray
    corners: np.ndarray
    pseudo: np.ndarray
    owner: np.ndarray
    boxes: np.ndarray
    start: np.ndarray
    entries: np.ndarray
    grid: np.ndarray


#: The bundle's fields that hold integers.
_INTEGERS = ("tool", "shape", "curve", "faces")


def build(table: RigidTool, scene) -> Bundle:
    """The contact nodes of one tool: the nodes of its set (and a surface's triangles)."""
    direction = np.asarray(table.normal if table.shape == "plane" else table.axis or (0.0, 0.0, 1.0), dtype=float)
    surface = read_tool(Path(table.file)) if table.shape == "surface" else None
    return _repeated(scene.mesh.sets[table.set].nodes.astype(np.int64), surface, tool=scene.place,
                     shape=SHAPES[table.shape], point=table.point, direction=direction / np.linalg.norm(direction),
                     radius=table.radius or 0.0, side=1.0 if table.side == "outside" else -1.0, motion=table.motion,
                     curve=scene.curve_index(table.curve), faces=FACE_RANGES[table.faces], penalty=table.penalty,
                     friction=table.friction)


def _repeated(nodes: np.ndarray, surface: tuple[np.ndarray, np.ndarray] | None = None, **tool) -> Bundle:
    """A :class:`Bundle` of one tool's ``nodes`` (K,), its values (every field but the nodes,
    the springs and the surface) repeated for each; ``surface``: (corners, pseudo) of
    its triangles (:func:`shellsim.loads.tool_surface.read_tool`), None for none."""
    def each(name, value):
        value = np.asarray(value, dtype=np.int64 if name in _INTEGERS else float)
        return np.broadcast_to(value, (len(nodes),) + value.shape).copy()

    k = len(nodes)
    corners, pseudo = surface if surface is not None else (np.zeros((0, 3, 3)), np.zeros((0, 7, 3)))
    t = len(corners)
    triangles = {"corners": corners, "pseudo": pseudo, "owner": np.full(t, tool["tool"], dtype=np.int64),
                 "boxes": np.zeros((t, 6)), "start": np.zeros(2 * t + 1 if t else 0, dtype=np.int64),
                 "entries": np.zeros(8 * t, dtype=np.int64), "grid": np.zeros((k, 5))}
    springs = {"stiffness": np.zeros(k), "stick": np.zeros(k)}
    return Bundle(nodes=nodes, **springs, **triangles, **{name: each(name, value) for name, value in tool.items()})


def calibrate(loads: Bundle, masses: np.ndarray, rotary: np.ndarray, h: np.ndarray, dt: float) -> None:
    """Set the springs, in place: k = s / (dt^2 (1/m + (h/2)^2 / m_r)) at each contact
    node, from the translational and rotary masses (n,), the fibre lengths h (n,) and the
    structure's critical step dt (the lever arm only where a face off the mid-surface
    touches); and the friction's dampers k dt / s."""
    n = loads.nodes
    arm = np.where(loads.faces[:, 0] != 0, 0.5 * h[n], 0.0) ** 2
    turning = np.divide(arm, rotary[n], out=np.zeros_like(arm), where=rotary[n] > 0.0)  # none where no rotary mass
    loads.stiffness[:] = loads.penalty / (dt * dt * (1.0 / masses[n] + turning))
    loads.stick[:] = loads.stiffness * dt / loads.penalty
    if len(loads.corners):  # the surfaces' grid, once: the tools only translate
        reach = h[n[loads.shape == SHAPES["surface"]]].max()
        loads.boxes[:], loads.start[:], loads.entries[:], frame = search_grid(loads.corners, reach)
        loads.grid[:] = np.append(frame, reach)


def step_share(loads: Bundle) -> float:
    """The share of the structure's critical step that stays stable with the springs."""
    return share_of(loads.penalty.max())


def share_of(penalty: float) -> float:
    """The share of the critical step that stays stable with springs of scale ``penalty``:
    1 / sqrt(1 + s / 4)."""
    return float(1.0 / np.sqrt(1.0 + penalty / 4.0))


@njit(cache=True, inline="always")
def _distance(loads, m, centre, y, normal):
    """The signed distance of the point y (3,) from tool item m whose point is now
    ``centre`` (3,), positive on the shell's side; writes the unit normal (3,) there."""
    shape = loads.shape[m]
    if shape == 3:
        tool = (loads.corners, loads.pseudo, loads.owner, loads.boxes, loads.start, loads.entries, loads.grid[m, :4],
                loads.grid[m, 4])
        gap = signed_distance(tool, loads.tool[m], (y[0] - centre[0], y[1] - centre[1], y[2] - centre[2]), normal)
        if gap == np.inf:  # far from the surface
            return gap
        for i in range(3):
            normal[i] *= loads.side[m]
        return loads.side[m] * gap
    if shape == 0:
        copy_into(loads.direction[m], normal)
        return (y[0] - centre[0]) * normal[0] + (y[1] - centre[1]) * normal[1] + (y[2] - centre[2]) * normal[2]
    for i in range(3):
        normal[i] = y[i] - centre[i]
    if shape == 2:  # off the axis only
        along = normal[0] * loads.direction[m, 0] + normal[1] * loads.direction[m, 1] + normal[2] * loads.direction[m, 2]
        for i in range(3):
            normal[i] -= along * loads.direction[m, i]
    size = np.sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2])
    for i in range(3):
        normal[i] *= loads.side[m] / size
    return loads.side[m] * (size - loads.radius[m])


@njit(cache=True, inline="always")
def _face_gap(loads, m, centre, node, face, y, normal):
    """(arm, gap) of the point y = x + arm d (3,) of ``face`` (-1, 0, +1; arm = face h/2)
    of item m's node = (x, d (3,), fibre length h): its signed distance from the tool at
    ``centre`` (3,), the unit normal there into ``normal`` (3,)."""
    x, d, h = node
    arm = 0.5 * face * h
    for i in range(3):
        y[i] = x[i] + arm * d[i]
    return arm, _distance(loads, m, centre, y, normal)


@njit(cache=True)
def _node_forces(loads, m, centre, x, d, h, out, scratch):
    """out = (f, g) (3,): the contact force on item m's node at x, d (3,), h, and its
    director-conjugate part, from the faces the item tests; scratch = (y, normal) (3,)."""
    f, g = out
    y, normal = scratch
    f[:] = 0.0
    g[:] = 0.0
    face = loads.faces[m, 0]
    while face <= loads.faces[m, 1]:
        arm, gap = _face_gap(loads, m, centre, (x, d, h), face, y, normal)
        push = penalty_law.push(loads.stiffness[m], -gap, TOUCHING * 0.5 * h)
        if push > 0.0:
            for i in range(3):
                f[i] += push * normal[i]
                g[i] += arm * push * normal[i]
        face += 2


@njit(cache=True)
def _centre(loads, curves, m, t, centre):
    """Item m's tool point at time t into centre (3,)."""
    c = factor(curves, loads.curve[m], t)
    for i in range(3):
        centre[i] = loads.point[m, i] + c * loads.motion[m, i]


@njit(cache=True)
def add_forces(t, model, shape, loads, f, g):
    """f, g (n, 3) += the tools' contact forces at time t on the current ``shape``."""
    if loads.nodes.shape[0] == 0:
        return  # no tool: nothing allocated in the time loop
    centre, fn, gn, y, normal = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for m in range(loads.nodes.shape[0]):
        node = loads.nodes[m]
        _centre(loads, model.curves, m, t, centre)
        _node_forces(loads, m, centre, shape.x[node], shape.d[node], shape.h[node], (fn, gn), (y, normal))
        for i in range(3):
            f[node, i] += fn[i]
            g[node, i] += gn[i]


@njit(cache=True)
def add_friction(t, model, shape, loads, f, g, v, w):
    """f, g (n, 3) += the tools' friction at time t on the current ``shape`` moving at
    the velocities v (n, 3), w (n, 2): at each face point in contact, against its
    velocity relative to the tool tangent to it (the node's, its director's rate times
    the lever arm, less the tool's), the smaller of mu times the push and the stick
    damper times that velocity (which stops the slip within a critical step, as sticking
    does)."""
    if loads.nodes.shape[0] == 0:
        return
    centre, y, normal, slip = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for m in range(loads.nodes.shape[0]):
        if loads.friction[m] == 0.0:
            continue
        node = loads.nodes[m]
        x, d, e1 = shape.x[node], shape.d[node], shape.e1[node]
        _centre(loads, model.curves, m, t, centre)
        moving = rate(model.curves, loads.curve[m], t)
        e2 = cross(d, e1)
        face = loads.faces[m, 0]
        while face <= loads.faces[m, 1]:
            arm, gap = _face_gap(loads, m, centre, (x, d, shape.h[node]), face, y, normal)
            face += 2
            push = penalty_law.push(loads.stiffness[m], -gap, TOUCHING * 0.5 * shape.h[node])
            if push == 0.0:
                continue
            for i in range(3):  # the director's rate is -w1 e1 - w2 e2
                slip[i] = v[node, i] - arm * (w[node, 0] * e1[i] + w[node, 1] * e2[i]) - moving * loads.motion[m, i]
            along = slip[0] * normal[0] + slip[1] * normal[1] + slip[2] * normal[2]
            for i in range(3):
                slip[i] -= along * normal[i]
            speed = np.sqrt(slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2])
            if speed == 0.0:
                continue
            drag = min(loads.friction[m] * push, loads.stick[m] * speed) / speed
            for i in range(3):
                f[node, i] -= drag * slip[i]
                g[node, i] -= arm * drag * slip[i]


@njit(cache=True)
def item_forces(t, model, shape, loads, out):
    """out (K, 3): each contact node's force at time t (for the tools' measures)."""
    centre, gn, y, normal = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for m in range(loads.nodes.shape[0]):
        node = loads.nodes[m]
        _centre(loads, model.curves, m, t, centre)
        _node_forces(loads, m, centre, shape.x[node], shape.d[node], shape.h[node], (out[m], gn), (y, normal))


@njit(cache=True)
def _clearance(t, model, shape, loads, m, scratch):
    """(gap, energy) of item m at time t: the least signed distance of the faces its node
    offers from the tool (+inf: a surface tool farther than its reach), and the energy
    its springs store over the faces (:func:`shellsim.loads.penalty_law.stored`). scratch: (centre, y,
    normal) (3,)."""
    centre, y, normal = scratch
    node = loads.nodes[m]
    _centre(loads, model.curves, m, t, centre)
    least, energy = np.inf, 0.0
    face = loads.faces[m, 0]
    while face <= loads.faces[m, 1]:
        gap = _face_gap(loads, m, centre, (shape.x[node], shape.d[node], shape.h[node]), face, y, normal)[1]
        least = min(least, gap)
        energy += penalty_law.stored(loads.stiffness[m], -gap, TOUCHING * 0.5 * shape.h[node])
        face += 2
    return least, energy


@njit(cache=True)
def item_gaps(t, model, shape, loads, out):
    """out (K,): each contact node's gap from its tool at time t (:func:`_clearance`)."""
    scratch = (np.empty(3), np.empty(3), np.empty(3))
    for m in range(loads.nodes.shape[0]):
        out[m] = _clearance(t, model, shape, loads, m, scratch)[0]


@njit(cache=True)
def item_energies(t, model, shape, loads, out):
    """out (K,): the energy stored in each contact node's springs at time t
    (:func:`_clearance`)."""
    scratch = (np.empty(3), np.empty(3), np.empty(3))
    for m in range(loads.nodes.shape[0]):
        out[m] = _clearance(t, model, shape, loads, m, scratch)[1]


@njit(cache=True)
def add_tangent(t, model, shape, loads, step_u, step_r, k):
    """k (ne, 45, 45) -= the derivative of each contact node's force and rotational force
    with respect to its five DOFs (central differences, order and steps as
    :mod:`shellsim.element.tangent`), into its diagonal block in the first element
    holding it; a node out of contact adds nothing."""
    body = model.body
    centre, fn, gn, y, normal = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    xm, dm, e1m = np.empty(3), np.empty(3), np.empty(3)
    block = np.empty((5, 5))
    for m in range(loads.nodes.shape[0]):
        node = loads.nodes[m]
        _centre(loads, model.curves, m, t, centre)
        block[:] = 0.0
        for move in range(10):
            step = moved_node(shape.x[node], shape.d[node], shape.e1[node], move, (step_u, step_r), (xm, dm, e1m))
            _node_forces(loads, m, centre, xm, dm, shape.h[node], (fn, gn), (y, normal))
            weight = 1.0 / (2.0 * step)
            e2 = cross(dm, e1m)
            column = move // 2
            for i in range(3):
                block[i, column] += weight * fn[i]
                block[3, column] -= weight * e1m[i] * gn[i]
                block[4, column] -= weight * e2[i] * gn[i]
        e, a = divmod(body.slots[body.node_slots[node]], 9)
        for i in range(5):
            for j in range(5):
                k[e, 5 * a + i, 5 * a + j] -= block[i, j]
