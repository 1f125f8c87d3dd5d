"""Wall time of bringing a valve engineer's Abaqus model over: the synthetic tricuspid valve
of :mod:`shellsim.verify.synthetic_valve` (8,100 S4R shells in three leaflets of one user
law, 4,095 T3D2 chordae in three Ogden groups, per-node annulus motion, contact, ...; its
size set by the options), imported with the user law mapped onto Lee-Sacks. Times reading
the file (``read_foreign``) and the whole ``shellsim import`` (mesh file, id map and deck
written, the deck checked against the mesh read back). Prints a Markdown table; nothing is
asserted.

    .venv/bin/python benchmarks/import_size.py [--circumferential 90 --belly 24 --band 6 --segments 15] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path


def main() -> None:
    from shellsim.foreign import read_foreign
    from shellsim.foreign.user_law import UserLaw
    from shellsim.imported_deck import import_model
    from shellsim.verify.synthetic_valve import SyntheticValve, abaqus_text

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    defaults = SyntheticValve()
    for key in ("circumferential", "belly", "band", "segments"):
        parser.add_argument(f"--{key}", type=int, default=getattr(defaults, key))
    parser.add_argument("--repeats", type=int, default=3)
    options = parser.parse_args()
    valve = SyntheticValve(options.circumferential, options.belly, options.band, options.segments)
    law = UserLaw.parse("lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1")
    folder = Path(tempfile.mkdtemp())
    source = folder / "valve.inp"
    source.write_text(abaqus_text(valve))
    reads, imports = [], []
    for repeat in range(options.repeats):
        start = time.perf_counter()
        model = read_foreign(source, law)
        reads.append(time.perf_counter() - start)
        start = time.perf_counter()
        done = import_model(source, folder / f"import_{repeat}", law)
        imports.append(time.perf_counter() - start)
    lines = sum(1 for _ in source.open())
    print("| shells (file) | quad9 | cables | nodes | materials | read [s] | import [s] | deck problems | listed |\n"
          "|---|---|---|---|---|---|---|---|---|\n"
          f"| {len(valve.shells):,} | {len(model.mesh.conn):,} | {len(model.mesh.lines):,} | {len(model.mesh.x):,} | "
          f"{len(model.tables['material'])} | {statistics.median(reads):.2f} | {statistics.median(imports):.2f} | "
          f"{len(done.problems)} | {len(done.unmapped)} |")
    print(f"(medians of {options.repeats}; {lines:,} lines, {source.stat().st_size / 1e6:.1f} MB of input)")
    for line in done.unmapped:
        print(f"- {line}")


if __name__ == "__main__":
    main()
