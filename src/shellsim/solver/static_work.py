"""The energies of a static solve: the internal work and the external work (the loads'
and the supports' reactions on prescribed motion; in an implicit one, friction's apart),
summed by the trapezoidal rule between converged load steps, as the explicit loop sums
them between time steps.

At equilibrium the two differ only by the work of the residual the steps converged to,
so their balance measures how well the path was solved; the internal work is the strain
energy the structure holds (a hyperelastic wall's stored energy), which a static run
otherwise reports as 0.
"""

from __future__ import annotations

import numpy as np

from .equilibrium import Equilibrium
from .explicit import EXTERNAL, FRICTION, INTERNAL


class StaticWork:
    """Trapezoidal works over the converged states of ``eq``'s simulation, written to its
    state's ``work`` and ``energy`` (an explicit run after a preload goes on from them)."""

    def __init__(self, eq: Equilibrium):
        self.eq = eq
        self._last = self._now()

    def _now(self) -> dict[str, np.ndarray]:
        """The converged state's positions, rotations and forces, and the supports'
        reactions along the prescribed axes (n_known,)."""
        s, n_free, space = self.eq.sim.state, self.eq.unknowns.n_free, self.eq.sim.workspace
        return {"x": s.x.copy(), "theta": s.theta.copy(), "f_int": s.f_int.copy(), "fr_int": s.fr_int.copy(),
                "f_ext": s.f_ext.copy(), "fr_ext": s.fr_ext.copy(), "reaction": -self.eq.residual()[n_free:],
                "f_fr": space.f_fr.copy(), "fr_fr": space.fr_fr.copy()}

    def add_step(self) -> None:
        """Add the works from the last converged state to the state now (converged, its
        forces evaluated)."""
        before, now = self._last, self._now()
        dx, dtheta = now["x"] - before["x"], now["theta"] - before["theta"]

        def work(f: str, fr: str) -> float:
            return 0.5 * float(np.sum((before[f] + now[f]) * dx) + np.sum((before[fr] + now[fr]) * dtheta))

        p = self.eq.sim.model.constraints.prescribed
        reactions = 0.5 * float(np.sum((before["reaction"] + now["reaction"]) * dx[p.nodes, p.axes]))
        s = self.eq.sim.state
        friction = work("f_fr", "fr_fr") if self.eq.sim.workspace.friction else 0.0
        s.work[INTERNAL] += work("f_int", "fr_int")
        s.work[EXTERNAL] += work("f_ext", "fr_ext") + reactions - friction  # friction is among f_ext
        s.work[FRICTION] -= friction
        for kind in (INTERNAL, EXTERNAL, FRICTION):
            s.energy[kind] = s.work[kind]
        self._last = now
