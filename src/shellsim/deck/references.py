"""Names that tie the deck's tables together: sets (from the geometry), curves, probes.

Checked after the tables themselves validate, against the set names a builder will
produce, so a misspelt name is caught before any meshing or computing. A mesh file's sets
are known once the file is read: :func:`shellsim.geometry.build_mesh` checks them then.
"""

from __future__ import annotations

import difflib

from ..loads import DECK_KEYS
from ..measures import measured_columns, measured_sets
from .columns import column_clashes
from .schema import Deck


def did_you_mean(word: str, choices: list[str] | tuple[str, ...]) -> str:
    """'; did you mean 'x'?' when a choice is close to ``word``, else ''."""
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""


def all_sets(deck: Deck, geometry_sets: dict[str, str]) -> dict[str, str]:
    """Every named set of the scene with its kind: the geometry's, ``all``, the deck's
    own ``[mesh] points`` and the sets its cables add."""
    added = {name: kind for table in deck.cable for name, kind in table.declared_sets.items()}
    return geometry_sets | {"all": "surface"} | {name: "point" for name in deck.mesh.points} | added


def check_references(deck: Deck, geometry_sets: dict[str, str] | None) -> list[str]:
    """Problems with names in ``deck``, one message per problem (empty when all resolve).

    Parameters
    ----------
    deck : a validated deck.
    geometry_sets : set name -> kind ('surface', 'edge' or 'point') the geometry provides;
        None when they are not known yet (a mesh file not read): sets are then not checked.
    """
    sets = all_sets(deck, geometry_sets or {})
    problems: list[str] = []

    def need_set(path: str, name: str, kinds: tuple[str, ...] = ("surface", "edge", "point")) -> None:
        if geometry_sets is None:
            return
        if name not in sets:
            listing = ", ".join(sorted(sets))
            problems.append(
                f"{path}: unknown set '{name}'{did_you_mean(name, sorted(sets))} "
                f"(sets of this geometry: {listing})"
            )
        elif sets[name] not in kinds:
            problems.append(
                f"{path}: set '{name}' is a {sets[name]} set; expected a "
                f"{' or '.join(kinds)} set here"
            )

    def need_curve(path: str, name: str | None) -> None:
        if name is not None and name not in deck.curves:
            known = ", ".join(sorted(deck.curves)) or "none defined"
            problems.append(
                f"{path}: unknown curve '{name}'{did_you_mean(name, sorted(deck.curves))} "
                f"(curves: {known})"
            )

    for name in deck.mesh.points:
        if name in (geometry_sets or {}) or name == "all":
            problems.append(f"mesh.points.{name}: the geometry already has a set named '{name}'"
                            + (" (every element)" if name == "all" else ""))
    taken = dict.fromkeys(list(geometry_sets or {}) + ["all"] + list(deck.mesh.points), "the geometry's or [mesh] points'")
    for i, table in enumerate(deck.cable):
        for name in table.declared_sets:
            if name in taken:
                problems.append(f"cable[{i}].name: '{table.name}' adds the set '{name}', which is already "
                                f"{taken[name]}; choose another name")
            taken[name] = f"cable[{i}]'s"
    for i, material in enumerate(deck.material):
        for name in material.sets:
            need_set(f"material[{i}].sets", name, ("surface",))
    for i, bc in enumerate(deck.boundary):
        need_set(f"boundary[{i}].set", bc.set)
        need_curve(f"boundary[{i}].curve", getattr(bc, "curve", None))
    for key in DECK_KEYS:
        for i, table in enumerate(getattr(deck, key)):
            for name_key, name in table.named_sets.items():
                need_set(f"{key}[{i}].{name_key}", name, table.SET_KINDS)
            need_curve(f"{key}[{i}].curve", getattr(table, "curve", None))
    problems += column_clashes(deck)
    for path, name, kinds in measured_sets(deck):
        need_set(path, name, kinds)
    probes = [column.name for column in measured_columns(deck)]
    for i, ref in enumerate(deck.reference):
        if ref.probe not in probes:
            problems.append(
                f"reference[{i}].probe: unknown probe '{ref.probe}'{did_you_mean(ref.probe, probes)} "
                f"(probes: {', '.join(probes) or 'none; add [[output.probe]]'})"
            )
    return problems
