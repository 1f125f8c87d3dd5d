"""What of an explicit step runs outside the element loop, and whether it shares out over
the threads: a scene's full step, and, each repeated inside compiled code (a call from
Python alone unboxes the model, about 0.04 us per element on the bench plate), the loads
(their forces and rotational parts), the nodal gather of the element forces, the
velocities' update, the motion and a half of the works; the element responses are the rest.
Best of several, on the threads asked: run it at 1 and 2 threads, and a part that does
not halve runs on one thread and caps the speed-up on many cores (Amdahl). The bench
plate (its pressure a dead load: nodal forces) or the artery tube (a follower pressure on
every face). Prints one line; nothing is asserted.

    .venv/bin/python benchmarks/serial_share.py [--scene plate] [--elements 10000] [--threads 1]
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

from scaling import divisions

ROOT = Path(__file__).resolve().parents[1]
DECKS = {"plate": "decks/bench/plate_step.toml", "tube": "decks/artery_inflation.toml"}
#: Calls of a part inside one compiled loop.
REPEATS = 20


def main() -> None:
    import numba
    from numba import njit

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=sorted(DECKS), default="plate")
    parser.add_argument("--elements", type=int, default=10_000, help="about this many elements")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    from shellsim.deck import deck_from_data
    from shellsim.element.assembly import _gather_at_nodes
    from shellsim.execute import built_run
    from shellsim.solver.explicit import applied_forces, half_works, move, update_velocities
    from shellsim.solver.outlook import quickest
    from shellsim.threads import ThreadChooser

    @njit
    def loads(n, t, model, fields, space):
        for _ in range(n):
            applied_forces(t, model, fields, space)

    @njit
    def gather(n, body, parts, shape, f, fr):
        for _ in range(n):
            _gather_at_nodes(body, parts, shape, f, fr)

    @njit
    def velocities(n, fields, projector, rot_free, dt, sums):
        for _ in range(n):
            update_velocities(fields, projector, rot_free, 0.0, dt, sums)

    @njit
    def motion(n, fields, space):
        for _ in range(n):
            move(fields, space, 0.0, 0.0)

    @njit
    def works(n, fields, space, dt):
        for _ in range(n):
            half_works(fields, space, dt)

    data = tomllib.loads((ROOT / DECKS[args.scene]).read_text())
    data["mesh"]["divisions"] = divisions(args.scene, args.elements)
    sim = built_run(deck_from_data(data), ROOT).sim
    sim.threads = ThreadChooser(args.threads, choose=False)  # the count asked, never the other
    dt = sim.critical_time_step() / 1.25
    sim.advance(5 * dt, dt, 5)
    steps = 50
    step = quickest(lambda: sim.advance(sim.state.t + steps * dt, dt, steps), 5) / steps
    model, fields, space = sim.model, sim.state.fields, sim.workspace
    t, constraints = sim.state.t, model.constraints
    f, fr = fields.f_int.copy(), fields.fr_int.copy()
    # each part on the state the steps left (the velocities' update and the motion change it:
    # nothing is stepped after them)
    calls = {"the loads": lambda n: loads(n, t, model, fields, space),
             "the nodal gather": lambda n: gather(n, model.body, space.parts, fields.shape, f, fr),
             "a half of the works": lambda n: works(n, fields, space, dt),
             "the velocities": lambda n: velocities(n, fields, constraints.projector, constraints.rot_free, dt, space.sums),
             "the motion": lambda n: motion(n, fields, space)}
    parts = {}
    for name, call in calls.items():
        call(1)  # compiled
        parts[name] = quickest(lambda call=call: call(REPEATS), 5) / REPEATS
    per = 1e6 / model.n_elements
    outside = sum(parts.values()) + parts["a half of the works"]  # two halves a step
    print(f"{args.scene}, {model.n_elements:,} elements, {args.threads} thread(s), us per element: a step "
          f"{per * step:.3f}; " + ", ".join(f"{name} {per * seconds:.4f}" for name, seconds in parts.items())
          + f"; the element responses the rest, {per * (step - outside):.3f} ({100 * (1 - outside / step):.1f}% of a step)")


if __name__ == "__main__":
    main()
