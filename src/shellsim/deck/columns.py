"""The columns of history.csv, named by the deck: the history's own (time, step,
energies), then each measure family's (:mod:`shellsim.measures`), checked here for two
columns of one name before anything runs."""

from __future__ import annotations

from ..measures import measured_columns

#: The energies' columns of history.csv, in the order of the time loop's energy indices;
#: the last, friction's, only where a contact has friction.
ENERGY_COLUMNS = ("internal_energy", "kinetic_energy", "external_work", "damping_work", "friction_work")
#: The columns every history.csv has: no probe, contact or measure may take their names.
OWN_COLUMNS = ("time", "dt", *ENERGY_COLUMNS)


def column_clashes(deck) -> list[str]:
    """One problem for each measured column whose name is one of the history's own or an
    earlier column's: history.csv would have two columns of one name. The columns whose
    names shellsim chose go first, so that a clash is the chosen name's."""
    problems, taken = [], {}
    columns = measured_columns(deck)
    for column in [c for c in columns if not c.chosen] + [c for c in columns if c.chosen]:
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
