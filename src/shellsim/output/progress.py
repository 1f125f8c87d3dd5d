"""Progress of a run: a rich bar on a terminal (simulated time, step, steps per second,
energy balance, the worst element's Jacobian ratio J/J0, time left; on a first run the
kernel compiling and its clock), a line every tenth of the run otherwise, nothing when
quiet."""

from __future__ import annotations

import time

from rich.console import Console
from rich.progress import BarColumn, Progress, ProgressColumn, TextColumn, TimeRemainingColumn
from rich.text import Text

from ..compile_watch import FIRST_RUN_NOTE, finished_text
from ..printable import shown
from ..solver.run import Listener, Run


def _static(run: Run) -> bool:
    """Whether ``run`` is in a static solve: load steps taken, no time step estimated yet
    (a preloaded run's explicit phase has one)."""
    return bool(run.newton) and not run.dt


class _Clock(ProgressColumn):
    """The time left while stepping; while a kernel compiles, how long it has compiled
    (ticking: the bar redraws itself)."""

    def __init__(self):
        super().__init__()
        self.remaining = TimeRemainingColumn()

    def render(self, task) -> Text:
        since = task.fields["compiling_since"]
        if since is None:
            return self.remaining.render(task)
        seconds = int(time.perf_counter() - since)
        return Text(f"{seconds // 60}:{seconds % 60:02d}", style="progress.elapsed")


class ProgressDisplay(Listener):
    def __init__(self, console: Console, end_time: float, quiet: bool = False):
        self.console = console
        self.end_time = end_time
        self.quiet = quiet
        self.stepping_since = (time.perf_counter(), 0)  # (clock, steps) where the steps' rate starts
        self.next_line = 0.1
        self.bar: Progress | None = None
        self.status = "dt -  - steps/s  balance -  J/J0 -"
        if not quiet and console.is_terminal:
            self.bar = Progress(TextColumn("[bold]t = {task.fields[t]}"), BarColumn(), TextColumn("{task.fields[status]}"),
                                _Clock(), console=console, transient=True)
            self.task = self.bar.add_task("run", total=end_time, t="0", status=self.status, compiling_since=None)
            self.bar.start()
        self.compiled_any = False

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
        """At the first estimate: the step and what the run will cost."""
        if len(run.dt_history) != 1:
            return
        self.stepping_since = (time.perf_counter(), run.sim.state.steps)  # not the compiling before
        if self.quiet:
            return
        from ..solver.outlook import contact_seconds, duration, stepping

        contact = contact_seconds(run.model, run.load_time, run.sim.state.fields.shape)
        steps, cost = stepping(run.deck.solver.end_time, run.dt, run.model.n_elements, contact)
        self.announce(f"critical step {run.dt_critical:.4g}, step {run.dt:.4g}: about {steps:,.0f} steps, "
                      f"about {duration(cost)} of stepping ({duration(cost / run.deck.solver.end_time)} "
                      "per unit of simulated time" + (", contact's included" if contact else "") + ")")

    def _fields(self, run: Run) -> dict:
        if _static(run):  # its last load step in place of the time step
            step = run.newton[-1]
            return {"t": f"{run.sim.state.t:.4g}", "dt": f"load step {len(run.newton)}", "rate": "-",
                    "balance": f"{step.iterations} iterations ({step.tangents} tangents), residual {step.residual:.2g}",
                    "quality": "-" if run.worst is None else f"{run.worst.ratio:.2f} (el. {run.worst.element + 1})"}
        since, steps_then = self.stepping_since
        elapsed = max(time.perf_counter() - since, 1e-9)
        share = run.balance_share()
        return {"t": f"{run.sim.state.t:.4g}", "dt": f"{run.dt:.3g}",
                "rate": f"{(run.sim.state.steps - steps_then) / elapsed:,.0f}",
                "balance": "-" if share is None else f"{100 * share:+.2f}%",
                "quality": "-" if run.worst is None else f"{run.worst.ratio:.2f} (el. {run.worst.element + 1})"}

    def on_sample(self, run: Run) -> None:
        if self.quiet:
            return
        if self.bar is not None:
            f = self._fields(run)
            self.status = f"dt {f['dt']}  {f['rate']} steps/s  balance {f['balance']}  J/J0 {f['quality']}"
            self.bar.update(self.task, completed=run.sim.state.t, t=f["t"], status=self.status)
        elif run.sim.state.t >= self.next_line * self.end_time - 1e-12 * self.end_time:
            f = self._fields(run)
            done = f"t = {f['t']} ({100 * run.sim.state.t / self.end_time:.0f}%), "
            self.console.print(done + (f"{f['dt']}: {f['balance']}" if _static(run) else
                                       f"dt {f['dt']}, {f['rate']} steps/s, balance {f['balance']}, "
                                       f"worst J/J0 {f['quality']}"), highlight=False)
            self.next_line += 0.1

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
