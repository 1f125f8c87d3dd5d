"""Running a scene: the time step schedule, history sampling, stability watch, and the
events that writers and the progress display listen to.

The solver knows nothing about files: it calls ``listener.on_sample(run)`` at every
history time, ``listener.on_frame(run)`` at t = 0 and at every output time, and
``listener.on_dt(run)`` after each critical-step estimate.
"""

from __future__ import annotations

import math
import signal
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..deck import Deck
from ..errors import NumericalError, OutputError, SceneTooLarge, place
from ..loads import calibrate, contact_of_node, needs_calibration, stable_step, step_share
from ..mesh import Mesh
from ..model import Model
from ..measures import Measure, resolve_measures
from .relaxation import Relaxing
from ..signals import STOP_SIGNALS, handling, noting_stops
from .explicit import DAMPED, EXTERNAL, FRICTION, INTERNAL, KINETIC, equal_step
from .outlook import refuse_if_hopeless, time_step
from .quality import ElementQuality, Worst, folding_diagnosis, step_history
from .simulation import Simulation
from .timestep import EstimateSchedule, massless_nodes

#: History samples over a run (fewer when the run has fewer steps).
HISTORY_SAMPLES = 2000
#: Energy balance error (share of the largest energy) beyond which a run is unstable.
UNSTABLE_BALANCE = 0.5
#: Energies below this share of the external work are round-off, not a balance to judge.
ENERGY_FLOOR = 1e-12
#: Nor are energies below this share of the structure's own scale, its mass times the
#: square of its size over the critical step (more than a unit strain's energy): a scene
#: that waits unloaded moves by round-off alone, with no external work to measure it by.
ROUND_OFF = 1e-20


@dataclass
class Stepping:
    """When the time loop estimates the critical step next: ``interval`` steps after the
    last estimate, ``since_update`` of them taken (:class:`.timestep.EstimateSchedule`)."""

    schedule: EstimateSchedule
    interval: int
    since_update: int = 0


@dataclass
class Run:
    """A scene being run: the simulation, its time step record and measured histories."""

    deck: Deck
    mesh: Mesh
    model: Model
    sim: Simulation
    measures: list[Measure] = field(default_factory=list)  # what the history samples, in column order
    dt: float = 0.0
    dt_critical: float = 0.0
    dt_history: list[tuple[float, float, float]] = field(default_factory=list)  # (t, dt_crit, dt)
    times: list[float] = field(default_factory=list)
    history: dict[str, list[float]] = field(default_factory=dict)
    energies: list[np.ndarray] = field(default_factory=list)
    frame_times: list[float] = field(default_factory=list)
    wall_time: float = 0.0
    status: str = "running"
    startup: dict[str, float] = field(default_factory=dict)  # fixed costs before stepping [s]
    quality: ElementQuality | None = None
    ratios: np.ndarray | None = None  # each element's Jacobian ratio at the last step update
    worst: Worst | None = None  # the worst element at the last step update
    lowest: Worst | None = None  # the worst element seen over the run
    breaking_frame: float | None = None  # time of the frame written as the run broke down
    newton: list = field(default_factory=list)  # a static solve's converged load steps (static.NewtonStep)
    tangent_seconds: list[float] = field(default_factory=list)  # each tangent a Newton path formed and factorised [s]
    stability: object | None = None  # a static solve's watch of its tangent's pivots (stability.StabilityWatch)
    relaxing: Relaxing | None = None  # a dynamic relaxation's watch for rest
    unloading: object | None = None  # finding an imaged scene's unloaded shape (unloaded.Unloading)
    stepping: Stepping | None = None  # the time loop's place between step estimates, once it has begun
    mass_rescalings: int = 0  # the masses scaled again during the run (mass scaling throughout)

    @property
    def load_time(self) -> float:
        """The time the loads read their curves at: the clock, but for an arc-length path
        (:mod:`shellsim.solver.arc_length`) the load time its last step reached."""
        return self.newton[-1].load_time if self.newton else self.sim.state.t

    def measure(self, name: str) -> Measure | None:
        """The measure of the family called ``name`` (its NAME) that the run samples; None: none."""
        return next((measure for measure in self.measures if measure.NAME == name), None)

    @property
    def balance_error(self) -> float:
        """(internal + kinetic + damping + friction - external) energy now."""
        e = self.sim.state.energy
        return float(e[INTERNAL] + e[KINETIC] + e[DAMPED] + e[FRICTION] - e[EXTERNAL])

    @cached_property
    def size(self) -> float:
        """The model's largest extent along an axis, initially."""
        return float(np.ptp(self.model.x0, axis=0).max())

    def balance_share(self) -> float | None:
        """The balance error over the energies' scale (the external work or what the
        structure holds and has lost, the larger); None while the energies are round-off:
        below ENERGY_FLOOR of the external work, or ROUND_OFF of the structure's own scale
        (its mass times the square of its size over the critical step)."""
        s, e = self.sim.state, self.sim.state.energy
        scale = max(abs(e[EXTERNAL]), e[INTERNAL] + e[KINETIC] + e[DAMPED] + abs(e[FRICTION]))
        noise = ROUND_OFF * float(s.mt.sum()) * (self.size / self.dt_critical) ** 2 if self.dt_critical > 0.0 else 0.0
        if not scale > max(ENERGY_FLOOR * abs(e[EXTERNAL]), noise):
            return None
        return self.balance_error / scale


class Listener:
    """Receives run events; subclasses override what they need."""

    def on_dt(self, run: Run) -> None:
        pass

    def on_sample(self, run: Run) -> None:
        pass

    def on_frame(self, run: Run) -> None:
        pass


class Listeners(Listener):
    """Passes every event to each of several listeners, in order."""

    def __init__(self, *listeners: Listener):
        self.listeners = listeners

    def on_dt(self, run: Run) -> None:
        for listener in self.listeners:
            listener.on_dt(run)

    def on_sample(self, run: Run) -> None:
        for listener in self.listeners:
            listener.on_sample(run)

    def on_frame(self, run: Run) -> None:
        for listener in self.listeners:
            listener.on_frame(run)


class Stopwatch:
    """Seconds between successive :meth:`lap` calls (the first from its creation)."""

    def __init__(self):
        self._last = time.perf_counter()

    def lap(self) -> float:
        now = time.perf_counter()
        elapsed, self._last = now - self._last, now
        return elapsed


class Timed(Listener):
    """Passes every event to ``listener`` and adds up the wall time it takes [s]."""

    def __init__(self, listener: Listener):
        self.listener = listener
        self.seconds = 0.0

    def _timed(self, event, run: Run) -> None:
        start = time.perf_counter()
        try:
            event(run)
        finally:
            self.seconds += time.perf_counter() - start

    def on_dt(self, run: Run) -> None:
        self._timed(self.listener.on_dt, run)

    def on_sample(self, run: Run) -> None:
        self._timed(self.listener.on_sample, run)

    def on_frame(self, run: Run) -> None:
        self._timed(self.listener.on_frame, run)


def prepare(deck: Deck, mesh: Mesh, model: Model) -> Run:
    """A run ready to start: simulation built, penalty springs set from the masses and the
    structure's critical step (:func:`shellsim.loads.calibrate`), and the measures the
    deck asks for placed on the scene (:mod:`.measures`)."""
    run = Run(deck=deck, mesh=mesh, model=model, sim=Simulation(model, static=deck.solver.method != "explicit"),
              quality=ElementQuality(mesh))
    if needs_calibration(model):
        s = run.sim.state
        calibrate(model, s.mt, s.mr, springs_step(deck, model, run.sim.critical_time_step()))
        run.sim.evaluate_forces()  # the springs act from the start
    run.measures = resolve_measures(deck, mesh, model)
    run.history = {column: [] for measure in run.measures for column in measure.columns}
    if deck.solver.relaxation is not None:
        run.relaxing = Relaxing(run, deck.solver.relaxation.residual)
    return run


def output_times(deck: Deck) -> np.ndarray:
    """Times the run lands on exactly: every output interval, the deck's output times and
    the end time."""
    end = deck.solver.end_time
    out = deck.output
    marks = np.asarray([t for t in out.times or () if 0.0 < t <= end])
    if out.interval is not None:
        marks = np.append(marks, np.arange(out.interval, end, out.interval))
    times = np.unique(np.append(marks, end))
    return times[times > 0.0]


def take_sample(run: Run, listener: Listener) -> None:
    """A history sample now: the time, every measure's columns, the energies; then
    ``listener.on_sample``."""
    run.times.append(run.sim.state.t)
    for measure in run.measures:
        for column, value in zip(measure.columns, measure.sample(run), strict=True):
            run.history[column].append(value)
    run.energies.append(run.sim.state.energy.copy())
    listener.on_sample(run)


@contextmanager
def interrupt_deferred() -> Iterator[None]:
    """Hold a stop signal that arrives inside the block until the block is done, then
    deliver it to its own handler, so a frame is written to every series and counted, or
    not at all."""
    held = []
    with handling(dict.fromkeys(STOP_SIGNALS, lambda number, _: held.append(number))):
        yield
    for number in dict.fromkeys(held):
        signal.raise_signal(number)


def take_frame(run: Run, listener: Listener) -> None:
    """A frame now (``listener.on_frame``), counted once written: a stop signal waits
    for it."""
    with interrupt_deferred():
        listener.on_frame(run)
        run.frame_times.append(run.sim.state.t)


def _watch_quality(run: Run) -> None:
    """Each element's Jacobian ratio now, the worst now and the worst seen into ``run``."""
    s = run.sim.state
    run.ratios = run.quality.ratios(s.x, s.d, s.h)
    run.worst = run.quality.worst(s.t, run.ratios)
    if run.lowest is None or run.worst.ratio < run.lowest.ratio:
        run.lowest = run.worst


def update_time_step(run: Run, listener: Listener) -> float:
    """The masses and the critical step (``run.dt_critical``) and step (``run.dt``) on the
    current shape; returns the shell structure's own critical step."""
    _watch_quality(run)
    run.sim.update_masses()
    structure = run.sim.critical_time_step()
    run.dt_critical = stable_step(run.model, run.sim.state.fields.shape, structure, run.sim.mass_factor)
    run.dt = time_step(run.deck.solver, run.dt_critical)
    run.dt_history.append((run.sim.state.t, run.dt_critical, run.dt))
    listener.on_dt(run)
    return structure


def _unscaled_critical(run: Run) -> float:
    """The critical step of the structure's own masses: how fast it changes tells when to
    estimate it again, which a rescaling of the masses (mass scaling throughout) does not."""
    return run.dt_critical / math.sqrt(run.sim.mass_factor)


def _hold_scaled_step(run: Run) -> None:
    """Mass scaling throughout: a later estimate's step ``run.dt`` shorter than the deck's
    target is brought back to it, every mass times (target / step)^2 (within
    MOST_MASS_FACTOR in all). A uniform factor multiplies every period alike, so the
    critical step follows exactly, without another estimate (a second entry in the step
    history at the same time); the velocities are divided by the factor's square root,
    which keeps the kinetic energy, so nothing enters the balance, but for those of
    prescribed translations, which the supports keep (the energy that brings the added
    mass to their speed counted as their work). The penalty springs keep the stiffness
    they were set to (their rate s / dt^2 and the masses they were set on stay together):
    set again on a stiffer structure's step they would store energy from nowhere wherever
    they are pressed, and on heavier nodes they stay stable."""
    scaling = run.deck.solver.mass_scaling
    if scaling is None or not scaling.throughout or run.dt >= scaling.step:
        return
    factor = min((scaling.step / run.dt) ** 2, MOST_MASS_FACTOR / run.sim.mass_factor)
    if factor <= 1.0:
        return
    sim, s = run.sim, run.sim.state
    sim.mass_factor *= factor
    for mass in (s.mt, s.mr):
        mass *= factor
    prescribed = run.model.constraints.prescribed
    imposed = s.v[prescribed.nodes, prescribed.axes]  # the supports' speeds, kept
    for velocity in (s.v, s.w):
        velocity /= math.sqrt(factor)
    s.v[prescribed.nodes, prescribed.axes] = imposed
    # a support brings its node's added mass up to its own speed: that kinetic energy is its work
    s.work[EXTERNAL] += 0.5 * (1.0 - 1.0 / factor) * float(s.mt[prescribed.nodes] @ imposed ** 2)
    run.dt_critical *= math.sqrt(factor)
    run.dt = time_step(run.deck.solver, run.dt_critical)
    run.dt_history.append((s.t, run.dt_critical, run.dt))
    run.mass_rescalings += 1


#: Mass scaling beyond this factor (a step a thousand times the stable one) is refused:
#: the run would follow the dynamics of another, far heavier structure.
MOST_MASS_FACTOR = 1e6


def _scale_masses(run: Run, listener: Listener) -> None:
    """Mass scaling: when the first step is shorter than the deck's target, every mass
    times (target / step)^2 and the step estimated again (a second entry at t = 0), the
    penalty springs calibrated again on the scaled masses and step (the same stiffness;
    friction's sticking impulse then the scaled nodes').
    Raises SceneTooLarge (the run refused) for a factor beyond MOST_MASS_FACTOR."""
    scaling = run.deck.solver.mass_scaling
    if scaling is None or run.dt >= scaling.step:
        return
    factor = (scaling.step / run.dt) ** 2
    if factor > MOST_MASS_FACTOR:
        raise SceneTooLarge(f"solver.mass_scaling.step = {scaling.step:g} is {scaling.step / run.dt:.3g} times the "
                            f"stable step {run.dt:.3g}: every mass would be multiplied by {factor:.3g}, more than "
                            f"{MOST_MASS_FACTOR:g}, and the run would follow another, far heavier structure; ask "
                            f"for a step of at most {run.dt * MOST_MASS_FACTOR ** 0.5:.3g}")
    run.sim.mass_factor = factor
    structure = update_time_step(run, listener)
    if needs_calibration(run.model):  # the penalties' step and the contact nodes' masses are the scaled ones
        s = run.sim.state
        calibrate(run.model, s.mt, s.mr, springs_step(run.deck, run.model, structure))


def springs_step(deck: Deck, model: Model, structure: float) -> float:
    """The critical step the penalty springs are set on (:func:`shellsim.loads.calibrate`):
    the structure's, ``structure``, or, where the deck's ``solver.dt_max`` holds the step
    below the one the springs' share of it leaves stable, the critical step that step
    stands for (dt_max x dt_safety_factor / share): springs as much stiffer as the shorter
    step bears, with the same margin. Soft leaflets have a long step at rest; springs set
    on it let the leaflets pressed together at full pressure sink into each other."""
    solver = deck.solver
    if solver.method != "explicit" or solver.dt_max is None:
        return structure
    return min(structure, solver.dt_max * solver.dt_safety_factor / step_share(model))


def check_unstable(run: Run) -> None:
    """Raise NumericalError when the state is no number or the energy balance is off by
    more than UNSTABLE_BALANCE of the energies' scale."""
    s = run.sim.state
    e = s.energy
    broken = not (np.isfinite(s.x).all() and np.isfinite(e).all())
    if not broken:
        share = run.balance_share()
        broken = share is not None and share > UNSTABLE_BALANCE
    if broken:
        raise NumericalError(
            f"the run became unstable at t = {s.t:.6g} after {s.steps} steps: energy is being "
            f"created (balance error {run.balance_error:.3g}, energies {e.round(6).tolist()})")


def _breakdown_cause(run: Run) -> str:
    """Why the run broke down: the crushed or folded elements and where they are if the
    mesh has given way (its state now, watched as at a step update, or at the last step
    update if now is no number),
    else the time step; and how the critical step moved just before."""
    s = run.sim.state
    if np.isfinite(s.x).all() and np.isfinite(s.d).all() and np.isfinite(s.h).all():
        _watch_quality(run)
    ratios = run.ratios
    folding = (folding_diagnosis(ratios, run.mesh.x, run.mesh.conn, massless_nodes(s.mt, s.mr))
               if ratios is not None else None)
    # a step above the critical one wrecks every shape too: then the step is named as well
    step = _time_step_hint(run) if not folding or run.deck.solver.dt_safety_factor < 1 else ""
    return (f"; {folding}" if folding else "") + _where_it_broke(run) + step + step_history(run.dt_history)


def _where_it_broke(run: Run) -> str:
    """Where the motion broke down: the nodes whose position or velocity is no longer a
    number (how many, and where the first was at rest), else the fastest node; whether it
    is a cable's node or a contact node touching a face. '' where nothing moves."""
    s, model = run.sim.state, run.model
    lost = ~(np.isfinite(s.x).all(axis=1) & np.isfinite(s.v).all(axis=1))
    if lost.any():
        nodes = np.flatnonzero(lost)
        node, what = int(nodes[0]), f"{len(nodes)} node(s) no longer have a number for a position or velocity"
    else:
        speed = np.linalg.norm(s.v, axis=1)
        node = int(np.argmax(speed))
        if speed[node] == 0.0:
            return ""
        what = f"the fastest node moves at {speed[node]:.3g}"
    on_shell = bool(np.any(model.conn == node))
    return (f"; {what}: node {node + 1}, at {place(model.x0[node])} at rest"
            + ("" if on_shell else ", on a cable alone") + contact_of_node(model, node))


def _breaking_frame(run: Run, listener: Listener) -> None:
    """The state the run broke down in, as a last frame, when it is still a shape (finite
    positions); the frames before it are the last good ones."""
    s = run.sim.state
    if run.frame_times and run.frame_times[-1] == s.t or not np.isfinite(s.x).all():
        return
    with suppress(OutputError):  # the breakdown is the news; the summary still records it
        take_frame(run, listener)
        run.breaking_frame = s.t


def _time_step_hint(run: Run) -> str:
    """What the time step was, and what to change."""
    factor = run.deck.solver.dt_safety_factor
    advice = (f"solver.dt_safety_factor = {factor} < 1 puts the step above the critical step"
              if factor < 1 else "a larger solver.dt_safety_factor or a smaller dt_update_every may help")
    return f"; time step {run.dt:.4g}, critical step {run.dt_critical:.4g}; {advice}"


def integrate(run: Run, listener: Listener | None = None) -> Run:
    """Integrate the scene from its state's time (0, or the end of a preload) to the
    deck's end time, or, relaxing (``[solver.relaxation]``), until it comes to rest.

    Raises SceneTooLarge (status 'refused') when its steps would take longer than anyone
    waits, before the first sample; NumericalError when the run goes unstable (the samples recorded until then stay
    in ``run``), or relaxing does not come to rest by the end time (status 'not converged');
    KeyboardInterrupt passes through with ``run.status = 'interrupted'``.
    """
    listener = listener or Listener()
    solver = run.deck.solver
    sim = run.sim
    with ending(run, listener, "unstable", _breakdown_cause) as start:
        if run.stepping is None:  # else it goes on from a checkpoint
            update_time_step(run, listener)
            _scale_masses(run, listener)
            refuse_if_hopeless(run.deck, run.model.n_elements, run.dt)
            run.startup["first_dt_s"] = time.perf_counter() - start
            if not run.times:  # else it continues a preload, whose last state is recorded
                take_sample(run, listener)
                take_frame(run, listener)
            schedule = EstimateSchedule(solver.dt_safety_factor, solver.dt_update_every)
            run.stepping = Stepping(schedule, schedule.after_estimate(sim.state.steps, _unscaled_critical(run)))
        stepping = run.stepping
        history_interval = solver.end_time / HISTORY_SAMPLES
        landings = output_times(run.deck)
        at_rest = False
        for landing in landings[landings > sim.state.t]:
            while sim.state.t < landing and not at_rest:
                # equal steps up to the next output time, history samples on whole steps
                step = equal_step(landing - sim.state.t, run.dt)
                target = min(landing, sim.state.t + max(1, round(history_interval / step)) * step)
                while sim.state.t < target:
                    steps = sim.advance(target, step, stepping.interval - stepping.since_update)
                    stepping.since_update += steps
                    if stepping.since_update >= stepping.interval:
                        update_time_step(run, listener)
                        _hold_scaled_step(run)
                        stepping.interval = stepping.schedule.after_estimate(sim.state.steps, _unscaled_critical(run))
                        stepping.since_update = 0
                        break  # re-plan the steps with the new dt
                take_sample(run, listener)
                check_unstable(run)
                at_rest = run.relaxing is not None and run.relaxing.at_rest(sim)
            take_frame(run, listener)
            if at_rest:
                break
    if run.relaxing is not None and not at_rest:  # the answer asked for is the state of rest
        run.status = "not converged"
        residual = run.relaxing.residual
        raise NumericalError(
            f"the relaxation did not come to rest by solver.end_time = {solver.end_time:g}: "
            + (f"its residual force is {residual:.3g} of the force scale, above solver.relaxation.residual = "
               f"{run.relaxing.tolerance:g}" if residual is not None else "its loads' curves had not yet held")
            + "; a later end time, or a looser residual, lets it settle")
    return run


@contextmanager
def ending(run: Run, listener: Listener, broken: str, cause: Callable[[Run], str] = lambda run: "") -> Iterator[float]:
    """The block solves ``run`` (yielding its start time): its status as it ends
    ('completed'; 'refused', SceneTooLarge; ``broken``, NumericalError, whose message gains
    ``cause(run)`` after the breaking state is kept as a frame; 'interrupted',
    KeyboardInterrupt, each raised on) and its wall time, however it ends. Any other error
    raised after a stop signal arrived is that stop, and is raised as the stop again."""
    start = time.perf_counter()
    try:
        with noting_stops() as stops:
            yield start
        run.status = "completed"
    except SceneTooLarge:
        run.status = "refused"
        raise
    except NumericalError as error:
        run.status = broken
        _breaking_frame(run, listener)
        raise NumericalError(f"{error}{cause(run)}") from None
    except KeyboardInterrupt:
        run.status = "interrupted"
        raise
    except Exception:
        if not stops:
            raise
        run.status = "interrupted"
        signal.raise_signal(stops[-1])  # its handler raises the stop's own exception
        raise
    finally:
        run.wall_time += time.perf_counter() - start  # a preloaded run's phases add up


def dt_statistics(run: Run) -> dict:
    """Minimum, mean and maximum step over the run, and the critical-step record."""
    steps = max(run.sim.state.steps, 1)
    dts = [dt for _, _, dt in run.dt_history] or [math.nan]
    return {"min": min(dts), "mean": run.sim.state.t / steps, "max": max(dts),
            "critical_min": min((c for _, c, _ in run.dt_history), default=math.nan),
            "updates": len(run.dt_history)}
