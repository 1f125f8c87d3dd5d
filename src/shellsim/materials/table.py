"""The base of every ``[material]`` table: the parts of the model it covers."""

from __future__ import annotations

from ..table_types import Name, Section


class MaterialTable(Section):
    """A material of the model. ``sets``: the surface sets whose elements it covers; a
    deck of one material may leave them out (it covers every element), a deck of several
    (``[[material]]`` tables) names each one's, every element in exactly one."""

    sets: list[Name] = []
