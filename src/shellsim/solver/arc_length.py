"""Arc-length continuation of a static solve (``solver.static.control = "arc_length"``):
Crisfield's cylindrical constraint, which follows an equilibrium path through limit
points where load control stops (a snapping shell, a tube past its inflation maximum).

The load time t, at which the loads read their curves, becomes an unknown beside the
shape. Each step moves the translations by a fixed length ``l`` along the path,

    ||Delta u||^2 = l^2       (translational unknowns only: rotations have other units),

and solves equilibrium r(u, t) = f_ext(u, t) - f_int(u) = 0 with it. A Newton iteration
takes the two solutions of K du_r = r and K du_t = q, q = d f_ext / dt (the loads' rate
in load time, central differences), and the change of load time dt that keeps the
constraint: the root of a quadratic nearer to the step's direction (Crisfield 1981,
"A fast incremental/iterative solution procedure that handles snap-through", Computers &
Structures 13, 55-62). A step's direction follows the last one (the sign of du_t . Delta
u_previous), so the path turns back at a limit point instead of reversing.

The run's clock is the load time's path length, sum |Delta t|: it equals the load time
until the first limit point and keeps rising after it, so histories and frames stay in
order; the load reached is the history's load factor.
"""

from __future__ import annotations

import numpy as np

from ..compiled_call import TypedCall
from ..errors import NumericalError
from ..loads import external_forces
from .run import Listener, Run, _frame, _record, output_times
from .static import CUT, NewtonSolver, NewtonStep, NotConverged, not_converged

#: Load-time share of the span by which the loads' rate is differenced.
RATE_STEP = 1e-6
#: Iterations a step aims at: the next step's length scales by sqrt(AIM / iterations),
#: by a factor within GROWTH (Crisfield's rule), up to LONGEST times the first step's.
AIM, GROWTH, LONGEST = 5, (0.5, 2.0), 4.0


class LoadRate:
    """q = d f_ext / dt over the free unknowns at the state's shape, by central
    differences of the external forces in load time (scratch arrays of their own, so the
    last evaluation's forces stay as they are)."""

    def __init__(self, newton: NewtonSolver):
        sim = newton.run.sim
        self.sim, self.unknowns = sim, newton.eq.unknowns
        n = sim.model.n_nodes
        self.step = RATE_STEP * newton.run.deck.solver.end_time
        self._f, self._fr, self._g = np.empty((n, 3)), np.empty((n, 2)), np.empty((n, 3))
        self._external = TypedCall(external_forces)

    def _forces(self, t: float) -> np.ndarray:
        fields = self.sim.state.fields
        self._external(float(t), self.sim.model, fields.shape, self._f, self._fr, self._g)
        return self.unknowns.gather(self.unknowns.to_local(self._f, self._fr))[:self.unknowns.n_free]

    def __call__(self, t: float) -> np.ndarray:
        return (self._forces(t + self.step) - self._forces(t - self.step)) / (2 * self.step)


class ArcLength:
    """Steps of a fixed translational length along the equilibrium path of ``newton``'s
    run, from its converged state."""

    def __init__(self, newton: NewtonSolver):
        self.newton = newton
        self.eq, self.settings = newton.eq, newton.settings
        self.rate = LoadRate(newton)
        u = newton.eq.unknowns
        translation = np.zeros(u.index.shape, dtype=bool)
        translation[:, :3] = True
        free = (u.index >= 0) & (u.index < u.n_free)
        self.translation = np.zeros(u.n_free, dtype=bool)
        self.translation[u.index[free & translation]] = True
        self.load_time = 0.0
        self.direction: np.ndarray | None = None  # the last converged step's translations

    def first_length(self, load_step: float) -> float:
        """The translational length of the linear response to ``load_step`` of load time at
        the converged state: the path's first step matches load control's first."""
        self.eq.evaluate(self.load_time)
        _, lu, _ = self.newton.linearised()
        along = lu.solve(self.rate(self.load_time))[self.translation]
        return abs(load_step) * float(np.linalg.norm(along))

    def step(self, length: float) -> tuple[int, float, float]:
        """Equilibrium a translational distance ``length`` along the path; returns
        (iterations, relative residual, change of load time). Raises NotConverged; the
        state is then wherever the iterations left it."""
        eq, newton, m = self.eq, self.newton, self.translation
        start = t = self.load_time
        eq.evaluate(t)
        _, lu, floor = newton.linearised()
        rate = self.rate(t)
        along = lu.solve(rate)
        sign = 1.0 if self.direction is None or along[m] @ self.direction >= 0.0 else -1.0
        change = sign * length / max(float(np.linalg.norm(along[m])), 1e-300)
        total = change * along
        eq.move(self._padded(total))
        t += change
        for iteration in range(1, self.settings.max_iterations + 1):
            eq.evaluate(t)
            residual = newton.free_residual()
            scale = eq.force_scale()
            norm = float(np.linalg.norm(residual))
            # the energy of the next correction, with the last factorisation
            energy = abs(float(lu.solve(residual) @ residual))
            # the energy against the work of the force scale over the step: the predictor's own
            # work vanishes at a limit point, where the load's change does
            if newton.converged(norm, scale, energy, scale * length, floor):
                newton.held_apart(t)
                self.direction = total[m]
                self.load_time = t
                return iteration, norm / max(scale, 1e-300), t - start
            _, lu, floor = newton.linearised()
            balance, along = lu.solve(residual), lu.solve(self.rate(t))
            shift = constrained_shift(total[m] + balance[m], along[m], length, total[m])
            correction = balance + shift * along
            eq.move(self._padded(correction))
            total += correction
            t += shift
        raise NotConverged(f"{self.settings.max_iterations} iterations left a residual of "
                           f"{norm / max(scale, 1e-300):.3g} of the force scale")

    def reach(self, length: float, first: float) -> tuple[NewtonStep, float]:
        """A converged step from the converged state, tried at ``length`` and cut back
        until it converges; returns the step (its clock t past the state's by the change
        of load time) and the length it was taken at. Raises NumericalError when the
        length falls below ``min_increment`` of the ``first``."""
        sim = self.newton.run.sim
        cutbacks = 0
        while True:
            try:
                iterations, residual, change = self.step(length)
                return NewtonStep(t=sim.state.t + abs(change), load_time=self.load_time, iterations=iterations,
                                  tangents=iterations, residual=residual, cutbacks=cutbacks), length
            except NotConverged as why:
                self.eq.converged.restore(sim)
                cutbacks += 1
                length *= CUT
                if length < self.settings.min_increment * first:
                    where = (f"along the path from load time {self.load_time:.6g} (clock t = {sim.state.t:.6g}) "
                             f"even in arc lengths of {self.settings.min_increment:g} of the first")
                    raise NumericalError(not_converged(self.newton.run, self.newton, where, str(why))) from None

    def _padded(self, free: np.ndarray) -> np.ndarray:
        """A correction of the free unknowns, with the prescribed ones (held) appended."""
        return np.concatenate([free, np.zeros(self.eq.unknowns.n_known)])


def constrained_shift(moved: np.ndarray, along: np.ndarray, length: float, before: np.ndarray) -> float:
    """The change of load time s that puts ``moved + s along`` on the sphere of radius
    ``length``: of the two roots of the quadratic, the one whose increment turns least
    from ``before`` (the step's increment so far). Raises NotConverged when the sphere is
    out of reach (no real root)."""
    a, b, c = along @ along, 2.0 * along @ moved, moved @ moved - length**2
    discriminant = b * b - 4.0 * a * c
    if discriminant < 0.0 or a == 0.0:
        raise NotConverged("the arc-length constraint has no real root (the step is too long for the path's curvature)")
    roots = (-b + np.array([1.0, -1.0]) * np.sqrt(discriminant)) / (2.0 * a)
    return float(max(roots, key=lambda s: (moved + s * along) @ before))


def follow_path(run: Run, newton: NewtonSolver, listener: Listener) -> None:
    """Arc-length steps from the converged state until the clock (the load time's path
    length) passes the end time; a frame after each step that passes an output time.
    The first step is as long as the linear response to the first load step of
    ``solver.static.increments``, and no later step is longer than LONGEST of it."""
    sim, end = run.sim, run.deck.solver.end_time
    arc = ArcLength(newton)
    first = length = arc.first_length(end / run.deck.solver.static.increments)
    marks = output_times(run.deck)
    while sim.state.t < end - 1e-12 * end:
        before = sim.state.t
        step, length = arc.reach(length, first)
        sim.state.t = step.t
        newton.commit(step)
        _record(run, listener)
        if np.any((marks > before) & (marks <= sim.state.t + 1e-12 * end)):
            _frame(run, listener)
        if step.cutbacks == 0:
            length = min(length * float(np.clip(np.sqrt(AIM / max(step.iterations, 1)), *GROWTH)), LONGEST * first)
