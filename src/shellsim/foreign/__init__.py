"""Models made with other programs, brought over as a mesh and the deck tables that state
the rest of their scene; what does not map is listed, never dropped.

A reader is one module and one line in :data:`READERS` (file suffix -> reader)."""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import MeshError
from ..mesh import ImportedMesh
from .units import with_units


@dataclass(frozen=True)
class ForeignModel:
    """What a model file gives.

    mesh : its shells as 9-node quads with named sets, directors and per-element data.
    tables : the deck's tables (``material``, ``section``, ``boundary``, ``load``,
        ``contact``, ``curves``, ``solver``, ``meta``), as TOML-ready values; ``geometry``
        is the writer's.
    unmapped : one line per thing of the file that the deck does not carry, each naming
        the keyword and where it was written and what the deck says instead.
    unused_elements : the lines of those that concern the mesh (elements left out), so that
        a deck reading the file's mesh directly can refuse it rather than lose them.
    id_map : (kind, the file's label, shellsim's index) of each node, element and cable
        element (:meth:`.shell_mesh.ShellMesh.id_map`).
    """

    mesh: ImportedMesh
    tables: dict
    unmapped: list[str]
    unused_elements: list[str]
    id_map: list[tuple[str, str, int]]


def meta_table(path: Path, title: str) -> dict:
    """The deck's ``[meta]`` of a model brought over from ``path``."""
    return {"title": title, "description": f"Brought over from {path.name}", "source": path.name}


def read_foreign(path: Path, user_law=None, units: str | None = None) -> ForeignModel:
    """The model in ``path``, read by the reader of its suffix; MeshError for another file.
    ``user_law`` (:class:`.user_law.UserLaw`) maps its user materials onto a law; ``units``
    names the file's unit system (recognised from its densities without)."""
    reader = READERS.get(Path(path).suffix.lower())
    if reader is None:
        raise MeshError(f"'{path}' is not a model file shellsim reads (suffixes: {', '.join(sorted(READERS))})")
    check_model_file(Path(path))
    try:
        model = reader(Path(path), user_law)
    except (ValueError, IndexError) as error:  # a number that is not one, a data line cut short
        raise MeshError(f"model file '{path}' holds a value shellsim cannot read ({error}): a number that is not a "
                        "number, or a data line with fields missing") from None
    except MemoryError:
        raise MeshError(f"model file '{path}' ({Path(path).stat().st_size / 1e6:,.0f} MB) does not fit in the memory "
                        "this process may use to read it; read it on a machine with more memory, or split its "
                        "mesh out") from None
    notes = list(model.unmapped)
    tables = with_units(model.tables, units, notes)
    return replace(model, tables=tables, unmapped=grouped(notes))


#: A note's place in the file: '(name.inp:123)' after the keyword it is about.
_PLACE = re.compile(r" \(([^()]+:\d+)\)")
#: The places a grouped note shows before '...'.
SHOWN_PLACES = 3


def grouped(notes: list[str]) -> list[str]:
    """The notes with those that differ only in their place in the file said once, with
    their count and first places: '*BOUNDARY (276 times: leaflet.inp:12, :40, :58, ...):
    OP=NEW ...'; in the order each first comes."""
    places: dict[str, list[str]] = {}
    for note in notes:
        found = _PLACE.search(note)
        key = note if found is None else note[:found.start()] + " ({})" + note[found.end():]
        places.setdefault(key, []).append(found.group(1) if found else "")
    out = []
    for key, where in places.items():
        if len(where) == 1 or not where[0]:  # said once, or a note of no place: as it was
            out += [key.replace("({})", f"({w})") if w else key for w in where]
            continue
        shown = ", ".join(where[:SHOWN_PLACES]) + (", ..." if len(where) > SHOWN_PLACES else "")
        out.append(key.replace("({})", f"({len(where)} times: {shown})"))
    return out


def check_model_file(path: Path) -> None:
    """MeshError unless ``path`` is a regular file: a folder, a missing file or a FIFO
    (which would block the read for ever) is named instead of read."""
    if not path.exists():
        raise MeshError(f"model file '{path}' not found")
    if not path.is_file():
        raise MeshError(f"model file '{path}' is not a regular file (a folder, a pipe or a device?)")


def read_foreign_mesh(path: Path) -> ImportedMesh:
    """The mesh of the model in ``path``; MeshError listing its elements that cannot be used."""
    model = read_foreign(path)
    if model.unused_elements:
        raise MeshError(f"model file '{path}' has elements shellsim cannot use (`shellsim import` brings over the "
                        "rest and lists them):\n" + "\n".join(f"  - {line}" for line in model.unused_elements))
    return model.mesh


def _abaqus(path: Path, user_law) -> ForeignModel:
    from .abaqus import read_abaqus

    return read_abaqus(path, user_law)


def _febio(path: Path, user_law) -> ForeignModel:
    """FEBio's materials are its own types: no user law to map."""
    from .febio import read_febio

    return read_febio(path)


#: File suffix -> the reader of that program's models.
READERS = {".inp": _abaqus, ".feb": _febio}
