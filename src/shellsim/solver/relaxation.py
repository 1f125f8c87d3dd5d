"""The end of a dynamic relaxation (``[solver.relaxation]``): the velocities are reset at
each peak of the kinetic energy in the time loop (:func:`shellsim.solver.explicit.kinetic_damping`);
here, once every curve holds its last value, the run is at rest when its residual force
is within the deck's tolerance, measured as a static step's is."""

from __future__ import annotations

import numpy as np

from ..curve_tables import held_from
from .equilibrium import Equilibrium


class Relaxing:
    """Watches a relaxing run (:class:`shellsim.solver.run.Run`) for rest."""

    def __init__(self, run, tolerance: float):
        self.equilibrium = Equilibrium(run.sim)
        self.held_from = held_from(run.model.curves)
        self.tolerance = tolerance
        self.residual: float | None = None  # at the last sample looked at, once the curves hold
        self.relaxed_at: float | None = None

    def at_rest(self, sim) -> bool:
        """Whether ``sim`` (:class:`shellsim.solver.simulation.Simulation`, the run's) has
        come to rest: the curves hold and the residual force over the free DOFs is within
        the tolerance of the force scale, both as a static step measures them
        (:class:`shellsim.solver.equilibrium.Equilibrium`)."""
        if sim.state.t < self.held_from:
            return False
        eq = self.equilibrium
        residual = eq.residual()[:eq.unknowns.n_free]
        self.residual = float(np.linalg.norm(residual) / max(eq.force_scale(), 1e-300))
        if self.residual <= self.tolerance:
            self.relaxed_at = float(sim.state.t)
        return self.relaxed_at is not None

    def record(self, sim) -> dict:
        """For summary.json: when the curves hold from, when the run came to rest (None: not
        by its end), the relative residual last measured, the velocity resets."""
        return {"held_from": self.held_from, "relaxed_at": self.relaxed_at, "residual": self.residual,
                "tolerance": self.tolerance, "resets": int(sim.workspace.relax[1])}
