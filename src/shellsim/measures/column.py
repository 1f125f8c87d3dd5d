"""A measured column of history.csv, as the deck names it (:mod:`shellsim.deck.columns`
checks them for clashes, :mod:`shellsim.output.plots` draws those with a quantity)."""

from __future__ import annotations

from typing import NamedTuple


class Column(NamedTuple):
    """A measured column: its ``name``, the deck key that asks for it (``owner``), whose
    column it is in words (``family``), the ``quantity`` it measures where it is plotted on
    its own (None: not), and whether a deck table ``chosen`` its name (a clash is then that
    name's) or shellsim did."""

    name: str
    owner: str
    family: str
    quantity: str | None = None
    chosen: bool = True
