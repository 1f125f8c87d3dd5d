"""Progress of a run: a rich bar on a terminal (simulated time, the columns of the
solution path, the worst element's Jacobian ratio J/J0, the time left at the recent pace;
on a first run the kernel compiling and its clock), a line every tenth of the run
otherwise, nothing when quiet."""

from __future__ import annotations

import time

import numpy as np

from rich.console import Console
from rich.progress import BarColumn, Progress, ProgressColumn, TextColumn
from rich.text import Text

from ..compile_watch import FIRST_RUN_NOTE, finished_text
from ..printable import shown
from ..solver.run import Listener, Run


def _static(run: Run) -> bool:
    """Whether ``run`` is in a static solve: load steps taken, no time step estimated yet
    (a preloaded run's explicit phase has one)."""
    return bool(run.newton) and not run.dt


class _Clock(ProgressColumn):
    """The time left (the display's own forecast, ``left``); while a kernel compiles, how
    long it has compiled (ticking: the bar redraws itself)."""

    def render(self, task) -> Text:
        since = task.fields["compiling_since"]
        if since is None:
            return Text(task.fields["left"], style="progress.remaining")
        return Text(f"compiling {clock(int(time.perf_counter() - since))}", style="progress.elapsed")


def clock(seconds: float) -> str:
    """'0:42', '12:05', '3:02:10'."""
    minutes, seconds = divmod(int(round(seconds)), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes}:{seconds:02d}"


class Pace:
    """How fast a run goes lately: its samples' (wall clock, simulated time, steps) over
    the last WINDOW seconds of wall time (at least the last two), and from them the time
    left. Explicit: the steps still to take at the current step, each at the recent wall
    time per step, so the forecast follows a falling step at once. Newton steps (whose
    lengths vary): the simulated time still to go at the recent rates between samples,
    the middle half of them giving a range."""

    WINDOW = 30.0

    def __init__(self):
        self.samples: list[tuple[float, float, int]] = []

    def add(self, t: float, steps: int, now: float | None = None) -> None:
        """A sample at simulated time ``t`` after ``steps`` steps, at the wall clock ``now``
        (perf_counter's, by default)."""
        now = time.perf_counter() if now is None else now
        self.samples.append((now, t, steps))
        while len(self.samples) > 2 and now - self.samples[1][0] > self.WINDOW:
            self.samples.pop(0)

    def left(self, end_time: float, dt: float | None) -> tuple[float, float] | None:
        """(soonest, latest) seconds to ``end_time`` at the recent pace, the step ``dt`` on
        (explicit) or None (Newton steps); None while it is not known."""
        if not self.samples:
            return None
        to_go = end_time - self.samples[-1][1]
        if dt:
            (w0, _, n0), (w1, _, n1) = self.samples[0], self.samples[-1]
            return (to_go / dt * (w1 - w0) / (n1 - n0),) * 2 if n1 > n0 else None
        rates = [(b[0] - a[0]) / (b[1] - a[1]) for a, b in zip(self.samples, self.samples[1:]) if b[1] > a[1]]
        return tuple(to_go * np.percentile(rates, [25, 75])) if rates else None  # the middle half of the rates


def left_text(span: tuple[float, float] | None) -> str:
    """'about 1:23 left', '1:10-2:40 left' where the range is wide, '-' before it is known."""
    if span is None:
        return "-"
    soonest, latest = span
    if latest <= 1.25 * soonest:
        return f"about {clock(0.5 * (soonest + latest))} left"
    return f"{clock(soonest)}-{clock(latest)} left"


class ProgressDisplay(Listener):
    """A run's progress on ``console``: a bar on a terminal, a line every tenth of the run
    otherwise, nothing when ``quiet``; each with the columns of its path (explicit: the
    step, steps per second, the energy balance; static or implicit: the load or time
    step, its iterations and tangents, its residual; both: the worst element's J/J0) and
    the time left at the recent pace (:class:`Pace`)."""

    def __init__(self, console: Console, end_time: float, quiet: bool = False):
        self.console = console
        self.end_time = end_time
        self.quiet = quiet
        self.stepping_since = (time.perf_counter(), 0)  # (clock, steps) where the steps' rate starts
        self.pace = Pace()
        self.next_line = 0.1
        self.bar: Progress | None = None
        self.status = "starting"
        if not quiet and console.is_terminal:
            self.bar = Progress(TextColumn("[bold]t = {task.fields[t]}"), BarColumn(), TextColumn("{task.fields[status]}"),
                                _Clock(), console=console, transient=True)
            self.task = self.bar.add_task("run", total=end_time, t="0", status=self.status, compiling_since=None,
                                          left="-")
            self.bar.start()
        self.compiled_any = False
        self.forecast_told = False

    def announce(self, text: str) -> None:
        """A stage of the work before the first step (meshing, the mesh's size, building)."""
        if not self.quiet:
            self.console.print(f"[dim]{shown(text)}[/]", highlight=False)

    def compiling(self, name: str) -> None:
        """A kernel begins to compile (:mod:`shellsim.compile_watch`): named on the bar, its
        clock ticking in place of the time left."""
        if not self.compiled_any:
            self.compiled_any = True
            self.announce(f"compiling the kernels ({FIRST_RUN_NOTE})")
        if self.bar is not None:
            self.bar.update(self.task, status=f"compiling {name}", compiling_since=time.perf_counter())

    def compiled(self, name: str, seconds: float) -> None:
        """A kernel has compiled in ``seconds``."""
        if self.bar is not None:
            self.bar.update(self.task, status=self.status, compiling_since=None)
        if text := finished_text(name, seconds):
            self.announce(text)

    def on_dt(self, run: Run) -> None:
        """At the start (the estimates at t = 0, a mass scaling's among them): the steps'
        rate counts from here, not from the compiling before."""
        if run.sim.state.t == 0.0:
            self.stepping_since = (time.perf_counter(), run.sim.state.steps)  # not the compiling before

    def _forecast(self, run: Run) -> None:
        """The explicit steps' start: the step, the steps it takes to the end, and that the
        time left (known after a few samples) follows the step as it changes."""
        steps = (run.deck.solver.end_time - run.sim.state.t) / run.dt
        self.announce(f"critical step {run.dt_critical:.4g}, step {run.dt:.4g}: about {steps:,.0f} steps to the end at "
                      "this step; the time left, shown once the pace is known, follows the step as it changes "
                      "(shellsim check forecasts the time)")

    def columns(self, run: Run) -> str:
        """The status columns of ``run``'s path now."""
        quality = "" if run.worst is None else f"  J/J0 {run.worst.ratio:.2f} (el. {run.worst.element + 1})"
        if _static(run):  # its last load or time step in place of the explicit step
            step = run.newton[-1]
            kind = "time step" if run.deck.solver.method == "implicit" else "load step"
            return (f"{kind} {len(run.newton)}: {step.iterations} iterations, {step.tangents} "
                    f"tangent{'s' if step.tangents != 1 else ''}, residual {step.residual:.2g}{quality}")
        since, steps_then = self.stepping_since
        elapsed = max(time.perf_counter() - since, 1e-9)
        share = run.balance_share()
        return (f"dt {run.dt:.3g}  {(run.sim.state.steps - steps_then) / elapsed:,.0f} steps/s  "
                f"balance {'-' if share is None else f'{100 * share:+.2f}%'}{quality}")

    def on_sample(self, run: Run) -> None:
        if self.quiet:
            return
        if not self.forecast_told and not _static(run) and run.dt:  # the explicit steps' start
            self.forecast_told = True
            self._forecast(run)
        state = run.sim.state
        self.pace.add(state.t, state.steps)
        self.status = self.columns(run)
        left = left_text(self.pace.left(self.end_time, None if _static(run) else run.dt))
        if self.bar is not None:
            self.bar.update(self.task, completed=state.t, t=f"{state.t:.4g}", status=self.status, left=left)
        elif state.t >= self.next_line * self.end_time - 1e-12 * self.end_time:
            self.console.print(f"t = {state.t:.4g} ({100 * state.t / self.end_time:.0f}%), {self.status}, {left}",
                               highlight=False)
            self.next_line += 0.1

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


class ProgressCallback(Listener):
    """Progress for a function: ``report({"t", "end_time", "steps", "status"})`` at every
    history sample, the status the ``display``'s (a quiet :class:`ProgressDisplay`'s)
    columns."""

    def __init__(self, report, display: ProgressDisplay):
        self.report, self.display = report, display

    def on_dt(self, run: Run) -> None:
        self.display.on_dt(run)

    def on_sample(self, run: Run) -> None:
        self.report({"t": run.sim.state.t, "end_time": self.display.end_time, "steps": run.sim.state.steps,
                     "status": self.display.columns(run)})
