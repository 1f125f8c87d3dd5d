"""Static equilibrium by Newton-Raphson load steps (``solver.method = "static"``): the
pseudo-time runs from 0 to the end time, the loads follow their curves in it, and each
step solves f_int(u) = f_ext(t) with the tangent of :mod:`.equilibrium`. The signs of the
pivots of a tangent formed at a converged state, with its own load, tell where the path
loses stability (:mod:`.stability`): load control forms one at the start, wherever the
load time has moved on by a load step of ``increments`` since the last, and at the end
(unless ``check_stability`` is off), and modified Newton goes on with it; arc length forms
one at every step's start anyway. The works between converged states are the run's
energies (:mod:`.static_work`).

Step control: a step that does not converge in ``max_iterations`` (or whose residual
turns to no number, or whose tangent is singular) is taken again from the last converged
state at a quarter of its length; one that converges with at most GROWTH_TANGENTS
tangents formed, or the second of two in a row that converged without a cut, lets the
next grow by half, up to the deck's first length. The second rule is what lets a step
grow back where every step needs many tangents whatever its length (a thin plate whose
finite-difference tangent converges linearly: steps cut to 1/256 of the first stayed
there for the rest of the run). The outputs
are the explicit run's: a history sample at every converged step, frames at the output
times.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..errors import NumericalError, id_list, place
from ..loads import contact_pairs, hold_pairs, pairs_added, passed_through
from .equilibrium import Converged, Equilibrium
from .quality import folding_diagnosis
from .run import Listener, Run, output_times, take_frame, take_sample
from .sparse_lu import FactorsTooLarge, SymmetricPatternLU
from .stability import StabilityWatch
from .tangent_pattern import free_columns
from .static_work import StaticWork

CUT, GROW, GROWTH_TANGENTS = 0.25, 1.5, 4
#: Modified Newton forms a new tangent when an iteration leaves more than this share of the residual.
SLOW = 0.5
#: Halvings a correction from a fresh tangent may take while it makes the residual larger.
LINE_SEARCH_HALVINGS = 4
#: An iterate whose force scale (its internal forces, supports' included) is more than this
#: many times the one its load step started from ran away: an exponential law far out
#: (k2 = 524.6 puts forces near 1e180) can balance a pressure to 1e-6 of forces that large
#: and pass as converged. Steps that prescribe motion are not held to it.
RUNAWAY = 1e6
#: A step whose shape moved more than this many times as far as its first correction (the
#: tangent's prediction) jumped: load control passes a small snap-through so, landing on
#: another part of the path without following it.
JUMP = 10.0
#: Iterations of a step after which each contact node is held to the face it touches
#: then, for the rest of the step: a node's nearest face can flip between two from one
#: iterate to the next (where three leaflets meet), and the residual with it for as long
#: as the iterations run. Converged so, the faces are searched again: the step is done
#: unless a node has come to touch a face it did not (then it goes on with those).
PAIRS_HELD_AFTER = 4


@dataclass
class NewtonStep:
    """A converged load step: the run's clock t at its end and the load time it reached
    (the same under load control), the iterations it took and the tangents it formed for
    them, the relative residual it ended with, and the tries cut back before it converged."""

    t: float
    load_time: float
    iterations: int
    tangents: int
    residual: float
    cutbacks: int


class NotConverged(Exception):
    """A load step that could not be solved, and why."""


class SingularTangent(NotConverged):
    """A tangent with no factors: formed at a converged state, no shorter step helps."""


class UnfactorisableTangent(SingularTangent):
    """A tangent whose factors do not fit the memory (:class:`shellsim.solver.sparse_lu.FactorsTooLarge`)."""


#: What to do about a tangent that is singular at a converged state.
SINGULAR_ADVICE = ("A node held by nothing in some direction (a slack cable's free end or joint, a node on no "
                   "element, a structure free to move as a whole) leaves the tangent singular where nothing is "
                   "stretched yet: hold it, give its cables a prestretch, or solve the scene explicitly "
                   "(solver.method = \"explicit\"), where its mass keeps it in place")
#: What to do about a tangent at a converged state that cannot be factorised in the memory.
UNFACTORISABLE_ADVICE = ("A coarser mesh, a machine with more memory, or the explicit method "
                         "(solver.method = \"explicit\") may get past it")


class NewtonSolver:
    """Load steps of a run (:class:`shellsim.solver.run.Run`) to equilibrium."""

    def __init__(self, run: Run, settings=None):
        self.run = run
        #: the steps' settings: ``[solver.static]``, or ``[solver.implicit]`` for time steps
        self.settings = settings or run.deck.solver.static
        self.eq = Equilibrium(run.sim)
        self.n_free = self.eq.unknowns.n_free
        self.last_residual = np.zeros(self.n_free)
        self.extent = float(np.abs(run.model.x0).max())
        #: (tangent, its free columns' LU, round-off floor) the iterations use, None until the first
        self.tangent = None
        self.work = StaticWork(self.eq)
        run.stability = self.stability = StabilityWatch()

    def round_off(self, tangent) -> float:
        """The residual's round-off floor at a tangent (n_free, size): machine epsilon times
        each free row's diagonal stiffness times the model's extent, over the free rows.
        The internal forces come from positions of that size, so a residual below it is
        noise (it is what a small load step near the start stalls at)."""
        return float(np.finfo(float).eps * self.extent * np.linalg.norm(self._free_diagonal(tangent)))

    def _free_diagonal(self, tangent) -> np.ndarray:
        """|K_ii| (n_free,) of a tangent (n_free, size): the free unknowns' own stiffnesses."""
        return np.abs(free_columns(tangent, self.n_free).diagonal())

    def free_residual(self) -> np.ndarray:
        """The residual over the free unknowns (n_free,) of the last evaluation, kept for a
        message; raises NotConverged when it is no longer a number."""
        residual = self.eq.residual()[:self.n_free]
        if not np.all(np.isfinite(residual)):
            raise NotConverged("the residual is no longer a number")
        self.last_residual = residual
        return residual

    def linearised(self, at_converged: bool = False):
        """(tangent (n_free, size), the LU factors of its free columns, its round-off
        floor) at the last evaluation; ``at_converged``: the evaluation is of the converged
        state, whose stability the factors' pivots are recorded as. Raises
        SingularTangent, naming the nodes with no stiffness, when it has no factors. The
        wall time of forming and factorising it is added to ``run.tangent_seconds``."""
        start = time.perf_counter()
        tangent = self.eq.tangent()
        try:
            lu = SymmetricPatternLU(free_columns(tangent, self.n_free))
        except FactorsTooLarge as error:
            raise UnfactorisableTangent(f"the tangent cannot be factorised here: {error}") from None
        except RuntimeError as error:  # "Factor is exactly singular"
            raise SingularTangent(f"the tangent stiffness is singular ({error}){self._stiffless(tangent)}") from None
        self.run.tangent_seconds.append(time.perf_counter() - start)
        if at_converged:
            self.stability.observe(self.eq.converged.t, self.run.load_time, lu.negative_pivots)
        return tangent, lu, self.round_off(tangent)

    def _stiffless(self, tangent) -> str:
        """The nodes a tangent (n_free, size) gives no stiffness in some free direction
        (a zero diagonal), for a message: '; nodes 12, 13 (the first at (0, 1, 2)) have no
        stiffness in some direction'; '' when there are none."""
        diagonal = self._free_diagonal(tangent)
        zero = diagonal <= 1e-14 * max(float(diagonal.max(initial=0.0)), 1e-300)
        if not zero.any():
            return ""
        marked = self.eq.unknowns.scatter(np.concatenate([zero, np.zeros(self.eq.unknowns.n_known)]))
        nodes = np.flatnonzero(marked.any(axis=1))
        return (f"; {len(nodes)} node(s) have no stiffness in some direction: nodes {id_list(nodes + 1)} (the first at "
                f"{place(self.run.mesh.x[nodes[0]])})")

    def at_converged(self, where: str, record: bool = True):
        """:meth:`linearised` at the converged state (its stability recorded unless not
        ``record``), ``where`` saying which for a message; NumericalError, with what to do,
        when it is singular: no shorter step gets past a tangent singular at the state
        every step starts from."""
        try:
            return self.linearised(at_converged=record)
        except SingularTangent as why:
            advice = UNFACTORISABLE_ADVICE if isinstance(why, UnfactorisableTangent) else SINGULAR_ADVICE
            raise NumericalError(not_converged(self.run, self, where, str(why), advice)) from None

    def observe(self) -> None:
        """Record the stability of the converged state: a tangent there, with its own load
        (a follower pressure's stiffness is the new load's at a step's first iterate), which
        modified Newton goes on with. Nothing in an implicit run: its tangents, with the mass
        term, are positive definite, and the first is formed at the first iteration."""
        if self.eq.inertia is not None:
            return
        self.eq.evaluate(self.run.load_time)
        self.tangent = None  # its factors go before the new ones are formed
        self.tangent = self.at_converged(f"at load time {self.run.load_time:.6g}, where the converged state's tangent "
                                         "is formed")

    def converged(self, norm: float, scale: float, energy: float, energy_scale: float, floor: float,
                  stalled: bool = False) -> bool:
        """Whether an iterate is in equilibrium: its residual ``norm`` within the force
        tolerance of ``scale`` and the ``energy`` of its next correction within the energy
        tolerance of ``energy_scale``, or the residual down to the round-off ``floor``. A
        residual within the force tolerance that a fresh tangent's correction no longer
        lowers (``stalled``) is at the internal forces' round-off: no iteration can meet
        the energy tolerance then, which a short step's small first correction sets (a
        tube inflated by 45% stalled at 6e-13 of its forces)."""
        settings = self.settings
        return norm <= floor or (norm <= settings.force_tolerance * scale
                                 and (stalled or energy <= settings.energy_tolerance * energy_scale))

    def step(self, t: float, line_search: bool = False) -> tuple[int, int, float]:
        """Equilibrium at load time t from the converged state; returns (iterations,
        tangents formed, relative residual). Raises NotConverged with the reason.
        ``line_search``: see :meth:`_line_search`.

        Full Newton forms the tangent at every iterate. Modified Newton keeps the last one
        (from earlier steps too) while each iteration leaves at most SLOW of the residual;
        when one leaves more it forms a new tangent there, or, when that iteration made the
        residual larger, goes back to the iterate before it and forms the tangent there."""
        if self.eq.inertia is not None and self.eq.inertia.to(t):
            self.tangent = None  # formed for another time step: its mass term is another
        # a wild iterate (an exponential law far out) has forces whose squares overflow: it is
        # no equilibrium, and is gone back from or cut back, so numpy need not warn of it
        with np.errstate(over="ignore", invalid="ignore"):
            try:
                return self._iterate(t, line_search)
            finally:
                hold_pairs(self.run.model, False)

    def _iterate(self, t: float, line_search: bool) -> tuple[int, int, float]:
        """:meth:`step`'s iterations."""
        eq, settings, n_free = self.eq, self.settings, self.n_free
        eq.evaluate(t)
        known = eq.prescribed_increments(t)
        pending = known  # the prescribed moves, made with the first correction
        first_energy, previous, before, tangents, fresh = None, np.inf, None, 0, False
        predicted = np.inf  # how far the first correction moved the nodes (JUMP's measure)
        held, hold_at = None, PAIRS_HELD_AFTER  # the contact pairs held (PAIRS_HELD_AFTER), and from when
        for iteration in range(settings.max_iterations + 1):
            if iteration == hold_at:
                hold_pairs(self.run.model, True)
                held = contact_pairs(self.run.model) or None  # None: the scene pairs nothing
            residual = self.free_residual()
            scale = eq.force_scale()
            norm = float(np.linalg.norm(residual))
            if iteration == 0:
                if not np.any(known) and norm <= settings.force_tolerance * scale:
                    return 0, 0, norm / max(scale, 1e-300)  # nothing changed (a held load)
                start_scale = scale if scale > 0.0 and not np.any(known) else np.inf  # RUNAWAY's measure
            else:
                # the energy of the next correction, with the last factorisation
                energy = abs(float(self.tangent[1].solve(residual) @ residual))
                stalled = fresh and norm > SLOW * previous
                ran_away = scale > RUNAWAY * start_scale
                converged = not ran_away and self.converged(norm, scale, energy, first_energy, self.tangent[2],
                                                            stalled)
                if converged and held is not None:  # search the faces again
                    hold_pairs(self.run.model, False)
                    eq.evaluate(t)
                    if pairs_added(self.run.model, held):  # new contacts: on with them, a new tangent
                        held, hold_at = None, iteration + PAIRS_HELD_AFTER
                        residual = self.free_residual()
                        norm, previous, before, self.tangent = float(np.linalg.norm(residual)), np.inf, None, None
                        converged = False
                if converged:
                    self.held_apart(t)
                    moved = self._moved()
                    if moved > JUMP * predicted and self.eq.inertia is None:
                        self.stability.jumped(self.eq.converged.t, self.run.load_time, t, moved / predicted)
                    return iteration, tangents, norm / max(scale, 1e-300)
            if iteration == settings.max_iterations:
                raise NotConverged(f"{iteration} iterations left a residual of {norm / max(scale, 1e-300):.3g} "
                                   "of the force scale" + (f", and forces {scale / start_scale:.3g} times those the "
                                                           "step started from" if ran_away else ""))
            fresh = self.tangent is None or settings.newton == "full" or norm > SLOW * previous
            if fresh:
                if before is not None and norm > previous:  # an old tangent led away: undo its correction
                    (before_state, pending, residual, norm) = before
                    before_state.restore(self.run.sim)
                    eq.evaluate(t)
                # the old factors go before the new are formed: together they would double the peak
                self.tangent = before = None
                self.tangent = self.linearised()
                tangents += 1
            # the iterate before the correction, kept only where it may be gone back to
            start = Converged(self.run.sim) if line_search or not fresh else None
            if not fresh:
                before = (start, pending, residual, norm)
            previous = norm
            # read through self.tangent, not held in names of this loop: those would keep the
            # factors alive past the next tangent's
            rhs = residual - self.tangent[0][:, n_free:] @ pending if np.any(pending) else residual
            correction = self.tangent[1].solve(rhs)
            if first_energy is None:
                first_energy = max(abs(float(correction @ rhs)), 1e-300)
            eq.move(np.concatenate([correction, pending]))
            if iteration == 0:
                predicted = max(self._moved(), 1e-300)
            eq.evaluate(t)
            if line_search and fresh and not np.any(pending):
                self._line_search(t, start, correction, norm)
            pending = np.zeros_like(known)
        raise AssertionError("unreachable")

    def _moved(self) -> float:
        """How far the nodes are from the converged state: the norm of their moves."""
        return float(np.linalg.norm(self.run.sim.state.x - self.eq.converged.arrays["x"]))

    def _step_or_search(self, t: float) -> tuple[int, int, float]:
        """:meth:`step` to t; when it fails, again from the same start with the line search.
        Only as a second try: where plain Newton converges the search can lead it astray
        (two contact scenes stalled with it at their first contact)."""
        try:
            return self.step(t)
        except NotConverged:
            self.back_to_converged()
            return self.step(t, line_search=True)

    def back_to_converged(self) -> None:
        """The last converged state again, and no tangent: one formed there may lie far
        from the path."""
        self.eq.converged.restore(self.run.sim)
        self.tangent = None

    def _line_search(self, t: float, start: Converged, correction: np.ndarray, norm: float) -> None:
        """After a fresh tangent's ``correction`` from ``start`` (residual ``norm``) made the
        residual larger, take half of it, a quarter, ... while that is so: where contact
        comes on or off, or a fibre family is recruited, the tangent at the start does not
        hold across the step, and the whole correction can overshoot to a state where every
        next one does too."""
        def residual_norm() -> float:
            return float(np.linalg.norm(self.eq.residual()[:self.n_free]))

        def moved_by(share: float) -> float:
            start.restore(self.run.sim)
            self.eq.move(np.concatenate([share * correction, np.zeros(self.eq.unknowns.n_known)]))
            self.eq.evaluate(t)
            return residual_norm()

        if residual_norm() <= norm:
            return
        for halvings in range(1, LINE_SEARCH_HALVINGS + 1):
            if moved_by(0.5 ** halvings) <= norm:
                return
        moved_by(1.0)  # no share lowers it: the whole correction, as without the search

    def held_apart(self, t: float) -> None:
        """Raises NotConverged when the equilibrium just found at load time t has contact
        surfaces passed through each other: it is no answer, and a shorter step may find
        the one that holds them apart."""
        why = passed_through(self.run.model, t, self.run.sim.state.fields.shape, self.eq.converged.arrays["x"])
        if why:
            raise NotConverged(why)

    def reach(self, landing: float, length: float) -> tuple[NewtonStep, float]:
        """A converged step from the state's t toward ``landing``, tried at ``length`` (or
        to ``landing`` when it is near: no sliver of a step is left) and cut back until it
        converges; returns the step and the length it was taken at. Raises NumericalError
        when the length falls below ``min_increment`` of the end time."""
        sim, end = self.run.sim, self.run.deck.solver.end_time
        cutbacks = 0
        while True:
            remaining = landing - sim.state.t
            target = landing if remaining <= 1.25 * length else sim.state.t + length
            try:
                iterations, tangents, residual = self._step_or_search(target)
                step = NewtonStep(t=target, load_time=target, iterations=iterations, tangents=tangents,
                                  residual=residual, cutbacks=cutbacks)
                return step, length
            except NotConverged as why:
                self.back_to_converged()
                cutbacks += 1
                length = min(length, remaining) * CUT
                if length < self.settings.min_increment * end:
                    where = (f"on the way from t = {sim.state.t:.6g} to t = {target:.6g} "
                             f"({100 * target / end:.3g}% of solver.end_time) even in steps of "
                             f"{self.settings.min_increment:g} of it")
                    raise NumericalError(not_converged(self.run, self, where, str(why))) from None

    def commit(self, step: NewtonStep) -> None:
        """The state is converged at ``step``'s end: steps now start from it."""
        self.run.sim.state.steps += 1
        if self.eq.inertia is not None:
            self.eq.inertia.commit()
        self.eq.converged = Converged(self.run.sim)
        self.run.newton.append(step)
        self.work.add_step()


def load_steps(run: Run, newton: NewtonSolver, listener: Listener, end: float) -> None:
    """Load control to ``end``: steps that land on every output time before it."""
    sim = run.sim
    largest = end / newton.settings.increments
    length = largest
    landings = output_times(run.deck)
    newton.observe()  # the first step's tangent, at the start
    observed = sim.state.t  # the load time of the last stability check
    uncut = 0  # steps in a row that converged at the length they were tried at
    for landing in np.append(landings[landings < end], end):
        while sim.state.t < landing - 1e-12 * end:
            step, length = newton.reach(landing, length)
            sim.state.t = step.t
            newton.commit(step)
            if newton.settings.check_stability and observed + largest * (1.0 - 1e-9) <= step.t < end * (1.0 - 1e-12):
                newton.observe()  # the end's is the run's last
                observed = step.t
            take_sample(run, listener)
            uncut = uncut + 1 if step.cutbacks == 0 else 0
            if step.cutbacks == 0 and (step.tangents <= GROWTH_TANGENTS or uncut >= 2):
                length, uncut = min(length * GROW, largest), 0
        take_frame(run, listener)


#: What may get a load-controlled static solve past where it stopped.
LOAD_ADVICE = ("If the load has reached the most the structure carries on this path (a limit point, where "
               "more load steps stop at the same load), solver.static.control = \"arc_length\" follows the "
               "path over it; otherwise a smaller solver.static.min_increment, or the explicit method, may help")
#: What may get an implicit time step past where it stopped.
IMPLICIT_ADVICE = ("A smaller solver.implicit.min_increment, more numerical damping (solver.implicit.alpha "
                   "toward -1/3), or the explicit method past this point may help")
#: What may get an arc-length solve past where it stopped.
ARC_ADVICE = ("More solver.static.increments (a shorter first arc) or the explicit method past this point "
              "may help")


def not_converged(run: Run, newton: NewtonSolver, where: str, why: str, advice: str | None = None) -> str:
    """The message of a step that cannot be solved: ``where`` in the load, why, the node
    with the largest residual force and its place, any folded element, and ``advice``
    (by default what may help load control, or an implicit run's time steps)."""
    s = run.sim.state
    implicit = run.deck.solver.method == "implicit"
    if advice is None:
        advice = IMPLICIT_ADVICE if implicit else LOAD_ADVICE
    message = f"the {'implicit time step' if implicit else 'static solve'} did not converge {where}: {why}"
    local = newton.eq.unknowns.scatter(np.concatenate([newton.last_residual, np.zeros(newton.eq.unknowns.n_known)]))
    per_node = np.linalg.norm(local, axis=1)
    if per_node.max() > 0:
        node = int(np.argmax(per_node))
        x = run.mesh.x[node]
        message += f"; the largest residual force is at node {node + 1} ({x[0]:.4g}, {x[1]:.4g}, {x[2]:.4g})"
    folding = folding_diagnosis(run.quality.ratios(s.x, s.d, s.h), run.mesh.x, run.mesh.conn)
    if folding:
        message += f"; {folding}"
    return f"{message}. {advice}"
