"""What of an explicit step runs outside the parallel element loop: the bench plate's full
step against its force evaluation (the element loop with the loads) and the serial nodal
gather of the element forces, best of several, on the threads asked. The rest of a step
(velocities, moves, the works) loops over the nodes on one thread, and caps the speed-up
on many cores (Amdahl). Prints one line; nothing is asserted.

    .venv/bin/python benchmarks/serial_share.py [--divisions 100] [--threads 1]
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    import numba

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", type=int, default=100, help="elements along each side of the plate")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    from shellsim.deck import deck_from_data
    from shellsim.element.assembly import _gather_at_nodes
    from shellsim.execute import built_run
    from shellsim.solver.outlook import quickest
    from shellsim.threads import ThreadChooser

    data = tomllib.loads((ROOT / "decks" / "bench" / "plate_step.toml").read_text())
    data["mesh"]["divisions"] = {"length": args.divisions, "width": args.divisions}
    sim = built_run(deck_from_data(data), ROOT).sim
    sim.threads = ThreadChooser(args.threads, choose=False)  # the count asked, never the other
    dt = sim.critical_time_step() / 1.25
    sim.advance(5 * dt, dt, 5)
    steps = 50
    step = quickest(lambda: sim.advance(sim.state.t + steps * dt, dt, steps), 5) / steps
    forces = quickest(lambda: sim.compute_forces(sim.state.t), 20)
    nodal = sim.state.fields.f_int.copy()
    gather = quickest(lambda: _gather_at_nodes(sim.model.body, sim.workspace.parts, nodal), 20)
    per = 1e6 / sim.model.n_elements
    print(f"{sim.model.n_elements:,} elements, {args.threads} thread(s): a step {per * step:.2f} us per element, "
          f"its forces {per * forces:.2f}, the nodal gather {per * gather:.3f}; outside the forces "
          f"{100 * (step - forces) / step:.1f}% of a step, the gather {100 * gather / step:.1f}%")


if __name__ == "__main__":
    main()
