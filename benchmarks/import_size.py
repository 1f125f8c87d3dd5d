"""Wall time of bringing an Abaqus model over at the size of a valve model: a shell sheet of
S4R elements (default 100 x 80 = 8,000) and chordae of T3D2 trusses (default 100 chords of
40 elements = 4,000) from the sheet's free edge to two papillary nodes, written by this
script. Times reading the file (``read_foreign``) and the whole ``shellsim import``
(mesh file written, deck written and checked against the mesh read back). Prints a
Markdown table; nothing is asserted.

    .venv/bin/python benchmarks/import_size.py [--shells 100 80] [--chords 100 40] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path


def valve_sized_inp(nx: int, ny: int, chords: int, segments: int) -> str:
    """An input file: an nx x ny S4R sheet (20 x 16 mm, clamped along y = 0) and ``chords``
    chains of ``segments`` T3D2 elements from its free edge (y = 16) down 20 mm to one of
    two papillary nodes (held), each chain's nodes its own."""
    lines = ["*Heading", " sheet and chordae", "*Node"]
    node = lambda i, j: 1 + i + j * (nx + 1)  # noqa: E731 - the grid's numbering, read once here
    lines += [f"{node(i, j)}, {20.0 * i / nx!r}, {16.0 * j / ny!r}, 0." for j in range(ny + 1) for i in range(nx + 1)]
    papillary = [(nx + 1) * (ny + 1) + 1, (nx + 1) * (ny + 1) + 2]
    lines += [f"{papillary[0]}, 5., 12., -20.", f"{papillary[1]}, 15., 12., -20."]
    label = papillary[1]
    chains = []
    for c in range(chords):
        i = round(c * nx / max(chords - 1, 1))
        start, tip = node(i, ny), papillary[0] if i < nx / 2 else papillary[1]
        x0, x1 = (20.0 * i / nx, 16.0, 0.0), (5.0 if i < nx / 2 else 15.0, 12.0, -20.0)
        chain = [start]
        for k in range(1, segments):
            label += 1
            share = k / segments
            lines.append(f"{label}, " + ", ".join(repr(a + share * (b - a)) for a, b in zip(x0, x1)))
            chain.append(label)
        chains.append(chain + [tip])
    lines.append("*Element, type=S4R, elset=Sheet")
    lines += [f"{1 + i + j * nx}, {node(i, j)}, {node(i + 1, j)}, {node(i + 1, j + 1)}, {node(i, j + 1)}"
              for j in range(ny) for i in range(nx)]
    lines.append("*Element, type=T3D2, elset=Chordae")
    element = nx * ny
    for chain in chains:
        for a, b in zip(chain, chain[1:]):
            element += 1
            lines.append(f"{element}, {a}, {b}")
    lines += ["*Nset, nset=Annulus, generate", f"1, {nx + 1}, 1", "*Nset, nset=Papillary",
              f"{papillary[0]}, {papillary[1]}",
              "*Shell Section, elset=Sheet, material=Leaflet", "0.4",
              "*Solid Section, elset=Chordae, material=Chord", "0.2",
              "*Material, name=Leaflet", "*Density", "1.1e-9", "*Hyperelastic, neo hooke", "0.05, 0.",
              "*Material, name=Chord", "*Density", "1.1e-9", "*Elastic", "40., 0.3",
              "*Boundary", "Annulus, ENCASTRE", "Papillary, PINNED",
              "*Step, nlgeom=YES", "*Dynamic, Explicit", ", 0.1", "*Dload", "Sheet, P, 0.01", "*End Step"]
    return "\n".join(lines) + "\n"


def main() -> None:
    from shellsim.foreign import read_foreign
    from shellsim.imported_deck import import_model

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--shells", nargs=2, type=int, default=[100, 80], metavar=("NX", "NY"))
    parser.add_argument("--chords", nargs=2, type=int, default=[100, 40], metavar=("CHORDS", "SEGMENTS"))
    parser.add_argument("--repeats", type=int, default=3)
    options = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    source = folder / "valve_sized.inp"
    source.write_text(valve_sized_inp(*options.shells, *options.chords))
    reads, imports = [], []
    for repeat in range(options.repeats):
        start = time.perf_counter()
        model = read_foreign(source)
        reads.append(time.perf_counter() - start)
        start = time.perf_counter()
        done = import_model(source, folder / f"import_{repeat}")
        imports.append(time.perf_counter() - start)
    print(f"| shells (file) | quad9 | cables | nodes | read [s] | import [s] | deck problems |\n|---|---|---|---|---|---|---|\n"
          f"| {options.shells[0] * options.shells[1]:,} | {len(model.mesh.conn):,} | {len(model.mesh.lines):,} | "
          f"{len(model.mesh.x):,} | {statistics.median(reads):.2f} | {statistics.median(imports):.2f} | "
          f"{len(done.problems)} |")
    print(f"(medians of {options.repeats}; {source.stat().st_size / 1e6:.1f} MB of input)")


if __name__ == "__main__":
    main()
