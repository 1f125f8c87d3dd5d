"""What a run measures into history.csv, one family of columns per module, registered in
:data:`FAMILIES`: the run samples each family it is handed and names none.

A family is a module with
- ``columns(deck)``: the columns it adds for ``deck`` (:class:`.column.Column`, each with
  the deck key that asks for it), in order; the deck checks them before anything runs;
- ``resolve(deck, mesh, model)``: its measures placed on the scene, a :class:`Measure`
  (None where the deck asks for none);
- where a deck table asks for it, ``TABLE``, ``OUTPUT_KEY`` and ``OUTPUT_FIELD``: the
  table, its key in ``[output]`` and (annotation, default), which the deck's ``[output]``
  section is built with; and ``named_sets(deck)``: (deck key, set name, the set kinds it
  may be) of each set its tables name, which the deck checks against the geometry.
A new family is a module here and a line in :data:`FAMILIES`. The families sit below the
deck (which builds its ``[output]`` from them) and read the running scene duck-typed.
"""

from __future__ import annotations

from typing import Protocol

from ..bundles import Model
from ..mesh import Mesh
from . import contact, load_factors, lumen, probes, valve
from .column import Column


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
        """The values of :attr:`columns` now, in ``run`` (a :class:`shellsim.solver.run.Run`)."""

    def record(self, run, output_seconds: float) -> dict | None:
        """Its summary.json entry at the end of ``run`` (``output_seconds`` of its wall
        time spent writing); None: it has none."""


#: Every family, in the order of their columns in history.csv.
FAMILIES = (probes, load_factors, contact, valve, lumen)
#: The ``[output]`` keys the families' tables take: key -> (annotation, default).
OUTPUT_FIELDS = {family.OUTPUT_KEY: family.OUTPUT_FIELD for family in FAMILIES if hasattr(family, "OUTPUT_KEY")}


def measured_columns(deck) -> list[Column]:
    """Every measured column of ``deck``'s history, in order."""
    return [column for family in FAMILIES for column in family.columns(deck)]


def measured_sets(deck) -> list[tuple[str, str, tuple[str, ...]]]:
    """(deck key, set name, kinds it may be) of every set the measures of ``deck`` read."""
    return [named for family in FAMILIES if hasattr(family, "named_sets") for named in family.named_sets(deck)]


def resolve_measures(deck, mesh: Mesh, model: Model) -> list[Measure]:
    """The measures ``deck`` asks for, placed on ``mesh`` and ``model``, in column order."""
    return [measure for family in FAMILIES if (measure := family.resolve(deck, mesh, model)) is not None]
