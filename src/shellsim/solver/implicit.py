"""Implicit dynamics (``solver.method = "implicit"``): the HHT-alpha method (Hilber,
Hughes and Taylor 1977, Earthquake Eng. Struct. Dyn. 5, 283-292) on the static solve's
Newton steps (:mod:`.static`), with the explicit run's lumped masses.

Each time step from t_n to t = t_n + dt finds the shape where

    M a + (1 + alpha) (c M v + f_int(u) - f_ext(t)) - alpha (c M v_n + f_int(u_n) - f_ext(t_n)) = 0,

a = (u - u_n - dt v_n - dt^2 (1/2 - beta) a_n) / (beta dt^2), v = v_n + dt ((1 - gamma)
a_n + gamma a), beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha (Hughes, The Finite Element
Method, 9.3), c the deck's mass-proportional ``damping``. The translations u are the
nodes' positions; the rotations the fibre-frame angles the static solve accumulates
(``theta``), with the rotary masses. The residual's derivative adds (1 / (beta dt^2) +
(1 + alpha) c gamma / (beta dt)) M to (1 + alpha) times the static tangent: the masses
keep every unknown stiff, a slack chord's node too. Friction between shells opposes
the iterate's velocities, v above, and its derivative by the translations, through v's
gamma / (beta dt), joins the tangent (:func:`shellsim.loads.shell_contact.friction_couplings`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .explicit import DAMPED, KINETIC
from .run import Listener, Run, ending, take_frame, take_sample
from .simulation import Simulation
from .static import NewtonSolver, load_steps


class HHT:
    """The inertia of an implicit time step over ``sim``'s state: the step's start (u_n,
    its velocities and accelerations, its out-of-balance forces), and what the residual
    and the tangent of the step to time ``t`` add.

    Shapes: translations (n, 3), rotations (n, 2); forces f_ext - f_int of the same."""

    def __init__(self, sim: Simulation, alpha: float, damping: float = 0.0):
        self.sim, self.alpha, self.damping = sim, alpha, damping
        self.beta, self.gamma = (1.0 - alpha) ** 2 / 4.0, 0.5 - alpha
        s = sim.state
        self.dt = 0.0
        self.start = self._snapshot()
        # at rest, the accelerations the out-of-balance forces give (none on a massless node)
        self.start["a"] = _per_mass(s.f_ext - s.f_int, s.mt[:, None])
        self.start["alpha"] = _per_mass(s.fr_ext - s.fr_int, s.mr[:, None])

    def _snapshot(self) -> dict[str, np.ndarray]:
        s = self.sim.state
        return {"t": s.t, "x": s.x.copy(), "theta": s.theta.copy(), "v": s.v.copy(), "w": s.w.copy(),
                "f": s.f_ext - s.f_int, "fr": s.fr_ext - s.fr_int}

    def to(self, t: float) -> bool:
        """Set the step's end time; whether its length changed (a tangent formed for
        another length has another mass term)."""
        dt = t - self.start["t"]
        changed = not np.isclose(dt, self.dt, rtol=1e-12, atol=0.0)
        self.dt = dt
        return changed

    def _motion(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(a, alpha, v, w) at the state's shape: Newmark's accelerations and velocities."""
        s, n, dt, beta, gamma = self.sim.state, self.start, self.dt, self.beta, self.gamma
        a = (s.x - n["x"] - dt * n["v"] - dt * dt * (0.5 - beta) * n["a"]) / (beta * dt * dt)
        spin = (s.theta - n["theta"] - dt * n["w"] - dt * dt * (0.5 - beta) * n["alpha"]) / (beta * dt * dt)
        return (a, spin, n["v"] + dt * ((1.0 - gamma) * n["a"] + gamma * a),
                n["w"] + dt * ((1.0 - gamma) * n["alpha"] + gamma * spin))

    def move_velocities(self) -> None:
        """Set the state's velocities to Newmark's at its shape (what the contacts' friction
        opposes); none before the step's end time is set."""
        if self.dt > 0.0:
            s = self.sim.state
            _, _, s.v[:], s.w[:] = self._motion()

    @property
    def velocity_rate(self) -> float:
        """d v / d u of Newmark's velocities, gamma / (beta dt) [1/s]."""
        return self.gamma / (self.beta * self.dt)

    def balanced(self, f: np.ndarray, fr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The step's residual forces from the state's out-of-balance ones f = f_ext - f_int
        (n, 3) and fr (n, 2): (1 + alpha) (f - c M v) - alpha (f_n - c M v_n) - M a."""
        s, n, alpha, c = self.sim.state, self.start, self.alpha, self.damping
        a, spin, v, w = self._motion()
        return ((1.0 + alpha) * (f - c * s.mt[:, None] * v) - alpha * (n["f"] - c * s.mt[:, None] * n["v"])
                - s.mt[:, None] * a,
                (1.0 + alpha) * (fr - c * s.mr[:, None] * w) - alpha * (n["fr"] - c * s.mr[:, None] * n["w"])
                - s.mr[:, None] * spin)

    def inertial_scale(self) -> float:
        """The norm of the inertial forces M a at the state (a force scale that is not 0
        where the loads and the internal forces are)."""
        s = self.sim.state
        a, spin, _, _ = self._motion()
        return float(np.sqrt(np.sum((s.mt[:, None] * a) ** 2) + np.sum((s.mr[:, None] * spin) ** 2)))

    def tangent(self, static: sp.csc_matrix, masses: np.ndarray) -> sp.csc_matrix:
        """(1 + alpha) K + (1 / (beta dt^2) + (1 + alpha) c gamma / (beta dt)) M:
        ``static`` (n_free, size) the static tangent, ``masses`` (n_free,) each free
        unknown's mass."""
        dt, beta = self.dt, self.beta
        per_mass = 1.0 / (beta * dt * dt) + (1.0 + self.alpha) * self.damping * self.gamma / (beta * dt)
        inertia = sp.diags(masses * per_mass, shape=static.shape, format="csc")
        return ((1.0 + self.alpha) * static + inertia).tocsc()

    def commit(self) -> None:
        """The state has converged at the step's end: its velocities and accelerations are
        the new start's, the kinetic energy the state's."""
        s, n = self.sim.state, self.start
        a, spin, s.v[:], s.w[:] = self._motion()
        # the damping forces' work over the step, by the trapezoidal rule
        s.work[DAMPED] += 0.5 * self.damping * float(np.sum(s.mt[:, None] * (n["v"] + s.v) * (s.x - n["x"]))
                                                     + np.sum(s.mr[:, None] * (n["w"] + s.w) * (s.theta - n["theta"])))
        s.energy[DAMPED] = s.work[DAMPED]
        s.energy[KINETIC] = 0.5 * float(np.sum(s.mt * np.sum(s.v ** 2, axis=1)) + np.sum(s.mr[:, None] * s.w ** 2))
        self.start = self._snapshot() | {"a": a, "alpha": spin}


def _per_mass(force: np.ndarray, mass: np.ndarray) -> np.ndarray:
    return np.divide(force, mass, out=np.zeros_like(force), where=mass > 0.0)


def solve_implicit(run: Run, listener: Listener | None = None) -> Run:
    """Integrate the scene in time from rest at t = 0 to the deck's end time by HHT-alpha
    time steps (``[solver.implicit]``), sampling the history at every converged step and
    writing frames at the output times. Raises NumericalError (status 'not converged')
    where a step cannot be solved even cut to ``min_increment``; the samples and frames
    until then are kept."""
    listener = listener or Listener()
    with ending(run, listener, "not converged"):
        settings = run.deck.solver.implicit
        newton = NewtonSolver(run, settings)
        newton.eq.evaluate(0.0)  # the forces at rest: the first accelerations
        newton.eq.inertia = HHT(run.sim, settings.alpha, run.deck.solver.damping)
        run.startup["first_dt_s"] = 0.0
        take_sample(run, listener)
        take_frame(run, listener)
        load_steps(run, newton, listener, run.deck.solver.end_time)
    return run
