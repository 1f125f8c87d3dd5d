"""The resolved deck: every default filled in, written back as TOML that loads to the same
scene, with the program version, for provenance beside a run's results."""

from __future__ import annotations

from pathlib import Path

import tomli_w

from .schema import Deck


def resolved_text(deck: Deck, source: Path, version: str) -> str:
    """TOML of ``deck`` as read from ``source`` with all defaults; a mesh file it names is
    made absolute so the copy loads from anywhere."""
    data = deck.model_dump(mode="json", exclude_none=True)
    if deck.geometry.builder == "file":
        from . import resolve_mesh_path

        data["geometry"]["path"] = str(resolve_mesh_path(deck, source.parent).resolve())
    header = f"# {source} resolved by shellsim {version}: every default filled in\n"
    return header + tomli_w.dumps(data, multiline_strings=True)
