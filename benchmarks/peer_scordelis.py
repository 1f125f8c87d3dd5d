"""Scordelis-Lo roof solved statically by an outside code and by shellsim, side by side in
one session: Kratos' 4-node shells (its thick corotational Q4 by default) and shellsim's
9-node element on a ladder of quarter meshes each, alternating between the codes round by
round, each warm (Kratos in one process of its own that solves every mesh in turn, its
first solve untimed; shellsim in this one, its kernels loaded first) and on the same
number of threads (``--threads``, 1 by default: serial against serial). Prints, per code
and mesh, the nodes and unknowns, the deflection at the free edge's mid-span against the
deck's reference (decks/verification/test05_scordelis_lo_16x16_static.toml: -3.024e-4 at
its 1/1000 load) and the wall time of the solve (medians; imports, meshing and model
building excluded for both; Kratos' includes setting up its system, shellsim's its Newton
iterations, with and without its stability check); then each code's cheapest mesh within
``--within`` (1%) of the reference and the ratio of their times, and the ratio at equal
element counts. Nothing is asserted.

The outside code is not a dependency; install it into an environment of its own and name
its interpreter:

    python3 -m venv /tmp/kratos && /tmp/kratos/bin/pip install KratosMultiphysics==10.3.0 \\
        KratosStructuralMechanicsApplication==10.3.0 KratosLinearSolversApplication==10.3.0
    .venv/bin/python benchmarks/peer_scordelis.py --kratos /tmp/kratos/bin/python [--ours 2 4 8 16] [--theirs 4 8 16 32]

(10.3.0: the thick Q4 of 10.4.4's wheels stops with a segmentation fault in its check,
on Kratos' own shell patch test too.)

The same quarter roof in Kratos: an m x m grid of ``--element`` (``ShellThickElementCorotational3D4N``,
or its thin ``ShellThinElementCorotational3D4N``), E = 4.32e8, nu = 0, t = 0.25, the weight
as a volume acceleration on the density; the diaphragm holds x, z and the rotation about
y, the symmetry lines their normal translation and the two rotations that would open them.
One linear solve (``ResidualBasedLinearStrategy``) with Eigen's sparse LU (``--solver``;
``amgcl`` and ``skyline_lu_factorization`` are the others it offers).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
import tomllib
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "decks" / "verification" / "test05_scordelis_lo_16x16_static.toml"
#: The deck's reference deflection at the free edge's mid-span (its 1/1000 load).
REFERENCE = -3.024e-4

#: Kratos solving quarter roofs in one process: reads "m element solver" lines, prints a
#: JSON line for each.
KRATOS = """
import json, sys, time
import numpy as np
import KratosMultiphysics as KM
import KratosMultiphysics.StructuralMechanicsApplication as SMA
import KratosMultiphysics.LinearSolversApplication
from KratosMultiphysics.python_linear_solver_factory import ConstructSolver
KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
KM.ParallelUtilities.SetNumThreads(int(sys.argv[1]))


def solve(m, element, solver_type):
    R, L, opening, t, E, weight = 25.0, 25.0, np.radians(40.0), 0.25, 4.32e8, 0.09
    model = KM.Model(); part = model.CreateModelPart("roof")
    part.SetBufferSize(2)  # as Kratos' own shell tests set it
    for variable in (KM.DISPLACEMENT, KM.REACTION, KM.ROTATION, KM.REACTION_MOMENT, KM.VOLUME_ACCELERATION):
        part.AddNodalSolutionStepVariable(variable)
    ids = {}
    for j in range(m + 1):
        for i in range(m + 1):
            ids[i, j] = len(ids) + 1
            phi = opening * i / m
            part.CreateNewNode(ids[i, j], R * np.sin(phi), L * j / m, R * np.cos(phi))
    properties = part.GetProperties()[1]
    for variable, value in ((KM.YOUNG_MODULUS, E), (KM.POISSON_RATIO, 0.0), (KM.THICKNESS, t), (KM.DENSITY, 1.0)):
        properties.SetValue(variable, value)
    properties.SetValue(KM.CONSTITUTIVE_LAW, SMA.LinearElasticPlaneStress2DLaw())
    for j in range(m):
        for i in range(m):
            part.CreateNewElement(element, i + m * j + 1, [ids[i, j], ids[i + 1, j], ids[i + 1, j + 1], ids[i, j + 1]],
                                  properties)
    for node in part.Nodes:
        node.SetSolutionStepValue(KM.VOLUME_ACCELERATION, [0.0, 0.0, -weight / t])
    for axis in "XYZ":
        KM.VariableUtils().AddDof(getattr(KM, "DISPLACEMENT_" + axis), getattr(KM, "REACTION_" + axis), part)
        KM.VariableUtils().AddDof(getattr(KM, "ROTATION_" + axis), getattr(KM, "REACTION_MOMENT_" + axis), part)
    fixed = {"diaphragm": ("DISPLACEMENT_X", "DISPLACEMENT_Z", "ROTATION_Y"),
             "crown": ("DISPLACEMENT_X", "ROTATION_Y", "ROTATION_Z"),
             "mid-span": ("DISPLACEMENT_Y", "ROTATION_X", "ROTATION_Z")}
    for (i, j), node_id in ids.items():
        for line, held in (("diaphragm", j == m), ("crown", i == 0), ("mid-span", j == 0)):
            for variable in fixed[line] if held else ():
                part.Nodes[node_id].Fix(getattr(KM, variable))
    part.ProcessInfo[KM.DOMAIN_SIZE] = 3
    part.CloneTimeStep(1.0)
    start = time.perf_counter()
    solver = ConstructSolver(KM.Parameters(json.dumps({"solver_type": solver_type})))
    strategy = KM.ResidualBasedLinearStrategy(part, KM.ResidualBasedIncrementalUpdateStaticScheme(),
                                              KM.ResidualBasedBlockBuilderAndSolver(solver), False, False, False, False)
    strategy.Initialize()
    strategy.Solve()
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "deflection": part.Nodes[ids[m, 0]].GetSolutionStepValue(KM.DISPLACEMENT_Z),
            "nodes": part.NumberOfNodes(), "unknowns": sum(not node.IsFixed(getattr(KM, kind + axis))
                                                           for node in part.Nodes
                                                           for kind in ("DISPLACEMENT_", "ROTATION_") for axis in "XYZ")}


for line in sys.stdin:
    m, element, solver_type = line.split()
    print(json.dumps(solve(int(m), element, solver_type)), flush=True)
"""


class Kratos:
    """Kratos in a process of its own on ``threads`` threads, solving roofs as asked."""

    def __init__(self, python: str, threads: int, element: str, solver: str):
        import os

        env = os.environ | {"OMP_NUM_THREADS": str(threads)}
        self.process = subprocess.Popen([python, "-c", KRATOS, str(threads)], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, env=env)
        self.element, self.solver = element, solver

    def solve(self, m: int) -> dict:
        """One solve of the m x m roof."""
        self.process.stdin.write(f"{m} {self.element} {self.solver}\n")
        self.process.stdin.flush()
        while not (line := self.process.stdout.readline()).startswith("{"):  # past its banner and log lines
            if not line:
                raise SystemExit(f"Kratos stopped on the {m} x {m} roof of {self.element} (exit {self.process.wait()})")
        return json.loads(line)

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait()


def shellsim_solve(m: int, check_stability: bool) -> dict:
    """One shellsim solve of the deck at m x m (kernels compiled by an earlier call)."""
    from shellsim.deck import deck_from_data
    from shellsim.execute import built_run, solve
    from shellsim.solver.unknowns import unknowns

    data = tomllib.loads(DECK.read_text())
    data["mesh"]["divisions"] = {"around": m, "along": m}
    data["solver"].setdefault("static", {})["check_stability"] = check_stability
    run = built_run(deck_from_data(data), DECK.parent)
    start = time.perf_counter()
    solve(run)
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "deflection": float(run.history["free_edge_deflection"][-1]),  # the deck's own probe
            "nodes": run.model.n_nodes, "unknowns": unknowns(run.model).n_free}


def cheapest_within(runs: dict, code: str, within: float) -> tuple[int, float] | None:
    """(m, median seconds) of ``code``'s fastest mesh whose deflection is within ``within``
    (a share) of the reference; None where none is."""
    near = [(statistics.median(row["seconds"] for row in rows), m) for (name, m), rows in runs.items()
            if name == code and abs(rows[0]["deflection"] / REFERENCE - 1) <= within]
    return (min(near)[1], min(near)[0]) if near else None


def main() -> None:
    import numba

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kratos", default=sys.executable, help="the Python that imports Kratos")
    parser.add_argument("--element", default="ShellThickElementCorotational3D4N", help="Kratos' shell element")
    parser.add_argument("--solver", default="sparse_lu", help="Kratos' linear solver")
    parser.add_argument("--ours", type=int, nargs="+", default=[2, 4, 8, 16])
    parser.add_argument("--theirs", type=int, nargs="+", default=[4, 8, 16, 32])
    parser.add_argument("--threads", type=int, default=1, help="threads for each code")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--within", type=float, default=0.01, help="the accuracy each code's cheapest mesh reaches")
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    kratos = Kratos(args.kratos, args.threads, args.element, args.solver)
    kratos.solve(args.theirs[0])  # its first solve, untimed: what a warm Kratos has done
    shellsim_solve(args.ours[0], True)  # the kernels compiled or loaded, outside the timing
    theirs = f"Kratos {args.element}, {args.solver}"
    ours = {check: f"shellsim 9-node, stability check {'on' if check else 'off'}" for check in (True, False)}
    runs: dict[tuple[str, int], list[dict]] = {}
    for _ in range(args.rounds):
        for m in args.theirs:
            runs.setdefault((theirs, m), []).append(kratos.solve(m))
        for m in args.ours:
            for check in (True, False):
                runs.setdefault((ours[check], m), []).append(shellsim_solve(m, check))
    kratos.close()
    print(f"{args.threads} thread(s) each, {args.rounds} rounds\n")
    print("| code | mesh | nodes | unknowns | deflection | against the reference | wall time (median, min) |")
    print("|---|---|---|---|---|---|---|")
    for (code, m), rows in runs.items():
        seconds = [row["seconds"] for row in rows]
        deflection = rows[0]["deflection"]
        print(f"| {code} | {m} x {m} | {rows[0]['nodes']:,} | {rows[0]['unknowns']:,} | {deflection:.5e} | "
              f"{100 * (deflection / REFERENCE - 1):+.2f}% | {1e3 * statistics.median(seconds):.1f} ms, "
              f"{1e3 * min(seconds):.1f} ms |")
    best_theirs = cheapest_within(runs, theirs, args.within)
    print(f"\nEach code's cheapest mesh within {100 * args.within:g}% of the reference:")
    for code in ours.values():
        best = cheapest_within(runs, code, args.within)
        if best and best_theirs:
            print(f"- {code}: {best[0]} x {best[0]}, {1e3 * best[1]:.1f} ms; Kratos {best_theirs[0]} x "
                  f"{best_theirs[0]}, {1e3 * best_theirs[1]:.1f} ms: ours {best[1] / best_theirs[1]:.2f} x theirs")
    print("\nAt equal element counts, ours over theirs (medians):")
    for m in sorted(set(args.ours) & set(args.theirs)):
        kratos_s = statistics.median(row["seconds"] for row in runs[theirs, m])
        print(f"- {m} x {m}: " + ", ".join(
            f"check {'on' if check else 'off'} {statistics.median(r['seconds'] for r in runs[code, m]) / kratos_s:.2f}"
            for check, code in ours.items()))


if __name__ == "__main__":
    main()
