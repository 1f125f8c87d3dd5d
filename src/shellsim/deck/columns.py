"""The columns of history.csv, named by the deck: the history's own (time, step,
energies), then each family of measured columns in the order :data:`FAMILIES` lists
them. The solver's measures (:mod:`shellsim.solver.measures`) fill the same columns; the
names live here so that the deck can check them before anything runs.

A family is one function: the deck in, its columns out, each with the deck key that asks
for it, whose column it is (for a message) and what it measures (a quantity, for units;
None: not plotted on its own).
"""

from __future__ import annotations

from typing import NamedTuple

from ..loads import measure_names
from .schema import Deck

#: The energies' columns of history.csv, in the order of the time loop's energy indices;
#: the last, friction's, only where a contact has friction.
ENERGY_COLUMNS = ("internal_energy", "kinetic_energy", "external_work", "damping_work", "friction_work")
#: The columns every history.csv has: no probe, contact or measure may take their names.
OWN_COLUMNS = ("time", "dt", *ENERGY_COLUMNS)


class Column(NamedTuple):
    """A measured column: its ``name``, the deck key that asks for it (``owner``), whose
    column it is in words (``family``), and the ``quantity`` it measures where it is
    plotted on its own (None: not)."""

    name: str
    owner: str
    family: str
    quantity: str | None = None


def load_factor_columns(deck: Deck) -> dict[str, int]:
    """The history columns of the curves' factors at the load time, each with its curve's
    index in the model's tables: ``load_factor_<curve>`` for every deck curve, and
    ``load_factor`` for the ramp that the loads without a curve of a static solve or a
    preload follow."""
    columns = {f"load_factor_{name}": deck.curve_index(name) for name in deck.curves}
    if deck.solver.ramp_end is not None:
        columns["load_factor"] = deck.curve_index(None)
    return columns


def probe_columns(deck: Deck) -> list[Column]:
    """Each ``[[output.probe]]``'s column, its name."""
    return [Column(p.name, f"output.probe[{i}].name", "a probe's", p.quantity) for i, p in enumerate(deck.output.probe)]


def factor_columns(deck: Deck) -> list[Column]:
    """Each curve's load factor at the load time (:func:`load_factor_columns`)."""
    return [Column(name, f"curves.{name.removeprefix('load_factor_')}" if name != "load_factor" else "the static ramp",
                   "a curve's load factor") for name in load_factor_columns(deck)]


def contact_columns(deck: Deck) -> list[Column]:
    """Each ``[[contact]]``'s force, contact area and spring energy."""
    return [Column(column, f"contact[{i}].name", "a contact's") for i, contact in enumerate(deck.contact)
            for column in measure_names([contact.name])]


def valve_columns(deck: Deck) -> list[Column]:
    """``[output.valve]``'s measures."""
    valve = deck.output.valve
    return [] if valve is None else [Column(name, "output.valve", "a valve measure's", quantity)
                                     for name, quantity in valve.COLUMNS.items()]


#: Every family of measured columns, in the order history.csv has them.
FAMILIES = (probe_columns, factor_columns, contact_columns, valve_columns)
#: The families whose names no table chooses: a clash is the chosen name's.
NAMED_BY_SHELLSIM = (factor_columns, valve_columns)


def measured_columns(deck: Deck) -> list[Column]:
    """Every measured column of ``deck``'s history, in order."""
    return [column for family in FAMILIES for column in family(deck)]


def column_clashes(deck: Deck) -> list[str]:
    """One problem for each measured column whose name is one of the history's own or an
    earlier column's: history.csv would have two columns of one name."""
    problems, taken = [], {}
    chosen = [family for family in FAMILIES if family not in NAMED_BY_SHELLSIM]
    for column in [column for family in (*NAMED_BY_SHELLSIM, *chosen) for column in family(deck)]:
        if column.name in OWN_COLUMNS:
            problems.append(f"{column.owner}: '{column.name}' is one of history.csv's own columns "
                            f"({', '.join(OWN_COLUMNS)}); choose another name")
        elif column.name in taken:
            first = taken[column.name]
            problems.append(f"{column.owner}: '{column.name}' is already a history column, {first.family} "
                            f"({first.owner}); choose another name")
        else:
            taken[column.name] = column
    return problems
