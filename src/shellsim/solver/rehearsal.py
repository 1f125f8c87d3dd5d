"""A run's course foreseen before it starts, by rehearsing it for a few seconds.

An explicit deck's critical step as its loads act: the loads followed quasi-statically
(a static solve of the same scene, loosely converged) and the structure's critical step
estimated at each converged state. An explicit run's step follows its structure: tissue
stiffens as it stretches (the Lee-Sacks flap's step fell 8.7 times at 20 mmHg), a sheet
thins, contact adds its springs. The step at rest alone forecast 2,655 steps where the
flap took 11,023. A static solve finds the loaded states in a few dozen Newton steps where
the run takes thousands; the dynamics' own overshoot is left out. The rehearsal stops at
REHEARSAL_SECONDS, or where the static solve cannot go on (a slack chord, spreading
contact, a load past the structure's limit): the steps beyond hold the last critical step
found.

A static or implicit deck's own solve, timed (:func:`newton_rehearsal`): its iterations
and tangents follow the path (the strip rolled up statically takes 8 tangents a step, the
hinged roofs' arc lengths 3), and its tangents' cost the scene as it deforms.
"""

from __future__ import annotations

import time

import numpy as np

from ..deck import Deck
from ..errors import ShellsimError
from ..loads import shell_contact, stable_step, without
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


#: What stops a rehearsed solve as it would stop the run: the rehearsal ends there.
SOLVE_STOPS = (ShellsimError, ArithmeticError, RuntimeError, ValueError, np.linalg.LinAlgError)


def _within(seconds: float | None, solve, run, on_sample=lambda run: None) -> tuple[bool, float]:
    """``solve(run, listener)`` with the run's kernels loaded first, until it ends or
    ``seconds`` (REHEARSAL_SECONDS by default) are spent, as checked at each sample after
    ``on_sample(run)``: (whether it ended on its own, the wall time [s] it took)."""
    from .run import Listener

    class Budget(Listener):
        def on_sample(self, run) -> None:
            on_sample(run)
            if time.perf_counter() > stop:
                raise _Spent

    start = stop = time.perf_counter()
    try:
        warmed(run.model)  # the budget is the solve's, not the kernels' loading
        start = time.perf_counter()
        stop = start + (REHEARSAL_SECONDS if seconds is None else seconds)
        solve(run, Budget())
    except _Spent:
        return False, time.perf_counter() - start
    except SOLVE_STOPS:
        pass  # a run stops there too
    return True, time.perf_counter() - start


def critical_steps_under_load(deck: Deck, mesh: Mesh, model: Model,
                              seconds: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(times (k,), critical (k,)): the structure's critical step [time] (the contacts'
    and the cables' share included, :func:`shellsim.loads.stable_step`) at the start and
    at each state a static solve of the deck's loads converged on within ``seconds``
    (REHEARSAL_SECONDS by default), in time order. Nothing the static solve meets stops
    the forecast: it ends the rehearsal. Contact between shells is left out of the solve:
    a static path stalls as it spreads (the heartbeat's did not get past its first step
    in 38 s), while the tissue's stiffening, which sets the step, comes from the stretch
    the loads give, and leaflets pressed through each other stretch as much or more
    (without it the heartbeat's loads are followed to t = 0.725 in 25 s, its step falling
    6 times under 80 mmHg). Where such contact carries the load, the solve without it
    finds no equilibrium, and the step at rest holds."""
    from .run import prepare
    from .static_solve import solve_static

    end = deck.solver.end_time
    solver = deck.solver.model_copy(update={"method": "static", "static": deck.solver.static.model_copy(update={
        "increments": REHEARSAL_LANDINGS, "force_tolerance": REHEARSAL_TOLERANCE, "check_stability": False,
        "control": "load"})})
    output = deck.output.model_copy(update={"interval": None, "times": list(np.linspace(0.0, end, REHEARSAL_LANDINGS + 1)[1:])})
    rehearsal = deck.model_copy(update={"solver": solver, "output": output})
    times, critical = [], []

    def estimate(run) -> None:
        sim = run.sim
        sim.update_masses()
        # the step first: where a state it cannot be estimated at ends the rehearsal (an
        # exponential law far out, its forces overflowing), neither list takes that state
        step = stable_step(model, sim.state.fields.shape, sim.critical_time_step(), sim.mass_factor)
        times.append(sim.state.t)
        critical.append(step)

    apart = without(model, shell_contact)  # the contacts' share of the step is still the deck's
    _within(seconds, solve_static, prepare(rehearsal, mesh, apart), estimate)  # the states found until it ends
    return np.asarray(times), np.asarray(critical)


def newton_rehearsal(deck: Deck, mesh: Mesh, model: Model, seconds: float | None = None) -> dict:
    """The deck's own static or implicit solve, run for at most ``seconds``
    (REHEARSAL_SECONDS by default) and timed: ``steps`` converged, the clock ``t`` they
    reached, the ``seconds`` they took (the solve's alone, its kernels loaded first),
    their ``iterations``, the ``tangents`` formed (stability checks' and cut-back tries'
    too), ``tangent_seconds`` a tangent formed and factorised took on average (None: none
    was), and whether the solve ``finished`` (it reached the end, or stopped on its own: a
    run would too). A tangent's cost follows the scene as it deforms (the follower
    pressure's and contact's parts, their fill of the factors), which a tangent timed at
    rest does not see."""
    from .implicit import solve_implicit
    from .run import prepare
    from .static_solve import solve_static

    run = prepare(deck, mesh, model)
    finished, spent = _within(seconds, solve_implicit if deck.solver.method == "implicit" else solve_static, run)
    return {"steps": len(run.newton), "t": float(run.sim.state.t), "seconds": spent,
            "iterations": sum(step.iterations for step in run.newton),
            "tangents": len(run.tangent_seconds), "finished": finished,
            "tangent_seconds": float(np.mean(run.tangent_seconds)) if run.tangent_seconds else None}
