"""External loads as registered kinds, one module each, and what the solvers call:
:func:`build_loads` (the deck's loads as the kernels' tables), the compiled
:func:`external_forces` and :func:`add_load_tangents`.

A kind is a module of this package with
- ``TABLES``: its ``[[load]]`` deck tables (:class:`~shellsim.loads.table.LoadTable`,
  ``type`` their tag; the deck's load union is every kind's tables);
- ``build(table, scene)``: one table's loads on the mesh (``scene`` a :class:`LoadScene`),
  as the ``Bundle`` of this kind or of another one (a dead pressure is tabulated as
  nodal forces, a mapped pressure is a follower pressure with values of its own);
and, when it has kernels of its own,
- ``Bundle``: a NamedTuple of arrays, every field with the loads along its first axis
  (the registry concatenates one per table), and ``empty(scene)``, a bundle of none;
- compiled ``add_forces(t, model, shape, bundle, f, g)``: its translational and
  director-conjugate forces f, g (n, 3) at time t added;
- compiled ``add_tangent(t, model, shape, bundle, step_u, step_r, k)`` where its forces
  depend on the shape: less their derivative, into the elements' blocks k (ne, 45, 45).
Adding a kind is writing its module and adding it to :data:`KINDS`.
"""

from __future__ import annotations

from typing import Callable, NamedTuple, Union

import numpy as np
from numba import njit

from ..bundles import Body, Curves, Rule, Shape
from ..compiled_call import TypedCall
from ..element.frames import to_rotational
from ..errors import MeshError
from . import edge_pressure, mapped_pressure, nodal, pressure

#: The kinds, in the order their forces are added.
KINDS = (nodal, pressure, edge_pressure, mapped_pressure)

#: The kinds with kernels of their own: the fields of :data:`Loads`.
CARRIERS = tuple(kind for kind in KINDS if hasattr(kind, "Bundle"))

#: Every ``[[load]]`` deck table, and the kind that builds each.
TABLES = tuple(table for kind in KINDS for table in kind.TABLES)
_KIND_OF = {table: kind for kind in KINDS for table in kind.TABLES}

#: Every load of a scene (:class:`shellsim.bundles.Model`'s ``loads``): one bundle per
#: carrying kind, named after its module.
Loads = NamedTuple("Loads", [(kind.__name__.rsplit(".", 1)[1], kind.Bundle) for kind in CARRIERS])

DeckLoad = Union[TABLES]


class LoadScene(NamedTuple):
    """What a kind's ``build`` reads: the mesh (:class:`shellsim.mesh.Mesh`), the element's
    rule and body, the initial shape, the curve tables and ``curve_index(name)``, a curve's
    place in them (a load without a curve: the static ramp's or -1)."""

    mesh: object
    rule: Rule
    body: Body
    initial: Shape
    curves: Curves
    curve_index: Callable[[Union[str, None]], int]


def build_loads(loads: list[DeckLoad], scene: LoadScene) -> Loads:
    """The deck's ``loads`` as the kernels' tables, in deck order within each kind."""
    parts: dict[type, list] = {kind.Bundle: [] for kind in CARRIERS}
    for i, table in enumerate(loads):
        try:
            made = _KIND_OF[type(table)].build(table, scene)
        except MeshError as error:
            raise MeshError(f"load[{i}] ({table.type} on '{table.set}'): {error}") from None
        parts[type(made)].append(made)
    return Loads(*(_concatenate(parts[kind.Bundle]) if parts[kind.Bundle] else kind.empty(scene) for kind in CARRIERS))


def _concatenate(bundles: list) -> NamedTuple:
    """One bundle holding the loads of ``bundles`` (of one type), in order."""
    return type(bundles[0])(*(np.concatenate(fields) for fields in zip(*bundles)))


def features(loads: list[DeckLoad]) -> dict[str, bool]:
    """Every load feature of the plan (:mod:`shellsim.plan`), True where ``loads`` use it."""
    used = {name: False for table in TABLES for name in table.FEATURES}
    for load in loads:
        used[load.feature] = True
    return used


def _chained(name: str, position: int = 0):
    """A compiled f(t, model, shape, f, g) that calls CARRIERS[k].<name>(t, model, shape,
    model.loads[k], f, g) for every k from ``position`` on, in order. Compiled code cannot
    call a function held in a value and still be cached, so the chain is built here, one
    inlined link per kind."""
    kind_function = getattr(CARRIERS[position], name)
    if position == len(CARRIERS) - 1:
        @njit(inline="always")
        def last(t, model, shape, f, g):
            kind_function(t, model, shape, model.loads[position], f, g)
        return last
    rest = _chained(name, position + 1)

    @njit(inline="always")
    def link(t, model, shape, f, g):
        kind_function(t, model, shape, model.loads[position], f, g)
        rest(t, model, shape, f, g)
    return link


_add_every_kind = _chained("add_forces")


@njit(cache=True)
def external_forces(t, model, shape, f_ext, fr_ext, g):
    """External forces at time t of every load of ``model`` (:class:`shellsim.bundles.Model`)
    on the current ``shape``: f_ext (n, 3) translational and fr_ext (n, 2) rotational,
    both overwritten. g (n, 3): scratch for the director-conjugate forces, so that
    nothing is allocated per step."""
    f_ext[:] = 0.0
    g[:] = 0.0
    _add_every_kind(t, model, shape, f_ext, g)
    # director-conjugate forces act on the rotational DOFs through the fibre frame
    to_rotational(g, shape.d, shape.e1, fr_ext)


class LoadTangents:
    """Less the derivative of every shape-dependent load, added into the elements' blocks
    k (ne, 45, 45) by each kind's compiled ``add_tangent`` (called with the argument types
    of its first call: :class:`shellsim.compiled_call.TypedCall`)."""

    def __init__(self, model):
        self.model = model
        self._calls = [(TypedCall(kind.add_tangent), bundle) for kind, bundle in zip(CARRIERS, model.loads)
                       if hasattr(kind, "add_tangent") and any(len(field) for field in bundle)]

    def __call__(self, t: float, shape: Shape, step_u: float, step_r: float, k: np.ndarray) -> None:
        for add_tangent, bundle in self._calls:
            add_tangent(float(t), self.model, shape, bundle, step_u, step_r, k)
