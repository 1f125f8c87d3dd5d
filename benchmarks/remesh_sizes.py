"""The surface remesher over element sizes from a quarter to a tenth of the radius: for
tubes (a coarse 32 x 8 facet cylinder, a finer 128 x 48 one, a tapered tube) and the
shipped carotid, whether each size gives a mesh that passes shellsim's checks (no folded
element), its element count, its longest element side over the size, and the time; as
shipped (bad elements mended by :mod:`shellsim.geometry.untangle`, other sizes and the
split meshes tried, ``surfaces.ATTEMPTS``) and as before (one gmsh mesh, taken as it is).
Prints a Markdown table; nothing is asserted.

    .venv/bin/python benchmarks/remesh_sizes.py
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager, nullcontext
import time
from pathlib import Path
from unittest import mock

import numpy as np

from shellsim.deck import parse_deck
from shellsim.errors import ShellsimError
from shellsim.geometry import build_mesh
from shellsim.verify.surfaces import tube_facets, write_facets

ROOT = Path(__file__).resolve().parents[1]
DIVISORS = (4, 5, 6, 7, 8, 9, 10)

DECK = """[meta]
title = "remeshed surface"
units = "SI"

[geometry]
builder = "file"
path = "{path}"
element_size = {size}

[material]
model = "neo_hookean"
C1 = 1.0e4
density = 1000.0

[section]
thickness = 0.0001

[solver]
end_time = 1.0
"""


def attempt(path: Path, size: float) -> str:
    """A table cell: elements, longest side over the size and seconds, or why it failed."""
    start = time.perf_counter()
    try:
        mesh = build_mesh(parse_deck(DECK.format(path=path.as_posix(), size=size), base_dir=path.parent), path.parent)
    except ShellsimError as error:
        return "fails: " + ("folded" if "Jacobian" in str(error) or "fold" in str(error) else str(error)[:40])
    corners = mesh.x[mesh.conn[:, :4]]
    longest = np.linalg.norm(np.roll(corners, -1, axis=1) - corners, axis=2).max() / size
    return f"{mesh.n_elements} ({longest:.1f}, {time.perf_counter() - start:.1f} s)"


@contextmanager
def as_before() -> Iterator[None]:
    """The remesher without its mending: one gmsh mesh at the size, taken as it is."""
    with mock.patch("shellsim.geometry.surfaces.untangled", side_effect=lambda x, conn, onto: x), \
            mock.patch("shellsim.geometry.surfaces.ATTEMPTS", ((False, 1.0),)):
        yield


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        tubes = {"cylinder R 1, 32 x 8 facets": ("coarse", (1.0, 1.0, 8.0, 32, 8), 1.0),
                 "cylinder R 1, 128 x 48 facets": ("fine", (1.0, 1.0, 3.0, 128, 48), 1.0),
                 "tapered tube R 1 to 0.6, 128 x 128": ("taper", (1.0, 0.6, 8.0, 128, 128), 0.8)}
        surfaces = {name: (write_facets(Path(folder) / f"{stem}.stl", *tube_facets(*shape)), radius)
                    for name, (stem, shape, radius) in tubes.items()}
        surfaces["shipped carotid (R about 4 mm)"] = (ROOT / "decks" / "tissue" / "carotid_segment.stl", 0.004)
        print("| surface | remesher | " + " | ".join(f"R/{d}" for d in DIVISORS) + " |")
        print("|---|---|" + "---|" * len(DIVISORS))
        for name, (path, radius) in surfaces.items():
            for mending in (False, True):
                with nullcontext() if mending else as_before():
                    cells = [attempt(path, radius / d) for d in DIVISORS]
                print(f"| {name} | {'as shipped' if mending else 'as before'} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
