"""What a run measures into history.csv, one family of columns per module, registered in
:data:`FAMILIES`: the run samples each family it is handed and names none.

A family is a module with ``resolve(deck, mesh, model)``, which places the family's
measures on the scene (None where the deck asks for none), returning a :class:`Measure`.
Its columns are the ones :mod:`shellsim.deck.columns` names for the deck, in the same
order, so the deck checks them before anything runs; a new family is a module here, a
line in :data:`FAMILIES`, and its columns' function there.
"""

from __future__ import annotations

from typing import Protocol

from ...mesh import Mesh
from ...model import Model
from . import contact, load_factors, probes, valve


class Measure(Protocol):
    """A family's measures on a scene.

    NAME : the family's key in summary.json (where it has an entry) and in checkpoints.
    columns : its history columns, in order.
    sparse : whether it measures at some samples only (NaN at the others), which
        references and plots then leave out.
    """

    NAME: str
    columns: list[str]
    sparse: bool

    def sample(self, run) -> list[float]:
        """The values of :attr:`columns` now, in ``run`` (:class:`shellsim.solver.run.Run`)."""

    def record(self, run, output_seconds: float) -> dict | None:
        """Its summary.json entry at the end of ``run`` (``output_seconds`` of its wall
        time spent writing); None: it has none."""


#: Every family, in the order of their columns (:data:`shellsim.deck.columns.FAMILIES`).
FAMILIES = (probes, load_factors, contact, valve)


def resolve_measures(deck, mesh: Mesh, model: Model) -> list[Measure]:
    """The measures ``deck`` asks for, placed on ``mesh`` and ``model``, in column order."""
    return [measure for family in FAMILIES if (measure := family.resolve(deck, mesh, model)) is not None]
