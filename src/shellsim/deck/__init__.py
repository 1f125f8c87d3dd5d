"""Reading decks: TOML in, a validated :class:`Deck` out, or a :class:`DeckError` that names
every problem (file, key path, value given, what was expected); see :mod:`.reading`.

The names below load on first use: the material laws define their deck tables with this
package's value types (:mod:`.types`), and the schema in turn lists the laws, so
importing the package must not import the schema."""

from __future__ import annotations

from importlib import import_module

__all__ = ["Deck", "deck_from_data", "load_deck", "parse_deck", "resolve_mesh_path"]


def __getattr__(name: str):
    if name in __all__:
        return getattr(import_module(".reading", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
