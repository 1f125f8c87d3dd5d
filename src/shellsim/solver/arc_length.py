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
u_previous), so the path turns back at a limit point instead of reversing; a step that
converges pointing back along the path anyway is taken again shorter.

The run's clock is the load time's path length, sum |Delta t|: it equals the load time
until the first limit point and keeps rising after it, so histories and frames stay in
order; the load reached is the history's load factor. Where the next output time or a
knot of a load curve is within the next arc's reach, the step goes there by a load step
instead (Newton at that load time), so frames land on their times and no step straddles
a kink of a curve. Such a load step counts only where it stays on the path: one that
moves the shape more than LANDING_REACH arcs found another equilibrium at that load (a
balloon past its pressure maximum turned inside out) and is undone. No arc passes an
output time either (it is taken again shorter), so each output time has a frame of its
own, at its time wherever a load step reaches it and just past it where a limit point
lies between. Where the curves hold (or have ended), the load time moves on to where
they change again with nothing to solve; where the path comes back to loads that no
longer change (a structure unloaded along it), the run ends there.
"""

from __future__ import annotations

import numpy as np

from ..compiled_call import TypedCall
from ..errors import NumericalError
from ..loads import external_forces
from .run import Listener, Run, output_times, take_frame, take_sample
from .equilibrium import Converged
from .static import ARC_ADVICE, CUT, NewtonSolver, NewtonStep, NotConverged, not_converged

#: Load-time share of the span by which the loads' rate is differenced.
RATE_STEP = 1e-6
#: Iterations a step aims at: the next step's length scales by sqrt(AIM / iterations),
#: by a factor within GROWTH (Crisfield's rule), up to LONGEST times the first step's.
AIM, GROWTH, LONGEST = 5, (0.5, 2.0), 4.0
#: The largest turn of the path from one step to the next [rad]: after a step that turned
#: more, the next is shorter in proportion, so the arcs follow the path's curvature.
MOST_TURN = 0.15
#: Steps in a row that move the clock by less than STALL of the end time end the run: the
#: path makes no progress.
STALLED_STEPS, STALL = 50, 1e-9
#: The most a load step onto an output time or knot may move the translations, in arcs
#: of the current length: further, and it left the path for another equilibrium.
LANDING_REACH = 2.0


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
        curves = newton.run.model.curves
        #: every curve's knots, where a load's rate may jump
        self.knots = np.unique(np.concatenate([curves.t[c, :n] for c, n in enumerate(curves.length)] or [[]]))
        self.load_time = 0.0
        self.forward = 1.0  # the way the load time went in the last step
        self.direction: np.ndarray | None = None  # the last converged step's translations
        self.turn = 0.0  # the angle between the last two steps' translations [rad]
        self.load_per_length = 0.0  # the last step's change of load time per translational length

    def first_length(self, load_step: float) -> float:
        """The translational length of the linear response to ``load_step`` of load time at
        the converged state: the path's first step matches load control's first."""
        self.eq.evaluate(self.load_time)
        _, lu, _ = self.newton.at_converged("at the start, where the path's first tangent is formed", record=False)
        along = lu.solve(self.rate(self.load_time))[self.translation]
        length = abs(load_step) * float(np.linalg.norm(along))
        self.load_per_length = abs(load_step) / max(length, 1e-300)
        return length

    def _changing(self, t: float) -> bool:
        """Whether the loads change just beyond load time t, the way the path goes."""
        return bool(np.any(self.rate(t + self.forward * 4.0 * self.rate.step)))

    def hold_end(self) -> float | None:
        """None while the loads change ahead; where they hold, the load time at which
        they change again the way the path goes (+-inf: never)."""
        t = self.load_time
        if self._changing(t):
            return None
        ahead = self.knots[(self.knots - t) * self.forward > 0.0][::int(self.forward)]
        return next((float(k) for k in ahead if self._changing(k)), self.forward * np.inf)

    def next_knot(self) -> float:
        """The load time of the next knot of a curve the way the path goes (+-inf: none)."""
        ahead = self.knots[(self.knots - self.load_time) * self.forward > 1e-12 * self.rate.step]
        if not len(ahead):
            return self.forward * np.inf
        return float(ahead[0] if self.forward > 0 else ahead[-1])

    def next_stop(self, clock: float, marks: np.ndarray) -> float:
        """The load time of the nearest place ahead a step should land on: the next knot
        of a curve, or where the clock (now ``clock``) reaches the next of ``marks``."""
        t = self.load_time
        stops = [self.next_knot(), *(t + self.forward * (m - clock) for m in marks[marks > clock])]
        return min(stops, key=lambda stop: abs(stop - t))

    def moved(self, before: Converged) -> None:
        """The state has converged at ``self.load_time`` from ``before`` by other means
        (a load step, a hold): the path's direction is that move's."""
        self._follow(self._translations(before))

    def _translations(self, before: Converged) -> np.ndarray:
        """The free translations (n_translations,) from ``before`` to the state."""
        u, s = self.eq.unknowns, self.newton.run.sim.state
        change = u.gather(u.to_local(s.x - before.arrays["x"], s.theta - before.arrays["theta"]))
        return change[:u.n_free][self.translation]

    def _follow(self, translations: np.ndarray) -> None:
        """The last step's translations (n_translations,): its turn from the one before."""
        if self.direction is not None and np.any(translations) and np.any(self.direction):
            cosine = translations @ self.direction / (np.linalg.norm(translations) * np.linalg.norm(self.direction))
            self.turn = float(np.arccos(np.clip(cosine, -1.0, 1.0)))
        if np.any(translations):
            self.direction = translations

    def step(self, length: float, stop: float, room: float = np.inf) -> tuple[int, float, float]:
        """Equilibrium a translational distance ``length`` along the path; returns
        (iterations, relative residual, change of load time). Raises NotConverged when it
        does not converge, converges pointing back along the path, passes the load time
        ``stop`` (a knot) or moves the clock more than ``room`` (past an output time); the
        state is then wherever the iterations left it."""
        eq, newton, m = self.eq, self.newton, self.translation
        start = t = self.load_time
        eq.evaluate(t)
        _, lu, floor = newton.at_converged(f"at load time {t:.6g} (clock t = {newton.run.sim.state.t:.6g}), where the "
                                           "converged state's tangent is formed")
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
                if (t - stop) * (start - stop) < 0.0:
                    raise NotConverged(f"the step passed load time {stop:.6g}, a knot of a load curve")
                if abs(t - start) > room * (1.0 + 1e-9):
                    raise NotConverged("the step passed an output time")
                if self.direction is not None and total[m] @ self.direction < 0.0:
                    raise NotConverged("the step turned back along the path it came by")
                newton.held_apart(t)
                self._follow(total[m])
                self.load_time, self.forward = t, (1.0 if t >= start else -1.0)
                self.load_per_length = abs(t - start) / length
                return iteration, norm / max(scale, 1e-300), t - start
            lu = None  # the old factors go before the new are formed: together they would double the peak
            _, lu, floor = newton.linearised()
            balance, along = lu.solve(residual), lu.solve(self.rate(t))
            shift = constrained_shift(total[m] + balance[m], along[m], length, total[m])
            correction = balance + shift * along
            eq.move(self._padded(correction))
            total += correction
            t += shift
        raise NotConverged(f"{self.settings.max_iterations} iterations left a residual of "
                           f"{norm / max(scale, 1e-300):.3g} of the force scale")

    def land(self, stop: float, length: float) -> NewtonStep | None:
        """A load step to the load time ``stop`` when the next arc of ``length`` would
        reach it (by the last step's load per length); None when it would not, when the
        load step does not converge (a limit point before it) or when it moves the shape
        further than LANDING_REACH arcs (to another equilibrium, off the path): the state
        is then as before."""
        if abs(stop - self.load_time) > self.load_per_length * length:
            return None
        newton, before = self.newton, self.eq.converged
        noted = len(newton.stability.noted)
        try:
            iterations, tangents, residual = newton.step(stop)
        except NotConverged:
            newton.back_to_converged()
            return None
        moved = self._translations(before)
        if np.linalg.norm(moved) > LANDING_REACH * length:
            newton.back_to_converged()  # another equilibrium at that load, off the path: no jump of it
            del newton.stability.noted[noted:]
            return None
        sim = newton.run.sim
        change, self.load_time = stop - self.load_time, stop
        self.forward = 1.0 if change >= 0.0 else -1.0
        self.moved(before)
        return NewtonStep(t=sim.state.t + abs(change), load_time=stop, iterations=iterations, tangents=tangents,
                          residual=residual, cutbacks=0)

    def hold(self, until: float, clock_to_mark: float) -> NewtonStep:
        """The load time moved on to ``until`` (or by ``clock_to_mark``, the clock's way to
        the next output time, when nearer) through loads that hold: the state stays in
        equilibrium."""
        change = min(abs(until - self.load_time), clock_to_mark)
        self.load_time += self.forward * change
        return NewtonStep(t=self.newton.run.sim.state.t + change, load_time=self.load_time, iterations=0,
                          tangents=0, residual=0.0, cutbacks=0)

    def reach(self, length: float, first: float, stop: float, room: float) -> tuple[NewtonStep, float]:
        """A converged step from the converged state, tried at ``length`` and cut back
        until it converges short of the load time ``stop`` and moves the clock by no more
        than ``room``; returns the step (its clock t past the state's by the change of load
        time) and the length it was taken at.
        Raises NumericalError when the length falls below ``min_increment`` of the ``first``."""
        sim = self.newton.run.sim
        cutbacks = 0
        while True:
            try:
                iterations, residual, change = self.step(length, stop, room)
                return NewtonStep(t=sim.state.t + abs(change), load_time=self.load_time, iterations=iterations,
                                  tangents=iterations, residual=residual, cutbacks=cutbacks), length
            except NotConverged as why:
                self.eq.converged.restore(sim)
                cutbacks += 1
                length *= CUT
                if length < self.settings.min_increment * first:
                    where = (f"along the path from load time {self.load_time:.6g} (clock t = {sim.state.t:.6g}) "
                             f"even in arc lengths of {self.settings.min_increment:g} of the first")
                    raise NumericalError(not_converged(self.newton.run, self.newton, where, str(why),
                                                       ARC_ADVICE)) from None

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
    ``solver.static.increments``; no later step is longer than LONGEST of it. Where the
    path comes back to loads that no longer change, the run ends there with a frame and
    says so (:meth:`.stability.StabilityWatch.unloaded`). Raises NumericalError where a
    step cannot be solved, or after STALLED_STEPS steps that barely move the clock."""
    sim, end = run.sim, run.deck.solver.end_time
    arc = ArcLength(newton)
    first = length = None
    marks = output_times(run.deck)
    stalled = 0
    while sim.state.t < end - 1e-12 * end:
        before = sim.state.t
        to_mark = marks[marks > before + 1e-12 * end][0] - before  # the marks end at the end time
        held = arc.hold_end()
        if held is not None:
            if arc.forward < 0.0 and np.isinf(held):
                newton.stability.unloaded(before, arc.load_time, end)
                take_frame(run, listener)
                return
            step = arc.hold(held, to_mark)
        else:
            if first is None:
                first = length = arc.first_length(end / run.deck.solver.static.increments)
            stop = arc.next_stop(before, marks)
            step = arc.land(stop, length)
            if step is None:
                step, length = arc.reach(length, first, arc.next_knot(), to_mark)
                if step.cutbacks == 0:
                    length = length * float(np.clip(np.sqrt(AIM / max(step.iterations, 1)), *GROWTH))
                length = min(length, LONGEST * first, length * MOST_TURN / max(arc.turn, 1e-300))
        sim.state.t = step.t
        newton.commit(step)
        take_sample(run, listener)
        if np.any((marks > before) & (marks <= sim.state.t + 1e-12 * end)):
            take_frame(run, listener)
        stalled = stalled + 1 if sim.state.t - before < STALL * end else 0
        if stalled >= STALLED_STEPS:
            raise NumericalError(f"arc length made no progress: {stalled} steps in a row moved the clock by less "
                                 f"than {STALL:g} of solver.end_time, at load time {arc.load_time:.6g} "
                                 f"(clock t = {sim.state.t:.6g})")
