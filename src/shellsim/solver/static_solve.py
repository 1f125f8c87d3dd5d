"""A static solve from start to end: the path chosen by ``solver.static.control``, load
steps (:func:`.static.load_steps`) or arc length (:func:`.arc_length.follow_path`), over
the Newton solver of :mod:`.static`."""

from __future__ import annotations

from .arc_length import follow_path
from .run import Listener, Run, ending, take_frame, take_sample
from .static import NewtonSolver, load_steps


def solve_static(run: Run, listener: Listener | None = None, until: float | None = None) -> Run:
    """Solve the scene statically from t = 0 to the deck's end time (or ``until``, a
    preload's end), by load steps or along the path (``solver.static.control``),
    sampling the history at every converged step and writing frames at the output times.

    Raises NumericalError (status 'not converged') naming where in the load, the residual
    and the worst place when a step cannot be solved even cut to ``min_increment``; the
    samples and frames until then are kept. KeyboardInterrupt passes through with
    ``run.status = 'interrupted'``.
    """
    listener = listener or Listener()
    with ending(run, listener, "not converged"):  # a breaking frame is the last converged state
        newton = NewtonSolver(run)
        run.startup["first_dt_s"] = 0.0
        take_sample(run, listener)
        take_frame(run, listener)
        if run.deck.solver.static.control == "arc_length":
            follow_path(run, newton, listener)
        else:
            load_steps(run, newton, listener, until or run.deck.solver.end_time)
        if newton.settings.check_stability:
            newton.observe()
    return run
