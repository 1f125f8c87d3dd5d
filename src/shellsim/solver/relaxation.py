"""The end of a dynamic relaxation (``[solver.relaxation]``): the velocities are reset at
each peak of the kinetic energy in the time loop (:func:`shellsim.solver.explicit.kinetic_damping`);
here, once every curve holds its last value, the run is at rest when its residual force
is within the deck's tolerance, measured as a static step's is."""

from __future__ import annotations

import math

import numpy as np

from ..bundles import Curves
from ..curve_tables import EXTRAPOLATION
from .equilibrium import Equilibrium


def held_from(curves: Curves) -> float:
    """The time from which every curve of ``curves`` holds its value: the latest of their
    last changes (0 for none; inf when one is extrapolated linearly past a change)."""
    latest = 0.0
    for c in range(len(curves.length)):
        n = int(curves.length[c])
        t, v = curves.t[c, :n], curves.v[c, :n]
        changes = np.flatnonzero(v[1:] != v[:-1])
        if not changes.size:
            continue
        if curves.extrap[c] == EXTRAPOLATION["linear"] and changes[-1] == n - 2:
            return math.inf
        latest = max(latest, float(t[changes[-1] + 1]))
    return latest


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
