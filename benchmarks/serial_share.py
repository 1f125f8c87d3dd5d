"""What of an explicit step runs outside the parallel element loop, and what of it still
runs on one thread: the bench plate's full step against its force evaluation (the element
loop with the loads), and of those the loads alone (their faces' loop runs on one thread),
the nodal gather of the element forces and the node loops (velocities, the works' halves),
best of several, on the threads asked. Run it at 1 and 2 threads: a part that does not
halve is serial and caps the speed-up on many cores (Amdahl). Prints one line; nothing is
asserted.

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
    from shellsim.solver.explicit import applied_forces, half_works, update_velocities
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
    fields, space, model = sim.state.fields, sim.workspace, sim.model
    loads = quickest(lambda: applied_forces(sim.state.t, model, fields, space), 20)
    nodal, rotational = fields.f_int.copy(), fields.fr_int.copy()
    gather = quickest(lambda: _gather_at_nodes(model.body, space.parts, fields.shape, nodal, rotational), 20)
    v, w = fields.v.copy(), fields.w.copy()  # the velocities' update below moves them: put back after
    velocities = quickest(lambda: update_velocities(fields, model.constraints.projector, model.constraints.rot_free,
                                                    0.0, dt, space.sums), 20)
    fields.v[:], fields.w[:] = v, w
    works = quickest(lambda: half_works(fields, space, dt), 20)
    per = 1e6 / model.n_elements
    print(f"{model.n_elements:,} elements, {args.threads} thread(s), us per element: a step {per * step:.3f}, "
          f"its forces {per * forces:.3f} (the loads {per * loads:.3f}, the nodal gather {per * gather:.3f}), "
          f"the velocities {per * velocities:.3f}, a half of the works {per * works:.3f}; outside the forces "
          f"{100 * (step - forces) / step:.1f}% of a step, the loads {100 * loads / step:.1f}%")

if __name__ == "__main__":
    main()
