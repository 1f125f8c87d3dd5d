"""Reading decks: TOML in, a validated :class:`Deck` out, or a :class:`DeckError` that names
every problem (file, key path, value given, what was expected)."""


from __future__ import annotations

import tomllib
from pathlib import Path

from pydantic import ValidationError

from ..errors import DeckError
from ..loads import DECK_KEYS
from .messages import format_errors
from .curves import with_file_tables
from .references import check_references
from .schema import Deck


def load_deck(path: str | Path) -> Deck:
    """Read and validate the deck at ``path``; mesh files it names are resolved next to it."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DeckError(str(path), ["file not found"]) from None
    except IsADirectoryError:
        raise DeckError(str(path), ["is a directory, expected a .toml deck file"]) from None
    except UnicodeDecodeError as err:
        raise DeckError(str(path), [f"not UTF-8 text ({err.reason} at byte {err.start})"]) from None
    except OSError as err:
        raise DeckError(str(path), [f"cannot be read: {err.strerror}"]) from None
    return parse_deck(text, name=str(path), base_dir=path.parent)


def parse_deck(text: str, name: str = "<deck>", base_dir: Path | None = None) -> Deck:
    """Validate deck source ``text``; ``name`` labels messages, ``base_dir`` resolves files."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise DeckError(name, [f"not valid TOML: {err}"]) from None
    return deck_from_data(data, name, base_dir, text)


def deck_from_data(data: dict, name: str = "<deck>", base_dir: Path | None = None, text: str = "") -> Deck:
    """Validate parsed deck ``data``; ``text`` (its TOML source) gives line numbers."""
    try:
        deck = Deck.model_validate(data)
    except ValidationError as err:
        raise DeckError(name, format_errors(err, data, text, Deck)) from None
    deck = _curve_files_read(deck, name, base_dir)
    deck = _table_files_found(deck, name, base_dir)
    builder_sets = deck.geometry.sets() if deck.geometry.builder != "file" else None
    problems = check_references(deck, builder_sets)
    if problems:
        raise DeckError(name, problems)
    return deck


def _curve_files_read(deck: Deck, name: str, base_dir: Path | None) -> Deck:
    """``deck`` with the tables of its curves' files in place (:func:`with_file_tables`);
    DeckError naming every file that cannot be used."""
    curves, problems = {}, []
    for key, curve in deck.curves.items():
        try:
            curves[key] = with_file_tables(curve, base_dir)
        except ValueError as error:
            problems.append(f"curves.{key}.file: {error}")
        except ValidationError as error:
            problems += [f"curves.{key}.file '{curve.file}': {e['msg'].removeprefix('Value error, ')}"
                         for e in error.errors()]
    if problems:
        raise DeckError(name, problems)
    return deck.model_copy(update={"curves": curves})


def _table_files_found(deck: Deck, name: str, base_dir: Path | None) -> Deck:
    """``deck`` with the files its load, contact and cable tables name (their ``FILE_KEYS``) as
    absolute paths, relative ones taken from the deck's folder; DeckError naming every
    file that is not there."""
    lists, problems = {}, []
    for key in DECK_KEYS:
        lists[key] = []
        for i, table in enumerate(getattr(deck, key)):
            found = {}
            for file_key in table.FILE_KEYS:
                given = getattr(table, file_key)
                if given is None:
                    continue
                path = Path(given) if Path(given).is_absolute() or base_dir is None else base_dir / given
                if not path.is_file():
                    problems.append(f"{key}[{i}].{file_key}: file '{given}' not found"
                                    + (f" (looked in {base_dir})" if base_dir is not None else ""))
                found[file_key] = str(path.resolve())
            lists[key].append(table.model_copy(update=found))
    if problems:
        raise DeckError(name, problems)
    return deck.model_copy(update=lists)


def resolve_mesh_path(deck: Deck, base_dir: Path | None) -> Path:
    """The mesh file of a ``builder = 'file'`` deck, relative to the deck's folder."""
    path = Path(deck.geometry.path)
    return path if path.is_absolute() or base_dir is None else base_dir / path
