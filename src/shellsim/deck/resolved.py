"""The resolved deck: every default filled in, written back as TOML that loads to the same
scene, with the program version, for provenance beside a run's results; and read back by
what works on those results (renders, plots)."""

from __future__ import annotations

from pathlib import Path

import tomli_w

from ..errors import OutputError
from .schema import Deck

#: The resolved deck's name in a run's folder.
RESOLVED_NAME = "deck.toml"


def resolved_text(deck: Deck, source: Path, version: str) -> str:
    """TOML of ``deck`` as read from ``source`` with all defaults; a mesh file it names is
    made absolute so the copy loads from anywhere."""
    data = deck.model_dump(mode="json", exclude_none=True)
    if deck.geometry.builder == "file":
        from . import resolve_mesh_path

        data["geometry"]["path"] = str(resolve_mesh_path(deck, source.parent).resolve())
    header = f"# {source} resolved by shellsim {version}: every default filled in\n"
    return header + tomli_w.dumps(data, multiline_strings=True)


def read_resolved(folder: Path) -> Deck:
    """The deck a run in ``folder`` was resolved from; OutputError when the folder holds none."""
    from . import parse_deck

    path = folder / RESOLVED_NAME
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise OutputError(f"'{folder}' is not a run's folder: {error.strerror or error} ({path})") from None
    return parse_deck(text, name=str(path))
