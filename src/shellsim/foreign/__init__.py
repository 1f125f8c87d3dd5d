"""Models made with other programs, brought over as a mesh and the deck tables that state
the rest of their scene; what does not map is listed, never dropped.

A reader is one module and one line in :data:`READERS` (file suffix -> reader)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import MeshError
from ..mesh import ImportedMesh


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
    """

    mesh: ImportedMesh
    tables: dict
    unmapped: list[str]
    unused_elements: list[str]


def meta_table(path: Path, title: str) -> dict:
    """The deck's ``[meta]`` of a model brought over from ``path``."""
    return {"title": title, "description": f"Brought over from {path.name}", "source": path.name}


def read_foreign(path: Path) -> ForeignModel:
    """The model in ``path``, read by the reader of its suffix; MeshError for another file."""
    reader = READERS.get(Path(path).suffix.lower())
    if reader is None:
        raise MeshError(f"'{path}' is not a model file shellsim reads (suffixes: {', '.join(sorted(READERS))})")
    check_model_file(Path(path))
    try:
        return reader(Path(path))
    except (ValueError, IndexError) as error:  # a number that is not one, a data line cut short
        raise MeshError(f"model file '{path}' holds a value shellsim cannot read ({error}): a number that is not a "
                        "number, or a data line with fields missing") from None
    except MemoryError:
        raise MeshError(f"model file '{path}' ({Path(path).stat().st_size / 1e6:,.0f} MB) does not fit in the memory "
                        "this process may use to read it; read it on a machine with more memory, or split its "
                        "mesh out") from None


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


def _abaqus(path: Path) -> ForeignModel:
    from .abaqus import read_abaqus

    return read_abaqus(path)


def _febio(path: Path) -> ForeignModel:
    from .febio import read_febio

    return read_febio(path)


#: File suffix -> the reader of that program's models.
READERS = {".inp": _abaqus, ".feb": _febio}
