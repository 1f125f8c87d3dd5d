"""What a scene will cost before it runs: memory, the critical step, the number of steps
and the wall time they take; a scene that cannot fit in memory or finish in a year is
refused with the numbers that say why.

A forecast times the scene itself (docs/verification.md, "Cost of a scene"): the explicit
loop's parts on the prepared scene at rest, counted as the loop will take them with the
step following the loads (:mod:`.rehearsal`); a Newton path's own solve, rehearsed. Only
refusing a hopeless scene, before anything is built, goes by a rate: one step of a group
of 16 elements takes about 130 us on one thread on this project's reference machine. The
memory a run holds is :mod:`shellsim.memory`'s.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from contextlib import suppress
from typing import TYPE_CHECKING

import numpy as np
from numba import get_num_threads

from ..bundles import Shape
from ..curve_tables import held_from
from ..deck import Deck
from ..deck.schema import Solver
from ..element.groups import group_count
from ..errors import SceneTooLarge
from ..memory import memory_bytes
from ..mesh import Mesh
from ..model import Model
from ..loads import ToolForces, stable_step
from .equilibrium import warmed
from .simulation import Simulation
from .sparse_lu import SymmetricPatternLU
from .tangent_pattern import free_columns
from .rehearsal import REHEARSAL_ELEMENTS, REHEARSAL_SECONDS, critical_steps_under_load, newton_rehearsal
from .timestep import MARGIN_SHARE, EstimateSchedule

if TYPE_CHECKING:
    from .run import Run

SECONDS_PER_GROUP_STEP = 130e-6
#: A run longer than this is not one anybody will wait for: it is refused.
HOPELESS_SECONDS = 365 * 24 * 3600.0


def seconds_per_step(n_elements: int) -> float:
    """About how long one explicit step takes on this machine's threads [s]."""
    groups = group_count(n_elements)
    return SECONDS_PER_GROUP_STEP * groups / min(groups, max(1, get_num_threads()))


def stepping(end_time: float, dt: float, n_elements: int) -> tuple[float, float]:
    """(steps, seconds): how many steps of ``dt`` reach ``end_time`` and about how long they
    take at SECONDS_PER_GROUP_STEP (a bound for refusing a hopeless scene; a forecast
    times the scene itself, :func:`forecast`)."""
    steps = min(end_time / dt, 1e300)
    return steps, steps * seconds_per_step(n_elements)


def contact_seconds(model: Model, t: float, shape: Shape) -> float:
    """The wall time [s] of every contact's forces (the search included) at time t on
    ``shape``, as a time step evaluates them: 0 without contact. On the synthetic
    tricuspid valve (8,100 shells) 10 ms at rest against 33 ms of the shells' own step; it
    grows as contact spreads."""
    forces = ToolForces(model, [])
    return forces.seconds_per_evaluation(t, shape, repeats=3) if forces.has_contact else 0.0


def time_step(solver: Solver, dt_critical: float) -> float:
    """The step a run takes at a critical step: divided by the safety factor, at most dt_max."""
    dt = dt_critical / solver.dt_safety_factor
    return dt if solver.dt_max is None else min(dt, solver.dt_max)


#: Wall time [s] the timing of a scene's own steps may take, and the fewest steps it times.
TIMING_SECONDS, TIMED_STEPS = 0.3, 20


def loop_costs(run: Run, dt: float, mass_factor: float = 1.0) -> dict:
    """The wall times [s] of the time loop's parts, timed on the prepared ``run``
    (:func:`shellsim.solver.run.prepare`) at rest, every mass times ``mass_factor``:
    ``step``, one step of the compiled loop at ``dt`` (TIMED_STEPS steps a call for
    TIMING_SECONDS); ``call``, what each return to Python adds (a single-step call's
    time less a step); ``sample``, a history sample and the stability check after it;
    ``estimate``, a warm critical-step estimate with the masses and the element quality
    it updates. Small scenes are bound by these and not by their elements: on 2 to 19
    elements the shipped decks took 160 to 980 us a step where a rate per element said
    130."""
    from .run import Listener, check_unstable, update_time_step, take_sample

    sim, quiet = run.sim, Listener()
    sim.mass_factor = mass_factor
    update_time_step(run, quiet)
    estimate = quickest(lambda: update_time_step(run, quiet), 1)
    run.dt = dt
    sample = quickest(lambda: (take_sample(run, quiet), check_unstable(run)), 3)
    end = run.deck.solver.end_time  # a finite stop: toward an infinite one each step took 50 times as long
    sim.advance(end, dt, 2)  # the first call may load the kernels
    steps, start = 0, time.perf_counter()
    while steps < TIMED_STEPS or time.perf_counter() - start < TIMING_SECONDS and steps < 100 * TIMED_STEPS:
        taken = sim.advance(end, dt, TIMED_STEPS)
        if not taken:  # at the end already (a scene of a few steps)
            break
        steps += taken
    step = (time.perf_counter() - start) / steps if steps else 0.0
    single = quickest(lambda: sim.advance(end, dt, 1), 5)
    return {"step": step, "call": max(single - step, 0.0), "sample": sample, "estimate": estimate}


def explicit_schedule(deck: Deck, times: np.ndarray, dts: np.ndarray, until: float | None = None) -> dict:
    """How the time loop will take the deck to ``until`` (its end time by default) with
    the step ``dts`` (k,) at ``times`` (k,) (linear between, held beyond): ``steps``, equal
    steps landing on every output time (a landing 1.4 steps on takes 2); ``samples``, the
    history samples on whole steps between landings; ``estimates``, the critical-step
    estimates after the first, as :class:`~.timestep.EstimateSchedule` spaces them: from
    FIRST steps, doubling to ``solver.dt_update_every`` while the step holds, closer where
    it changes."""
    from .run import HISTORY_SAMPLES, output_times

    solver = deck.solver
    end = solver.end_time if until is None else min(until, solver.end_time)
    landings = output_times(deck)
    landings = np.append(landings[landings < end], end)
    grid = np.unique(np.concatenate([np.linspace(0.0, end, 4001), landings, times]))
    grid = grid[(grid <= end) & (np.diff(grid, prepend=-np.inf) > 1e-9 * end)]
    step = np.interp(grid, times, dts)
    taken = np.concatenate([[0.0], np.cumsum(np.diff(grid) * 0.5 * (1.0 / step[1:] + 1.0 / step[:-1]))])
    # equal steps to each landing, rounded up as :func:`.explicit.equal_step` rounds them
    per_segment = np.maximum(1.0, np.ceil(np.diff(np.interp(landings, grid, taken), prepend=0.0) - 1e-9))
    segments = np.diff(landings, prepend=0.0)
    per_sample = np.maximum(1.0, np.round(solver.end_time / HISTORY_SAMPLES / (segments / per_segment)))
    between = np.abs(np.diff(np.log(step))) / np.diff(taken)  # the change of ln(step) per step
    change = np.maximum(np.append(between, 0.0), np.insert(between, 0, 0.0))  # at each point, either side's
    margin = MARGIN_SHARE * math.log(solver.dt_safety_factor) if solver.dt_safety_factor > 1.0 else 0.0
    estimates = _estimate_count(taken, change, margin, solver.dt_update_every)
    return {"steps": int(per_segment.sum()), "samples": int(np.ceil(per_segment / per_sample).sum()),
            "estimates": estimates}


#: Estimates the walk of :func:`_estimate_count` counts one by one before it extrapolates.
WALK_LIMIT = 100_000


def _estimate_count(taken: np.ndarray, change: np.ndarray, margin: float, most: int) -> int:
    """The estimates after the first that :class:`~.timestep.EstimateSchedule` makes over
    ``taken[-1]`` steps, ``taken`` (g,) the steps taken by each point of a time grid and
    ``change`` (g,) the change of ln(step) per step there: each interval at most
    ``margin`` over the fastest change of the last ``most`` steps, twice the one before and
    ``most``. Where no later change can shorten an interval of ``most``, the rest is
    counted at once (a hopeless scene's 10^20 steps)."""
    total = taken[-1]
    calm = margin / most if margin else math.inf  # a change this slow leaves the interval at most
    later = np.maximum.accumulate(change[::-1])[::-1]  # the fastest change from each point on
    estimates, interval, at = 0, min(EstimateSchedule.FIRST, most), 0.0
    while at + interval < total:
        at += interval
        estimates += 1
        first, last = np.searchsorted(taken, at - most), np.searchsorted(taken, at, side="right")
        if interval == most and later[min(first, len(later) - 1)] <= calm:
            return estimates + max(0, math.ceil((total - at) / most) - 1)
        if estimates >= WALK_LIMIT:
            return estimates + int((total - at) / (at / estimates))
        rate = float(change[first:last].max()) if last > first else float(np.interp(at, taken, change))
        proposed = margin / rate if margin and rate > 0.0 else math.inf
        interval = most if not margin else int(max(1, min(most, 2 * interval, proposed)))
    return estimates


def _scaled_step(solver: Solver, critical: float, mass_factor: float) -> float:
    """The step a run takes at the critical step ``critical`` of the unscaled masses, every
    mass times ``mass_factor``: scaled throughout, never below the scaling's target."""
    dt = time_step(solver, critical * math.sqrt(mass_factor))
    scaling = solver.mass_scaling
    return max(dt, scaling.step) if scaling is not None and scaling.throughout else dt


def step_outlook(deck: Deck, mesh: Mesh, model: Model, on_product: Callable[[int], None] | None = None,
                 announce: Callable[[str], None] = lambda text: None) -> dict:
    """What the run's time step will be, before it starts: the critical step at t = 0
    [time] with each lumping, ``{"M1": .., "M2": ..}``; ``dt``, the step the run takes
    first, with the deck's lumping and safety factor, or the mass scaling's target and
    ``mass_factor`` the masses' factor that reaches it (1 without); ``steps``, the number
    of steps that land on every output time ``until`` the end (a relaxation's until its
    curves hold, where it may first come to rest), the step following the critical
    step as the loads act (:func:`.rehearsal.critical_steps_under_load`, on scenes of up
    to REHEARSAL_ELEMENTS elements); ``loaded``, the lowest critical step found
    (``critical``), when (``at``), whether a rehearsal was ``tried`` and how far it went
    (``rehearsed_to``; None: not past the start); ``seconds``, about how long the first
    estimate and the time loop take (:func:`loop_costs` for :func:`explicit_schedule`),
    ``contact_share`` the contacts' share of a step (timed at rest), and ``bytes``, the
    memory the run holds.
    ``on_product(count)`` is told each stiffness product of the estimates, ``announce``
    each stage that follows them."""
    from .run import prepare

    initial = Shape(x=model.x0, d=model.d0, e1=model.e1f0, h=model.h0)
    critical, cold = {}, 0.0
    for mass in ("M1", "M2"):
        start = time.perf_counter()
        critical[mass] = stable_step(model, initial, Simulation(model._replace(mass=mass)).critical_time_step(on_product))
        if mass == deck.solver.mass:  # the run's own first estimate, cold
            cold = time.perf_counter() - start
    dt = time_step(deck.solver, critical[deck.solver.mass])
    scaling, mass_factor = deck.solver.mass_scaling, 1.0
    if scaling is not None and dt < scaling.step:  # every mass scaled, the step the target
        mass_factor, dt = (scaling.step / dt) ** 2, scaling.step
    contact = contact_seconds(model, 0.0, initial)
    lumped = model._replace(mass=deck.solver.mass)  # the deck's lumping, as the run's
    costs = loop_costs(prepare(deck, mesh, lumped), dt, mass_factor)
    times, under_load, loaded = _critical_under_load(deck, mesh, lumped, critical[deck.solver.mass], announce)
    # a relaxation ends at rest, once its curves hold: no sooner than that
    until = min(held_from(model.curves), deck.solver.end_time) if deck.solver.relaxation else deck.solver.end_time
    schedule = explicit_schedule(deck, times, np.array([_scaled_step(deck.solver, c, mass_factor) for c in under_load]),
                                 until)
    seconds = (cold + schedule["steps"] * costs["step"] + schedule["estimates"] * (costs["estimate"] + costs["call"])
               + schedule["samples"] * (costs["sample"] + costs["call"]))
    return critical | {"dt": dt, "mass_factor": mass_factor, "steps": schedule["steps"], "until": until,
                       "seconds": seconds, "loaded": loaded, "contact_share": contact / costs["step"],
                       "bytes": memory_bytes(model.n_elements, deck.solver.newton)}


def _critical_under_load(deck: Deck, mesh: Mesh, model: Model, at_rest: float,
                         announce: Callable[[str], None]) -> tuple[np.ndarray, np.ndarray, dict]:
    """(times (k,), critical (k,), loaded): the critical step as the loads act, from the
    static rehearsal on scenes of up to REHEARSAL_ELEMENTS elements, else ``at_rest`` at
    t = 0 alone; ``loaded`` as :func:`step_outlook` describes it."""
    times, critical = np.zeros(1), np.full(1, at_rest)
    tried = model.n_elements <= REHEARSAL_ELEMENTS
    if tried:
        announce(f"following the loads statically to foresee the step's fall (at most {REHEARSAL_SECONDS:g} s)")
        rehearsed = critical_steps_under_load(deck, mesh, model)
        if len(rehearsed[0]):  # else the static solve could not even start
            times, critical = rehearsed
    lowest = int(np.argmin(critical))
    return times, critical, {"critical": float(critical[lowest]), "at": float(times[lowest]), "tried": tried,
                             "rehearsed_to": float(times[-1]) if len(times) > 1 else None}


def newton_holds(model: Model) -> dict:
    """What a static or implicit solve of ``model`` holds: ``unknowns`` (5 DOF per node,
    supports' included) and ``bytes``."""
    return {"unknowns": 5 * model.n_nodes, "bytes": memory_bytes(model.n_elements, newton=True)}


def static_outlook(model: Model) -> dict:
    """What a static or implicit solve will hold (:func:`newton_holds`) and cost per
    tangent: ``residual_seconds`` to evaluate the residual once (an
    iteration's main cost), ``seconds`` to form a tangent at rest and factorise it
    on this machine's threads (timed: the rate per element said 0.056 s where the aortic
    valve's tangent and factors took 0.22 s, the follower pressure's and the contact's
    tangents and the factors left out)."""
    equilibrium = warmed(model)

    def factorised() -> None:
        tangent = equilibrium.tangent()
        with suppress(RuntimeError):  # singular at rest (a slack chord's nodes): the forming's time alone
            SymmetricPatternLU(free_columns(tangent, equilibrium.unknowns.n_free))

    return newton_holds(model) | {"seconds": quickest(factorised),
                                  "residual_seconds": quickest(lambda: equilibrium.evaluate(0.0))}


def quickest(work: Callable[[], None], repeats: int = 2) -> float:
    """The shortest wall time [s] of ``repeats`` calls of ``work``: the least disturbed."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return min(times)


#: Each Newton path's (iterations, tangents) per load or time step, as the shipped decks
#: took them (benchmarks/forecasts.py), every tangent formed counted: the stability
#: checks' and those of tries cut back too. Load control 3-15 iterations and 0.35-8
#: tangents (the hemisphere to the rolled-up strip), 8 and 1 taken: the carotid's 11.5
#: and 0.35, the one deck too large to rehearse to its end, are what a large scene's
#: modified Newton steps take; arc length 2.3-3.2 and 2.0-2.8 (the balloon, the hinged
#: roofs); implicit 11.2 and 5.1 (the aortic valve: 462 tangents formed in 91 steps, 317
#: of them in the tries that converged).
NEWTON_PACE = {"load": (8.0, 1.0), "arc_length": (3.0, 3.0), "implicit": (11.0, 5.1)}
#: Arc length takes about this many steps per output landing or first increment (the
#: hinged roofs 1.8 and 2.0, the balloon 4.1).
ARC_STEPS = 2.0
#: An iteration's own bookkeeping beyond its residual [s]: a 3-element cantilever's 31
#: iterations took 0.058 s.
ITERATION_SECONDS = 1.5e-3


def newton_path(deck: Deck) -> str:
    """The Newton path of a static or implicit deck: "load", "arc_length" or "implicit"."""
    return "implicit" if deck.solver.method == "implicit" else deck.solver.static.control


def newton_steps(deck: Deck) -> int:
    """About how many load or time steps a static or implicit solve takes: its
    ``increments`` first, and at least one to each output time it lands on; arc length
    ARC_STEPS times that."""
    from .run import output_times

    settings = deck.solver.implicit if deck.solver.method == "implicit" else deck.solver.static
    steps = max(settings.increments, len(output_times(deck)))
    return math.ceil(steps * (ARC_STEPS if newton_path(deck) == "arc_length" else 1.0))


def forecast(deck: Deck, mesh: Mesh, model: Model, on_product: Callable[[int], None] | None = None,
             announce: Callable[[str], None] = lambda text: None) -> dict:
    """What a run of ``deck`` on ``model`` will take: ``steps`` and ``seconds`` (and the
    outlook they come from: :func:`step_outlook`'s for the explicit path, :func:`newton_outlook`'s
    for a Newton path). The model's penalty springs are left set as a run's
    :func:`~.run.prepare` sets them."""
    if deck.solver.method == "explicit":
        return step_outlook(deck, mesh, model, on_product, announce)
    return newton_outlook(deck, mesh, model, announce)


def newton_outlook(deck: Deck, mesh: Mesh, model: Model, announce: Callable[[str], None] = lambda text: None) -> dict:
    """A static or implicit run's ``steps`` and ``seconds``, and what it holds
    (:func:`newton_holds`). On scenes of up to REHEARSAL_ELEMENTS elements the deck's own
    solve is rehearsed for REHEARSAL_SECONDS (:func:`.rehearsal.newton_rehearsal`): one
    that ends in that time is what the run takes (``rehearsed`` True; ``pace`` the
    iterations and tangents a step it took). Otherwise, with :func:`static_outlook`'s
    timings, a step to each output time (:func:`newton_steps`), each at NEWTON_PACE's
    iterations and tangents (``pace``); a tangent costs
    ``tangent_seconds``, what the rehearsal's took as the scene deformed (the valve's
    0.26 s against 0.15 s formed at rest), or one formed at rest and factorised where
    none was (``tangent_timed`` says which), and an iteration a residual timed at rest (``residual_seconds``) and
    ITERATION_SECONDS. The rehearsal's pace itself tells little of the rest: the
    carotid's first four steps took half its run's time, forming the tangents its
    modified Newton steps then keep."""
    rehearsed = {"tangent_seconds": None}
    if model.n_elements <= REHEARSAL_ELEMENTS:
        announce(f"rehearsing the solve (at most {REHEARSAL_SECONDS:g} s)")
        rehearsed = newton_rehearsal(deck, mesh, model)
        if rehearsed["finished"] and rehearsed["steps"]:
            steps = rehearsed["steps"]
            pace = (rehearsed["iterations"] / steps, rehearsed["tangents"] / steps)
            return newton_holds(model) | {"steps": steps, "seconds": rehearsed["seconds"], "pace": pace,
                                          "rehearsed": True}
    outlook = static_outlook(model)  # timed at rest only where the rehearsal did not tell it all
    tangent = rehearsed["tangent_seconds"] or outlook["seconds"]
    timed = "as the rehearsal's first steps formed them" if rehearsed["tangent_seconds"] else "formed at rest"
    steps = newton_steps(deck)
    iterations, tangents = pace = NEWTON_PACE[newton_path(deck)]
    per_step = tangents * tangent + iterations * (outlook["residual_seconds"] + ITERATION_SECONDS)
    return outlook | {"steps": steps, "seconds": steps * per_step, "tangent_seconds": tangent, "tangent_timed": timed,
                      "pace": pace, "rehearsed": False}


def refuse_if_hopeless(deck: Deck, n_elements: int, dt: float) -> None:
    """Raise SceneTooLarge when the steps of size ``dt`` to the end time would take longer
    than HOPELESS_SECONDS."""
    steps, seconds = stepping(deck.solver.end_time, dt, n_elements)
    if seconds > HOPELESS_SECONDS:
        raise SceneTooLarge(
            f"solver.end_time = {deck.solver.end_time:g} takes {steps:.3g} steps of {dt:.3g} (the critical step "
            f"of the mesh's stiffest element, divided by solver.dt_safety_factor): about {duration(seconds)} on "
            "this machine. Check the units of material.E, material.density and section.thickness against the "
            "geometry and the end time; a thin shell's critical step falls with its thickness")


def duration(seconds: float) -> str:
    """'3.2 s', '108 s', '14 min', '5.1 h', '2.3e+04 years'."""
    if seconds < 10:
        return f"{seconds:.2g} s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.2g} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.2g} h"
    if seconds < 365 * 86400:
        return f"{seconds / 86400:.2g} days"
    return f"{seconds / (365 * 86400):.3g} years"


