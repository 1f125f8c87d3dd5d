"""External loads as registered kinds, one module each, and what the solvers call:
:func:`build_loads` (the deck's loads as the kernels' tables), the compiled
:func:`external_forces` and :func:`friction_forces`, and :class:`LoadTangents`.

A kind is a module of this package with
- ``TABLES``: its deck tables (:class:`~shellsim.loads.table.LoadTable`, ``type`` their
  tag), ``[[load]]`` or ``[[contact]]`` ones (their ``DECK_KEY``; the deck's unions are
  every kind's tables);
- ``build(table, scene)``: one table's loads on the mesh (``scene`` a :class:`LoadScene`),
  as the ``Bundle`` of this kind or of another one (a dead pressure is tabulated as
  nodal forces, a mapped pressure is a follower pressure with values of its own);
and, when it has kernels of its own,
- ``Bundle``: a NamedTuple of arrays, every field with the loads along its first axis
  (the registry concatenates one per table), and where its kernels need what only all
  of its tables together tell (the pressure's map from the nodes to their faces)
  ``joined(bundle, scene)``, the concatenated bundle completed;
- ``empty(scene)``, a bundle of none, where the kind is compiled into every scene (the
  everyday loads, nodal and pressure: were each left out where unused, every mix of them
  would type a model of its own and compile its time loop again); a kind without it is
  None in a scene that does not use it, and its code is not compiled (:data:`Loads`);
- compiled ``add_forces(t, model, shape, bundle, f, g)``: its translational and
  director-conjugate forces f, g (n, 3) at time t added;
- compiled ``add_tangent(t, model, shape, bundle, step_u, step_r, k)`` where its forces
  depend on the shape: less their derivative, into the elements' blocks k (ne, 45, 45);
- where it is a penalty (contact): ``calibrate(bundle, masses, rotary, h, dt)``, its
  springs from the masses and the structure's critical step when the run starts,
  ``step_share(bundle)``, the share of that step it leaves stable, compiled
  ``item_forces(t, model, shape, bundle, out)`` with a ``tool`` field, the force on each
  of its contact nodes, ``FORCE_TOTAL``, how a table's history column totals them
  (``resultant``: the magnitude of their sum, the force on a tool; ``magnitudes``: the
  sum of their magnitudes, what two sides of the shell press on each other with), and
  ``SIDES``, how many of the shell's sides a contact's nodes are on (1: a tool's; 2:
  both sides of a contact between shells, whose nodes' areas count each contact twice);
  compiled ``item_gaps(t, model, shape, bundle, out)``, each contact node's gap (the
  clearance between its face and what it may touch; +inf beyond the search's reach),
  and ``item_energies(t, model, shape, bundle, out)``, the energy in its springs (after
  ``item_forces`` on the same shape: it may read what that left in the bundle);
- where it has friction: compiled ``add_friction(t, model, shape, bundle, f, g, v, w)``,
  its sliding forces at the velocities v (n, 3), w (n, 2), added after its
  ``add_forces`` on the same shape (it may read what that left in the bundle);
- where its surfaces can pass through each other (contact between shells): compiled
  ``deepest(t, model, shape, bundle)``, (item, share) the contact node that has gone
  deepest through the offset between the surfaces and by what share of it, and
  ``farthest_moved(t, model, shape, bundle, before)``, of those near a face the one that
  moved farthest relative to it since the positions ``before`` (n, 3), by what share of
  its distance from the face;
- where it pairs each contact node with a face found by a search: ``hold_pairs(bundle,
  holding)``, the pairs of the last evaluation held (or searched again), and
  ``pairs(bundle)``, each contact node's face at the last evaluation (a copy; -1: none),
  for the Newton iterations of a static or implicit step;
- where its forces couple nodes that share no element (contact between shells, cables):
  compiled ``couplings(t, model, shape, bundle, step_u, nodes, blocks)``, the derivative
  of its forces by groups of ten nodes' translations (nodes (K, 10), blocks (K, 30, 30),
  returning how many), for the static tangent;
- where it is made of elements of its own (cables, ``[[cable]]`` tables):
  ``extend_mesh(table, mesh)``, the mesh with its nodes and sets added (before the model
  is built), ``add_masses(bundle, mt, mr)``, its masses added to the shell's (n,), and
  compiled ``critical_step(shape, bundle)``, the step its elements allow on their own.
Adding a kind is writing its module and adding it to :data:`KINDS`; which of these
hooks its role (a load, a contact, a cable) must and may have is :mod:`.contract`'s, checked
as the registry imports it.
"""

from __future__ import annotations

import time
from typing import Callable, NamedTuple, Union

import numpy as np
from numba import njit, types
from numba.extending import overload

from ..bundles import Body, Curves, Rule, Shape
from ..compiled_call import TypedCall
from ..element.frames import to_rotational
from ..errors import MeshError
from ..mesh import node_areas
from . import cable, edge_pressure, mapped_pressure, nodal, pressure, rigid_tool, shell_contact
from .contract import check_kind

#: The kinds, in the order their forces are added.
KINDS = (nodal, pressure, edge_pressure, mapped_pressure, rigid_tool, shell_contact, cable)
#: Each kind's role, its hooks checked against the role's contract (:mod:`.contract`).
ROLE = {kind: check_kind(kind) for kind in KINDS}

#: The kinds with kernels of their own: the fields of :data:`Loads`.
CARRIERS = tuple(kind for kind in KINDS if hasattr(kind, "Bundle"))

#: Every ``[[load]]``, ``[[contact]]`` and ``[[cable]]`` deck table, and the kind that builds each.
TABLES, CONTACT_TABLES, CABLE_TABLES = (tuple(table for kind in KINDS if ROLE[kind] == role for table in kind.TABLES)
                                        for role in ("load", "contact", "cable"))
#: The deck's lists of load tables, by their keys.
DECK_KEYS = ("load", "contact", "cable")
_KIND_OF = {table: kind for kind in KINDS for table in kind.TABLES}

#: Every load of a scene (:class:`shellsim.bundles.Model`'s ``loads``): one field per
#: carrying kind, named after its module, its bundle; None where the scene has none of it
#: and the kind has no ``empty``. None types apart from a bundle, so the compiled code of
#: such a kind is left out of a scene that does not use it (:func:`_chained`): the
#: contacts' and the cables' kernels are a third of what a scene compiles.
Loads = NamedTuple("Loads", [(kind.__name__.rsplit(".", 1)[1], Union[kind.Bundle, None]) for kind in CARRIERS])


def _with(model, hook: str):
    """(kind, bundle) of every kind of ``model`` that has ``hook`` and loads of its own."""
    return [(kind, bundle) for kind, bundle in zip(CARRIERS, model.loads)
            if hasattr(kind, hook) and bundle is not None and any(len(field) for field in bundle)]


class LoadScene(NamedTuple):
    """What a kind's ``build`` reads: the mesh (:class:`shellsim.mesh.Mesh`), the element's
    rule and body, the initial shape, the curve tables and ``curve_index(name)``, a curve's
    place in them (a load without a curve: the static ramp's or -1); place: the table's
    place in its deck list."""

    mesh: object
    rule: Rule
    body: Body
    initial: Shape
    curves: Curves
    curve_index: Callable[[Union[str, None]], int]
    place: int = 0


def extend_mesh(tables: list, mesh):
    """``mesh`` (:class:`shellsim.mesh.Mesh`) with the nodes, elements and sets of the
    ``tables`` whose kinds have elements of their own (cables), in order."""
    for table in tables:
        kind = _KIND_OF[type(table)]
        if hasattr(kind, "extend_mesh"):
            mesh = kind.extend_mesh(table, mesh)
    return mesh


def build_loads(tables: dict[str, list], scene: LoadScene) -> Loads:
    """The deck's lists of tables (:data:`DECK_KEYS`) as the kernels' tables, in deck
    order within each kind."""
    parts: dict[type, list] = {kind.Bundle: [] for kind in CARRIERS}
    for key, listed in tables.items():
        for i, table in enumerate(listed):
            try:
                made = _KIND_OF[type(table)].build(table, scene._replace(place=i))
            except MeshError as error:
                raise MeshError(f"{key}[{i}] ({table.type} on '{table.set}'): {error}") from None
            parts[type(made)].append(made)
    return Loads(*(_joined(kind, _concatenate(parts[kind.Bundle]), scene) if parts[kind.Bundle]
                   else kind.empty(scene) if hasattr(kind, "empty") else None for kind in CARRIERS))


def _joined(kind, bundle: NamedTuple, scene: LoadScene) -> NamedTuple:
    """``bundle``, every table's of ``kind``, completed by the kind's ``joined``."""
    return kind.joined(bundle, scene) if hasattr(kind, "joined") else bundle


def _concatenate(bundles: list) -> NamedTuple:
    """One bundle holding the loads of ``bundles`` (of one type), in order."""
    return type(bundles[0])(*(np.concatenate(fields) for fields in zip(*bundles)))


def features(tables: list) -> dict[str, bool]:
    """Every load and contact feature of the plan (:mod:`shellsim.plan`), True where
    ``tables`` use it."""
    used = {name: False for table in TABLES + CONTACT_TABLES + CABLE_TABLES for name in table.FEATURES}
    for table in tables:
        used[table.feature] = True
    return used


def calibrate(model, masses: np.ndarray, rotary: np.ndarray, dt: float) -> None:
    """Set the penalty springs of every kind that has them, in place, from the lumped
    masses and rotary masses (n,) and the structure's critical step ``dt``."""
    for kind, bundle in _with(model, "calibrate"):
        kind.calibrate(bundle, masses, rotary, model.h0, dt)


def overlaps_at_rest(model, contacts: list) -> list[str]:
    """What each contact kind says of surfaces that overlap in the initial shape (one line
    per contact table of the deck's ``contacts``)."""
    return [line for kind, bundle in _with(model, "overlaps_at_rest")
            for line in kind.overlaps_at_rest(bundle, contacts, model.x0)]


def hold_pairs(model, holding: bool) -> None:
    """Hold every contact node to the face it touched at the last evaluation, or search
    again at each (``holding`` false), for every kind that pairs nodes with faces."""
    for kind, bundle in _with(model, "hold_pairs"):
        kind.hold_pairs(bundle, holding)


def contact_pairs(model) -> list[np.ndarray]:
    """Each pairing kind's (K,) face row of each contact node at the last evaluation (-1:
    none), copies."""
    return [kind.pairs(bundle) for kind, bundle in _with(model, "pairs")]


def pairs_added(model, before: list[np.ndarray]) -> int:
    """How many contact nodes touch a face at the last evaluation that touched none in
    ``before`` (:func:`contact_pairs`)."""
    return sum(int(np.count_nonzero((now >= 0) & (then < 0))) for now, then in zip(contact_pairs(model), before))


def contact_of_node(model, node: int) -> str:
    """', touching a face (of a contact between shells)' where ``node`` touched a face at
    the last evaluation, else ''."""
    for pairs_now, (_, bundle) in zip(contact_pairs(model), _with(model, "pairs")):
        if np.any(pairs_now[bundle.nodes == node] >= 0):
            return ", touching a face (a contact between shells)"
    return ""


def needs_calibration(model) -> bool:
    """Whether some kind of ``model`` has penalty springs for :func:`calibrate` to set."""
    return bool(_with(model, "calibrate"))


def without(model, kind):
    """``model`` with ``kind``'s loads (a module of KINDS that carries a bundle) left out."""
    return model._replace(loads=model.loads._replace(**{kind.__name__.rsplit(".", 1)[1]: None}))


def step_share(model) -> float:
    """The share of the structure's critical step that stays stable with every penalty."""
    return min((kind.step_share(bundle) for kind, bundle in _with(model, "step_share")), default=1.0)


def stable_step(model, shape: Shape, structure: float, mass_factor: float = 1.0) -> float:
    """The critical step of the whole scene on ``shape``, from the shell structure's
    ``structure``: that share of it the penalties leave stable, and no longer than the
    step of any load kind's own elements (cables), whose masses mass scaling multiplies
    by ``mass_factor`` with the shell's (their step by its square root)."""
    own = [kind.critical_step(shape, bundle) * np.sqrt(mass_factor) for kind, bundle in _with(model, "critical_step")]
    return min([structure * step_share(model)] + own)


def hold_min_steps(model, shape: Shape) -> None:
    """Every load kind's own elements (cables) whose critical step on ``shape`` has fallen
    below their ``min_step`` made heavier to it, in place (before :func:`add_masses`)."""
    for kind, bundle in _with(model, "hold_min_step"):
        kind.hold_min_step(shape, bundle)


def add_masses(model, mt: np.ndarray, rotary: np.ndarray) -> None:
    """The masses of every load kind's own elements (cables) added to the shell's lumped
    masses mt and rotary masses (n,), in place."""
    for kind, bundle in _with(model, "add_masses"):
        kind.add_masses(bundle, mt, rotary)


#: The share of its offset a contact node may go through in an equilibrium, and of its
#: distance from the nearest face's mid-surface it may move relative to that face in one
#: load step: a node deeper has passed through (a load step too long for the penalty, or
#: a penalty too soft to hold the surfaces apart); one that moved farther may have passed
#: the face unseen (a node against face contact measures no side), and the state answers
#: nothing. Half: a node that crossed a mid-surface in the step has moved at least its
#: distance from it.
PASSED_THROUGH = 0.5


def passed_through(model, t: float, shape: Shape, before: np.ndarray) -> str | None:
    """Why the contact surfaces of ``shape`` at time t may have passed through each other
    since the positions ``before`` (n, 3) (:data:`PASSED_THROUGH`), naming the node; None
    where they cannot have."""
    for kind, bundle in _with(model, "deepest"):
        item, share = kind.farthest_moved(float(t), model, shape, bundle, before)
        if share > PASSED_THROUGH:
            return (f"contact node {bundle.nodes[item] + 1} (numbered from 1) moved {share:.2g} times its distance "
                    f"from the nearest face, relative to it, in one load step: far enough to pass through it unseen")
        item, share = kind.deepest(float(t), model, shape, bundle)
        if share > PASSED_THROUGH:
            return (f"contact node {bundle.nodes[item] + 1} (numbered from 1) has gone {share:.0%} of the way through "
                    f"the offset to the face it touches: the surfaces pass through each other (a load step too long "
                    f"for the penalty, or a penalty too soft to hold them apart)")
    return None


class ToolForces:
    """The contact tables' measures from the kinds' compiled ``item_forces`` and
    ``item_energies``: each table's force (its kind's ``FORCE_TOTAL``) by the table's
    ``name``, its contact area (the initial mid-surface shares of the nodes in contact,
    over the kind's ``SIDES``) by ``name_area`` and the energy in its springs by
    ``name_energy`` (history columns, :func:`measure_names`); the contact force and gap
    at each node (output fields)."""

    def __init__(self, model, names: list[str]):
        self.model, self.names = model, names
        kinds = _with(model, "item_forces")
        self._calls = [(TypedCall(kind.item_forces), TypedCall(kind.item_energies), bundle,
                        (np.zeros((len(bundle.tool), 3)), np.zeros(len(bundle.tool))), kind) for kind, bundle in kinds]
        self._forces = [(TypedCall(kind.add_forces), bundle) for kind, bundle in kinds]
        self._gaps = [(TypedCall(kind.item_gaps), bundle) for kind, bundle in kinds]
        # the areas only where there are columns to fill (the output field has its own)
        self._areas = node_areas(model.x0, model.conn) if self._calls and names else None

    def __call__(self, t: float, shape: Shape) -> dict[str, float]:
        totals = np.zeros((len(self.names), 3))
        forces, areas, energies = np.zeros(len(self.names)), np.zeros(len(self.names)), np.zeros(len(self.names))
        resultant = np.zeros(len(self.names), dtype=bool)
        for item_forces, item_energies, bundle, (out, stored), kind in self._calls:
            item_forces(float(t), self.model, shape, bundle, out)
            item_energies(float(t), self.model, shape, bundle, stored)
            magnitude = np.linalg.norm(out, axis=1)
            if kind.FORCE_TOTAL == "resultant":
                np.add.at(totals, bundle.tool, out)
                resultant[bundle.tool] = True
            else:
                np.add.at(forces, bundle.tool, magnitude)
            np.add.at(areas, bundle.tool, np.where(magnitude > 0.0, self._areas[bundle.nodes], 0.0) / kind.SIDES)
            np.add.at(energies, bundle.tool, stored)
        forces[resultant] = np.linalg.norm(totals[resultant], axis=1)
        return dict(zip(measure_names(self.names), np.column_stack([forces, areas, energies]).ravel().tolist()))

    @property
    def has_contact(self) -> bool:
        """Whether the model has a contact table."""
        return bool(self._forces)

    def seconds_per_evaluation(self, t: float, shape: Shape, repeats: int = 5) -> float:
        """The median wall time [s] of every contact kind's forces at time t on ``shape``
        (the search included), as a time step evaluates them (``repeats`` times)."""
        forces, g = np.zeros((self.model.n_nodes, 3)), np.zeros((self.model.n_nodes, 3))
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            for add_forces, bundle in self._forces:
                add_forces(float(t), self.model, shape, bundle, forces, g)
            times.append(time.perf_counter() - start)
        return float(np.median(times))

    def gaps(self, t: float, shape: Shape) -> np.ndarray:
        """(n,) each node's contact gap at time t: the least clearance between a face it
        offers and what a contact table lets it touch (negative: overlapping), NaN for a
        node in no contact or farther than the search reaches."""
        gaps = np.full(self.model.n_nodes, np.inf)
        for item_gaps, bundle in self._gaps:
            out = np.empty(len(bundle.nodes))
            item_gaps(float(t), self.model, shape, bundle, out)
            np.minimum.at(gaps, bundle.nodes, out)
        gaps[np.isinf(gaps)] = np.nan
        return gaps

    def at_nodes(self, t: float, shape: Shape) -> np.ndarray:
        """(n, 3) the contact force on each node at time t: every contact kind's forces,
        a face's share of what its contact nodes take included."""
        forces, g = np.zeros((self.model.n_nodes, 3)), np.zeros((self.model.n_nodes, 3))
        for add_forces, bundle in self._forces:
            add_forces(float(t), self.model, shape, bundle, forces, g)
        return forces


def measure_names(names: list[str]) -> list[str]:
    """The history columns of contact tables of these ``name``s: each name (its force),
    name_area (its contact area) and name_energy (the energy in its springs)."""
    return [column for name in names for column in (name, f"{name}_area", f"{name}_energy")]


def _chained(name: str, positions: tuple[int, ...]):
    """A compiled chain(t, model, shape, args) that calls CARRIERS[k].<name>(t, model,
    shape, model.loads[k], *args) for every k of ``positions`` whose bundle is not None,
    in order (nothing for none). Compiled code cannot call a function held in a value
    and still be cached, so the chain is built here, one inlined link per kind."""
    if not positions:
        @njit(inline="always")
        def nothing(t, model, shape, args):
            pass
        return nothing
    position, rest = positions[0], _chained(name, positions[1:])
    present = _if_present(getattr(CARRIERS[position], name))

    @njit(inline="always")
    def link(t, model, shape, args):
        present(t, model, shape, model.loads[position], args)
        rest(t, model, shape, args)
    return link


def _if_present(kind_function):
    """call(t, model, shape, bundle, args): kind_function(t, model, shape, bundle, *args)
    unless the bundle is None. Compiled, the choice is made by the bundle's type while the
    caller is typed, and the chosen body inlined: for None nothing of the kind is typed or
    compiled (numba drops a branch on a field's None only when it is an argument), and no
    compiled layer of its own copies the kind's code once more."""
    def call(t, model, shape, bundle, args):
        if bundle is not None:
            kind_function(t, model, shape, bundle, *args)

    @overload(call, inline="always")
    def typed_call(t, model, shape, bundle, args):
        if isinstance(bundle, types.NoneType):
            return lambda t, model, shape, bundle, args: None
        return lambda t, model, shape, bundle, args: kind_function(t, model, shape, bundle, *args)
    return call


def _every_kind_with(name: str):
    """:func:`_chained` over every carrying kind that has the hook ``name``."""
    return _chained(name, tuple(k for k, kind in enumerate(CARRIERS) if hasattr(kind, name)))


_add_every_kind = _every_kind_with("add_forces")
_add_every_friction = _every_kind_with("add_friction")


# external_forces and friction_forces are inlined into their callers (the time step, the
# static solver's applied forces): a compiled layer of their own would copy the kinds' code
# once more (see shellsim.element.assembly.internal_forces)
@njit(cache=True, inline="always")
def external_forces(t, model, shape, f_ext, fr_ext, g):
    """External forces at time t of every load of ``model`` (:class:`shellsim.bundles.Model`)
    on the current ``shape``, friction's apart (:func:`friction_forces`): f_ext (n, 3)
    translational and fr_ext (n, 2) rotational, both overwritten. g (n, 3): scratch for
    the director-conjugate forces, so that nothing is allocated per step."""
    f_ext[:] = 0.0
    g[:] = 0.0
    _add_every_kind(t, model, shape, (f_ext, g))
    # director-conjugate forces act on the rotational DOFs through the fibre frame
    to_rotational(g, shape.d, shape.e1, fr_ext)


@njit(cache=True, inline="always")
def friction_forces(t, model, shape, v, w, f_fr, fr_fr, g):
    """The contacts' friction at time t on the current ``shape`` moving at the velocities
    v (n, 3), w (n, 2), after :func:`external_forces` on the same shape (whose contacts
    it reads): f_fr (n, 3) and fr_fr (n, 2), overwritten; g (n, 3) scratch."""
    f_fr[:] = 0.0
    g[:] = 0.0
    _add_every_friction(t, model, shape, (f_fr, g, v, w))
    to_rotational(g, shape.d, shape.e1, fr_fr)


def friction_in_newton(table) -> bool:
    """Whether the kind of the contact ``table`` has its friction's derivative
    (``friction_couplings``), which an implicit step's Newton iterations need."""
    return hasattr(_KIND_OF[type(table)], "friction_couplings")


def has_friction(model) -> bool:
    """Whether any contact of ``model`` has friction (a ``friction`` field not all zero)."""
    return any(np.any(bundle.friction) for _, bundle in _with(model, "add_friction"))


class LoadTangents:
    """Less the derivative of every shape-dependent load, added into the elements' blocks
    k (ne, 45, 45) by each kind's compiled ``add_tangent`` (called with the argument types
    of its first call: :class:`shellsim.compiled_call.TypedCall`)."""

    def __init__(self, model):
        self.model = model
        self._calls = [(TypedCall(kind.add_tangent), bundle) for kind, bundle in _with(model, "add_tangent")]
        self._couplings = [(TypedCall(kind.couplings), bundle) for kind, bundle in _with(model, "couplings")]
        self._friction = [(TypedCall(kind.friction_couplings), bundle)
                          for kind, bundle in _with(model, "friction_couplings") if np.any(bundle.friction)]

    def __call__(self, t: float, shape: Shape, step_u: float, step_r: float, k: np.ndarray) -> None:
        for add_tangent, bundle in self._calls:
            add_tangent(float(t), self.model, shape, bundle, step_u, step_r, k)

    def couplings(self, t: float, shape: Shape, step_u: float,
                  motion: tuple[np.ndarray, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The derivative of the forces that couple nodes sharing no element: nodes (P, 10)
        and blocks (P, 30, 30) d(force)/d(translation) of each group of ten nodes, global
        axes (translations of step ``step_u`` differenced). With ``motion`` (v, rate), the
        nodes moving at v (n, 3) whose derivative by the translations is ``rate``: the
        contacts' friction's too."""
        nodes, blocks = [np.zeros((0, 10), dtype=np.int64)], [np.zeros((0, 30, 30))]
        calls = [(call, bundle, ()) for call, bundle in self._couplings]
        if motion is not None:
            calls += [(call, bundle, ((motion[0], float(motion[1])),)) for call, bundle in self._friction]
        for couplings, bundle, velocities in calls:
            n = len(bundle.nodes)
            some, their = np.zeros((n, 10), dtype=np.int64), np.zeros((n, 30, 30))
            count = couplings(float(t), self.model, shape, bundle, *velocities, step_u, some, their)
            nodes.append(some[:count])
            blocks.append(their[:count])
        return np.concatenate(nodes), np.concatenate(blocks)
