"""Scordelis-Lo roof solved statically by an outside code and by shellsim, side by side in
one session: Kratos' thin corotational 4-node shell and shellsim's 9-node element on a
ladder of quarter meshes each, alternating between the codes round by round. Prints, per
code and mesh, the nodes and unknowns, the deflection at the free edge's mid-span against
the deck's reference (decks/verification/test05_scordelis_lo_16x16_static.toml: -3.024e-4
at its 1/1000 load) and the wall time of the solve (medians; imports, meshing and model
building excluded for both; Kratos' includes setting up its system, shellsim's its
Newton iterations, and both with and without its stability check). Nothing is asserted.

The outside code is not a dependency; install it into an environment of its own and name
its interpreter:

    python3 -m venv /tmp/kratos && /tmp/kratos/bin/pip install KratosMultiphysics==10.4.4 \\
        KratosStructuralMechanicsApplication==10.4.4 KratosLinearSolversApplication==10.4.4
    .venv/bin/python benchmarks/peer_scordelis.py --kratos /tmp/kratos/bin/python [--ours 8 16] [--theirs 16 32]

The same quarter roof in Kratos: an m x m grid of ``ShellThinElementCorotational3D4N``
(the thick corotational element of these wheels aborts with a corrupted heap here, in
its initialisation), E = 4.32e8, nu = 0, t = 0.25, the weight as a volume acceleration
on the density; the diaphragm holds x, z and the rotation about y, the symmetry lines
their normal translation and the two rotations that would open them. One linear solve
(``ResidualBasedLinearStrategy``) with Eigen's sparse LU (``--solver``; ``amgcl`` and
``skyline_lu_factorization`` are the others it offers).
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

#: One Kratos solve of an m x m quarter roof, in the outside interpreter; prints a JSON line.
KRATOS = """
import json, sys, time
import numpy as np
import KratosMultiphysics as KM
import KratosMultiphysics.StructuralMechanicsApplication as SMA
import KratosMultiphysics.LinearSolversApplication
from KratosMultiphysics.python_linear_solver_factory import ConstructSolver
m, solver_type = int(sys.argv[1]), sys.argv[2]
R, L, opening, t, E, weight = 25.0, 25.0, np.radians(40.0), 0.25, 4.32e8, 0.09
model = KM.Model(); part = model.CreateModelPart("roof")
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
        part.CreateNewElement("ShellThinElementCorotational3D4N", i + m * j + 1,
                              [ids[i, j], ids[i + 1, j], ids[i + 1, j + 1], ids[i, j + 1]], properties)
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
print(json.dumps({"seconds": seconds, "deflection": part.Nodes[ids[m, 0]].GetSolutionStepValue(KM.DISPLACEMENT_Z),
                  "nodes": part.NumberOfNodes(), "unknowns": sum(not node.IsFixed(getattr(KM, kind + axis)) for node in part.Nodes
                                  for kind in ("DISPLACEMENT_", "ROTATION_") for axis in "XYZ")}))
"""


def kratos_solve(python: str, m: int, solver: str) -> dict:
    """One Kratos solve of the m x m roof in a fresh process of ``python``."""
    done = subprocess.run([python, "-c", KRATOS, str(m), solver], capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"Kratos ({python}) failed on the {m} x {m} roof:\n{done.stderr[-2000:]}")
    return json.loads([line for line in done.stdout.splitlines() if line.startswith("{")][-1])


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kratos", default=sys.executable, help="the Python that imports Kratos")
    parser.add_argument("--solver", default="sparse_lu", help="Kratos' linear solver")
    parser.add_argument("--ours", type=int, nargs="+", default=[8, 16])
    parser.add_argument("--theirs", type=int, nargs="+", default=[16, 32])
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    shellsim_solve(args.ours[0], True)  # compiles or loads the kernels, outside the timing
    runs: dict[tuple[str, int], list[dict]] = {}
    for _ in range(args.rounds):
        for m in args.theirs:
            runs.setdefault((f"Kratos ShellThinElementCorotational3D4N, {args.solver}", m), []).append(
                kratos_solve(args.kratos, m, args.solver))
        for m in args.ours:
            for check in (True, False):
                runs.setdefault((f"shellsim 9-node, stability check {'on' if check else 'off'}", m), []).append(
                    shellsim_solve(m, check))
    print("| code | mesh | nodes | unknowns | deflection | against the reference | wall time (median, min) |")
    print("|---|---|---|---|---|---|---|")
    for (code, m), rows in runs.items():
        seconds = [row["seconds"] for row in rows]
        deflection = rows[0]["deflection"]
        print(f"| {code} | {m} x {m} | {rows[0]['nodes']:,} | {rows[0]['unknowns']:,} | {deflection:.5e} | "
              f"{100 * (deflection / REFERENCE - 1):+.2f}% | {1e3 * statistics.median(seconds):.0f} ms, "
              f"{1e3 * min(seconds):.0f} ms |")


if __name__ == "__main__":
    main()
