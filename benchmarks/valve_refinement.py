"""The shipped aortic valve (``decks/valves/aortic_valve_closing.toml``) closed on its
builder's mesh refined 1x, 2x and 4x, by a path given on the command line:

- ``explicit`` (the default): explicit dynamics with every mass scaled throughout to a
  step of ``--step`` seconds (``[solver.mass_scaling] throughout = true``) and
  mass-proportional damping ``--damping`` [1/s], so that neither the leaflets' stiffening
  nor the finer meshes shorten the step;
- ``implicit``: the deck as shipped (HHT-alpha, steps of 1 ms).

For each mesh: the steps taken, the wall time, the closed valve's measures at the end
(orifice area, coaptation height and area, peak principal stress everywhere and away
from the annulus), the nearest gap between leaflets as a share of the thickness, the
kinetic energy over the internal one (at rest: far below 1) and the energy balance; then
each measure's change from the mesh before. Prints a Markdown table; nothing is asserted.

    .venv/bin/python benchmarks/valve_refinement.py [explicit|implicit] [--refinements 1 2 4]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from shellsim.execute import built_run, solve
from shellsim.loads import ToolForces
from shellsim.solver.explicit import EXTERNAL, INTERNAL, KINETIC
from shellsim.study.jobs import variant_deck

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "decks" / "valves" / "aortic_valve_closing.toml"
#: The deck's divisions at 1x.
DIVISIONS = {"around": 12, "belly": 6, "coaptation": 2}
MEASURES = ("orifice_area", "coaptation_height", "coaptation_area", "peak_principal_stress",
            "peak_principal_stress_away")


def closed(refinement: int, path: str, step: float, damping: float) -> dict[str, float]:
    """The valve on the mesh refined ``refinement`` times, closed by ``path``: its run's
    numbers by name."""
    changes = {"output.render": [], "output.interval": 0.02,
               "mesh.divisions": {key: refinement * value for key, value in DIVISIONS.items()}}
    if path == "explicit":
        changes["solver"] = {"method": "explicit", "end_time": 0.08, "damping": damping,
                             "mass_scaling": {"step": step, "throughout": True}}
    run = built_run(variant_deck(DECK, changes), DECK.parent)
    start = time.perf_counter()
    solve(run)
    wall = time.perf_counter() - start
    state = run.sim.state
    gaps = ToolForces(run.model, []).gaps(state.t, state.fields.shape)
    row = {"elements": run.model.n_elements, "status": run.status, "steps": int(state.steps), "wall_s": wall,
           "mass_factor": float(run.sim.mass_factor),
           "nearest_gap_h": float(np.nanmin(gaps)) / run.deck.section.thickness,
           "kinetic_per_internal": float(state.energy[KINETIC] / state.energy[INTERNAL]),
           "balance": float(run.balance_error / state.energy[EXTERNAL])}
    record = run.measure("valve").record(run, wall)  # what summary.json's "valve" holds
    return row | {name: record[name]["final"] for name in MEASURES}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("path", nargs="?", choices=("explicit", "implicit"), default="explicit")
    parser.add_argument("--refinements", type=int, nargs="+", default=[1, 2, 4])
    parser.add_argument("--step", type=float, default=1e-5, help="explicit: the step the masses are scaled to [s]")
    parser.add_argument("--damping", type=float, default=300.0, help="explicit: mass-proportional damping [1/s]")
    args = parser.parse_args()
    rows = {}
    for refinement in args.refinements:
        rows[refinement] = closed(refinement, args.path, args.step, args.damping)
        print(f"{refinement}x done: {rows[refinement]}", flush=True)
    columns = list(next(iter(rows.values())))
    print("| refinement | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 1) + "|")
    refinements = list(rows)
    for i, refinement in enumerate(refinements):
        row = rows[refinement]
        cells = [f"{value:.4g}" if isinstance(value, float) else str(value) for value in row.values()]
        print(f"| {refinement}x | " + " | ".join(cells) + " |")
        if i:
            before = rows[refinements[i - 1]]
            change = [f"{100 * (row[name] / before[name] - 1):+.2f}%" if name in MEASURES else "" for name in columns]
            print(f"| change from {refinements[i - 1]}x | " + " | ".join(change) + " |")


if __name__ == "__main__":
    main()
