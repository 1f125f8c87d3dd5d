"""The critical step as an explicit deck's loads act, foreseen before the run: the deck's
loads followed quasi-statically (a static solve of the same scene, loosely converged) and
the structure's critical step estimated at each converged state.

An explicit run's step follows its structure: tissue stiffens as it stretches (the Lee-Sacks
flap's step fell 8.7 times at 20 mmHg), a sheet thins, contact adds its springs. The step at
rest alone forecast 2,655 steps where the flap took 11,023. A static solve finds the loaded
states in a few dozen Newton steps where the run takes thousands; the dynamics' own
overshoot is left out. The rehearsal stops at REHEARSAL_SECONDS, or where the static solve
cannot go on (a slack chord, spreading contact, a load past the structure's limit): the
steps beyond hold the last critical step found.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..deck import Deck
from ..errors import ShellsimError
from ..loads import stable_step
from ..mesh import Mesh
from ..model import Model
from .equilibrium import warmed

#: Wall time [s] a rehearsal may take; the static solve's loosened force tolerance (a
#: share of the force scale: the critical step needs the loaded shape, not equilibrium to
#: round-off); and the landings it solves at, evenly over the end time.
REHEARSAL_SECONDS, REHEARSAL_TOLERANCE, REHEARSAL_LANDINGS = 10.0, 1e-3, 8
#: Scenes above this many elements are not rehearsed: a static tangent's memory and a
#: budget's worth of Newton steps would tell little there.
REHEARSAL_ELEMENTS = 2000


class _Spent(Exception):
    """The rehearsal's wall time is used up."""


def critical_steps_under_load(deck: Deck, mesh: Mesh, model: Model,
                              seconds: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(times (k,), critical (k,)): the structure's critical step [time] (the contacts'
    and the cables' share included, :func:`shellsim.loads.stable_step`) at the start and
    at each state a static solve of the deck's loads converged on within ``seconds``
    (REHEARSAL_SECONDS by default), in time order. Nothing the static solve meets stops
    the forecast: it ends the rehearsal."""
    from .run import Listener, prepare
    from .static_solve import solve_static

    end = deck.solver.end_time
    solver = deck.solver.model_copy(update={"method": "static", "static": deck.solver.static.model_copy(update={
        "increments": REHEARSAL_LANDINGS, "force_tolerance": REHEARSAL_TOLERANCE, "check_stability": False,
        "control": "load"})})
    output = deck.output.model_copy(update={"interval": None, "times": list(np.linspace(0.0, end, REHEARSAL_LANDINGS + 1)[1:])})
    rehearsal = deck.model_copy(update={"solver": solver, "output": output})
    times, critical = [], []
    stop = math.inf

    class Estimates(Listener):
        def on_sample(self, run) -> None:
            sim = run.sim
            sim.update_masses()
            times.append(sim.state.t)
            critical.append(stable_step(run.model, sim.state.fields.shape, sim.critical_time_step(), sim.mass_factor))
            if time.perf_counter() > stop:
                raise _Spent

    try:
        warmed(model)  # the budget is the solve's, not the kernels' loading
        stop = time.perf_counter() + (REHEARSAL_SECONDS if seconds is None else seconds)
        solve_static(prepare(rehearsal, mesh, model), Estimates())
    except (_Spent, ShellsimError, ArithmeticError, RuntimeError, ValueError, np.linalg.LinAlgError):
        pass  # the states found until then
    return np.asarray(times), np.asarray(critical)
