"""``shellsim import``: a model file brought over as an editable deck and its mesh, the
deck's header listing what was not brought over, the deck checked as ``check`` would."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import DeckError, OutputError, ShellsimError
from .foreign import read_foreign
from .mesh import Mesh
from .output.folder import output_folder, write_atomically
from .printable import printable

DECK_NAME = "deck.toml"
#: The table of the model file's labels against shellsim's node and element indices.
ID_MAP_NAME = "ids.csv"
#: The deck's tables in the order a reader expects them.
ORDER = ("meta", "geometry", "material", "section", "boundary", "load", "contact", "cable", "curves", "solver")


@dataclass(frozen=True)
class Imported:
    """What ``shellsim import`` wrote: the deck, the mesh, the id map, its shell and cable
    element counts, the sets, the lines of what was not brought over, the deck's
    problems (empty when it runs as written) and its unit system (None: not known)."""

    deck: Path
    mesh: Path
    ids: Path
    elements: int
    cables: int
    sets: dict[str, str]
    unmapped: list[str]
    problems: list[str]
    units: str | None


def import_model(source: Path, folder: Path, user_law=None, units: str | None = None) -> Imported:
    """Bring the model ``source`` over into ``folder`` as DECK_NAME, ``<stem>.vtu`` and
    ID_MAP_NAME (kind, the file's label, shellsim's 0-based index: the mesh file's point or
    cell id), its user materials mapped by ``user_law``
    (:class:`shellsim.foreign.user_law.UserLaw`), in ``units`` (recognised without).

    Refuses (OutputError) to replace a deck already in ``folder``; MeshError for a model
    that cannot be read. The deck is validated and its sets checked against the mesh; its
    problems are returned, not raised: the deck is there to be edited.
    """
    from .output.mesh_files import write_mesh_vtu

    deck_path, mesh_path = folder / DECK_NAME, folder / f"{source.stem}.vtu"
    if deck_path.exists():
        raise OutputError(f"'{deck_path}' exists: import into another folder (--out) or move it away first")
    model = read_foreign(source, user_law, units)
    output_folder(folder)
    m = model.mesh
    thickness = m.thickness if m.thickness is not None else np.full(len(m.x), model.tables["section"]["thickness"])
    mesh = Mesh(x=m.x, conn=m.conn, director=m.director, thickness=thickness, sets=m.sets,
                cell_vectors=m.cell_vectors, point_fields=m.point_fields, cell_fields=m.cell_fields, lines=m.lines)
    write_mesh_vtu(mesh, mesh_path, with_thickness=m.thickness is not None)
    ids_path = folder / ID_MAP_NAME
    write_atomically(ids_path, "kind,label,index\n" + "".join(f"{kind},{_csv(label)},{index}\n"
                                                           for kind, label, index in model.id_map))
    tables = model.tables | {"geometry": {"builder": "file", "path": mesh_path.name}}
    text = _header(source, model.unmapped) + deck_text({key: tables[key] for key in ORDER if key in tables})
    write_atomically(deck_path, text)
    sets = {name: s.kind for name, s in m.sets.items()}
    return Imported(deck_path, mesh_path, ids_path, len(m.conn), len(m.lines), sets, model.unmapped,
                    _problems(deck_path), model.tables["meta"].get("units"))


def _csv(text: str) -> str:
    """``text`` as a CSV field: quoted where it holds a comma or a quote."""
    return '"' + text.replace('"', '""') + '"' if any(c in text for c in ',"\n') else text


def deck_text(tables: dict) -> str:
    """TOML of deck ``tables`` as a person writes it: one ``[table]`` or ``[[table]]`` per
    entry, sub-tables and vectors inline (``axes = { kind = "fixed", ... }``)."""
    blocks = []
    for key, value in tables.items():
        if isinstance(value, list):
            blocks += [f"[[{key}]]\n" + _keys(item) for item in value]
        elif key == "curves":
            blocks += [f"[curves.{_key(name)}]\n" + _keys(curve) for name, curve in value.items()]
        else:
            blocks.append(f"[{key}]\n" + _keys(value))
    return "\n".join(blocks)


def _key(name: str) -> str:
    """``name`` as a TOML key: bare where it may be, else a quoted string."""
    return name if re.fullmatch(r"[A-Za-z0-9_\-]+", name) else _string(name)


def _string(text: str) -> str:
    """``text`` as a TOML basic string: JSON's escapes, and DEL's, which JSON leaves bare."""
    return json.dumps(text).replace("\x7f", "\\u007f")


def _keys(table: dict) -> str:
    return "".join(f"{_key(key)} = {_inline(value)}\n" for key, value in table.items())


def _inline(value) -> str:
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_key(key)} = {_inline(v)}" for key, v in value.items()) + " }"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_inline(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return _string(str(value))


def _header(source: Path, unmapped: list[str]) -> str:
    """The deck's opening comments; what they quote of the file is one line each
    (:func:`printable`), so no text of the file's can start a table."""
    lines = [f"# Brought over from {printable(source.name)} by `shellsim import`."]
    if unmapped:
        lines += ["# Not brought over (state these in the deck where the scene needs them):"]
        lines += [f"#   - {printable(line)}" for line in unmapped]
    return "\n".join(lines) + "\n\n"


def _problems(deck_path: Path) -> list[str]:
    """What ``shellsim check`` would refuse in the written deck (its sets read from the mesh)."""
    from .deck import load_deck
    from .geometry import build_mesh

    try:
        deck = load_deck(deck_path)
        build_mesh(deck, deck_path.parent)
    except DeckError as error:
        return error.problems
    except ShellsimError as error:
        return [str(error)]
    return []
