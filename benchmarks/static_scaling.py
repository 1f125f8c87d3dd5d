"""The static solver's cost against the number of unknowns: the pinched hemisphere
(decks/verification/pinched_hemisphere_static.toml) from a few thousand to about 10^5
unknowns.

For each mesh, in a fresh process (its peak memory its own): the tangent at the loaded
state by forward differences (what the solver forms) and by central ones (their check, and
what it formed before), its LU factors on the diagonal (the solver's,
:mod:`shellsim.solver.sparse_lu`) and by SuperLU's default (COLAMD, pivoting freely; the
solver's before; in a process of its own, so that the peak memory shown is the solver's),
the entries in the factors, and one solve. Medians of ``--repeat`` runs. With
``--runs``, whole runs of the deck with its forces times ``--scale`` (10^5 by default: a
radial displacement of about 3.4 at A, 85 thicknesses) for the wall time and peak memory
per mesh, stability checks and all.
Prints Markdown tables; nothing is asserted.

    .venv/bin/python benchmarks/static_scaling.py [--patches 8 16 23 32 50] [--runs 6 11 23] [--scale 1e5] [--no-colamd]
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "decks" / "verification" / "pinched_hemisphere_static.toml"
#: The deck's forces scaled up for the nonlinear runs (``--scale``'s default).
NONLINEAR = 1e5

#: One mesh's operations, in a child process; prints a JSON row.
CHILD = """
import json, resource, statistics, sys, time, tomllib
import numpy as np, scipy.sparse.linalg as spla
from shellsim.deck import deck_from_data
from shellsim.execute import built_run
from shellsim.solver.equilibrium import Equilibrium
from shellsim.solver.sparse_lu import SymmetricPatternLU
from shellsim.solver.tangent_pattern import free_columns
deck_path, patch, repeat, part = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
data = tomllib.loads(open(deck_path).read())
data["mesh"]["divisions"]["patch"] = patch
run = built_run(deck_from_data(data), ROOT)
eq = Equilibrium(run.sim)
eq.evaluate(1.0)
n = eq.unknowns.n_free
def median_seconds(work):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result
eq.tangent()  # the first call loads the kernel
forward, k = median_seconds(eq.tangent)
k = free_columns(k, n)  # as the solver takes it
if part == "colamd":  # SuperLU's default ordering alone, so that its factors stay out of the solver's peak
    colamd, general = median_seconds(lambda: spla.splu(k, permc_spec="COLAMD"))
    print(json.dumps({"colamd_s": colamd, "colamd_fill": general.L.nnz + general.U.nnz}))
    sys.exit()
central, _ = median_seconds(lambda: eq.tangent(central=True))
factor, lu = median_seconds(lambda: SymmetricPatternLU(k))
rhs = eq.residual()[:n]
solve, _ = median_seconds(lambda: lu.solve(rhs))
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"elements": run.model.n_elements, "unknowns": n, "entries": k.nnz, "forward_s": forward,
                  "central_s": central, "factor_s": factor, "fill": lu.entries, "pivoted": lu.pivoted,
                  "solve_s": solve, "peak_bytes": peak}))
"""


#: Runs the command in its arguments and prints its peak memory [bytes] as the last line.
PEAK_OF = """
import resource, subprocess, sys
done = subprocess.run(sys.argv[1:])
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024)
sys.exit(done.returncode)
"""


def operations(patches: list[int], repeat: int, colamd: bool) -> None:
    print("| elements | unknowns | tangent entries | forward tangent [s] | central tangent [s] | LU on the diagonal [s] "
          "| its factors [M] | COLAMD LU [s] | its factors [M] | solve [s] | peak memory [MB] | per element [kB] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for patch in patches:
        r = {"colamd_s": math.nan, "colamd_fill": math.nan}
        for part in ("solver", "colamd") if colamd else ("solver",):
            done = subprocess.run([sys.executable, "-c", f"ROOT = {str(ROOT)!r}\n" + CHILD, str(DECK), str(patch),
                                   str(repeat), part], capture_output=True, text=True, cwd=ROOT)
            if done.returncode:
                break
            r |= json.loads(done.stdout.strip().splitlines()[-1])
        if done.returncode:
            print(f"| patch {patch} | failed: {done.stderr.strip().splitlines()[-1]} |", flush=True)
            continue
        pivoted = " (pivoted)" if r["pivoted"] else ""
        print(f"| {r['elements']:,} | {r['unknowns']:,} | {r['entries'] / 1e6:.2f} M | {r['forward_s']:.3f} "
              f"| {r['central_s']:.3f} | {r['factor_s']:.3f}{pivoted} | {r['fill'] / 1e6:.1f} | {r['colamd_s']:.3f} "
              f"| {r['colamd_fill'] / 1e6:.1f} | {r['solve_s']:.4f} | {r['peak_bytes'] / 1e6:.0f} "
              f"| {r['peak_bytes'] / r['elements'] / 1e3:.0f} |", flush=True)


def runs(patches: list[int], scale: float) -> None:
    print("| elements | DOFs | load steps | iterations | tangents formed | wall time of the solve [s] | peak memory [MB] "
          "| per element [kB] | u_A |")
    print("|---|---|---|---|---|---|---|---|---|")
    text = DECK.read_text().replace("1.0e-3", repr(1.0e-3 * scale))
    text = text[:text.index("[[reference]]")]  # the deck's reference is for its linear forces
    for patch in patches:
        with tempfile.TemporaryDirectory() as folder:
            deck = Path(folder) / "hemisphere.toml"
            deck.write_text(text.replace("patch = 8 }", f"patch = {patch} }}"))
            # the run in a child of its own, whose peak memory the wrapper reports alone
            done = subprocess.run([sys.executable, "-c", PEAK_OF, sys.executable, "-m", "shellsim", "run", str(deck),
                                   "--out", str(Path(folder) / "out")], capture_output=True, text=True, cwd=ROOT,
                                  env=dict(os.environ, COLUMNS="200"))
            if done.returncode:
                print(f"| patch {patch} | failed: {done.stderr.strip().splitlines()[-1]} |", flush=True)
                continue
            summary = json.loads((Path(folder) / "out" / "summary.json").read_text())
            with open(Path(folder) / "out" / "history.csv") as history:
                u_a = float(list(csv.DictReader(history))[-1]["a_radial"])
        static, peak = summary["static"], float(done.stdout.strip().splitlines()[-1])
        print(f"| {summary['elements']:,} | {5 * summary['nodes']:,} | {static['load_steps']} | {static['iterations']} "
              f"| {static['tangents_formed']} | {summary['wall_time_s']:.1f} | {peak / 1e6:.0f} "
              f"| {peak / summary['elements'] / 1e3:.0f} | {u_a:.4f} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--patches", type=int, nargs="*", default=[8, 16, 23, 32, 50],
                        help="elements per patch edge of the operations table (two patches: 2 p^2 elements)")
    parser.add_argument("--runs", type=int, nargs="*", default=[6, 11, 23],
                        help="patches of the whole nonlinear runs (6, 11, 23: about 8 x 8, 16 x 16, 32 x 32 "
                             "elements on the quarter)")
    parser.add_argument("--scale", type=float, default=NONLINEAR,
                        help="the deck's forces times this in the whole runs (1: its own, nearly linear, forces)")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each operation (the median is shown)")
    parser.add_argument("--no-colamd", action="store_true",
                        help="leave out SuperLU's COLAMD (its time grew as n^2.1 to 19.5 s at 5,000 elements)")
    args = parser.parse_args()
    if args.patches:
        operations(args.patches, args.repeat, not args.no_colamd)
    if args.runs:
        print()
        runs(args.runs, args.scale)


if __name__ == "__main__":
    main()
