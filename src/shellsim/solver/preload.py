"""A preloaded explicit run (``solver.preload``): static load steps to the preload time,
then central differences from rest in that equilibrium, as an explicit code's dynamic
relaxation or a static step before an explicit one sets up a prestressed state (the
artery at diastolic pressure before the heartbeat) in seconds instead of a damped hold.
"""

from __future__ import annotations

from .run import Listener, Run, integrate
from .static_solve import solve_static


def preload_then_integrate(run: Run, listener: Listener | None = None) -> Run:
    """Solve ``run`` statically to ``solver.preload``, then integrate it from rest to the
    end time; one history and one series of frames over both. Raises as
    :func:`shellsim.solver.static_solve.solve_static` in the first phase and as
    :func:`shellsim.solver.run.integrate` in the second."""
    listener = listener or Listener()
    solve_static(run, listener, until=run.deck.solver.preload)
    start_from_rest(run)
    return integrate(run, listener)


def start_from_rest(run: Run) -> None:
    """The converged static state as the integration's start: at rest, no step taken
    yet, and its forces evaluated with no increment (an incremental law's stresses are
    the equilibrium's, not moved again)."""
    s = run.sim.state
    s.v[:] = 0.0
    s.w[:] = 0.0
    s.dt_prev = 0.0
    s.steps = 0  # the static phase's steps are run.newton's
    run.sim.evaluate_forces()
