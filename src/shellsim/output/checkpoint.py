"""Checkpoints of an explicit run, and a run restored from one to go on.

At output frames ``output.checkpoint_interval`` apart, everything the time loop carries
from one step to the next is written to ``checkpoint.pkl`` in the run's folder (replacing
the last one atomically): the simulation's arrays, the loop's scratch that carries over
(the incremental formulation's increments, kinetic damping's watch), every array of the
loads (whatever a load kind keeps between steps), the critical-step estimator's start vector and
random state, when the next estimate is due, and the run's record (history, energies,
time steps, frames written). Restored into a run built afresh from the folder's resolved
deck, the run goes on as it would have: the explicit path is deterministic, so its history
is the same to the last bit.
"""

from __future__ import annotations

import math
import pickle
from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..solver.run import Listener, Run
from .folder import write_atomically

CHECKPOINT_NAME = "checkpoint.pkl"
#: Raised when what a checkpoint holds changes, so an older one is refused, not misread.
FORMAT = 1
#: The run's record, saved as it is.
RECORD = ("dt", "dt_critical", "dt_history", "times", "history", "energies", "wall_time", "startup", "ratios", "worst",
          "lowest", "newton", "stepping")


def _arrays(bundle) -> list[np.ndarray]:
    """Every array in ``bundle`` (an array, a tuple of them, nested), in a fixed order."""
    if isinstance(bundle, np.ndarray):
        return [bundle]
    if isinstance(bundle, tuple):
        return [array for item in bundle for array in _arrays(item)]
    return []


def _carried(run: Run) -> list[np.ndarray]:
    """The arrays a step hands to the next: the state's, the time loop's scratch, and the
    loads' (a load kind that keeps something between steps keeps it in its bundle)."""
    sim = run.sim
    return _arrays(sim.state.fields) + _arrays(sim.workspace) + _arrays(run.model.loads)


def _numbers(watch) -> dict:
    """The plain numbers an object (a relaxation's or a valve's watch) keeps between samples."""
    return {name: value for name, value in vars(watch).items()
            if isinstance(value, (int, float)) or value is None}


def snapshot(run: Run) -> dict:
    """What :func:`restore` needs to continue ``run`` from now, the frame of now written."""
    sim, state = run.sim, run.sim.state
    return {"format": FORMAT, "t": state.t, "dt_prev": state.dt_prev, "steps": state.steps,
            "arrays": [array.copy() for array in _carried(run)],
            "eigenvector": sim._eigenvector, "fresh": sim._fresh.bit_generator.state, "mass_factor": sim.mass_factor,
            "record": {name: getattr(run, name) for name in RECORD}, "frame_times": [*run.frame_times, state.t],
            "watches": {name: _numbers(getattr(run, name)) for name in ("relaxing", "valve")
                        if getattr(run, name) is not None}}


def restore(run: Run, saved: dict) -> None:
    """Put a checkpoint's state into ``run``, built from the same deck and not yet started."""
    sim, state = run.sim, run.sim.state
    carried = _carried(run)
    if len(carried) != len(saved["arrays"]) or any(a.shape != b.shape for a, b in zip(carried, saved["arrays"])):
        raise OutputError("the checkpoint is of another scene than the folder's deck.toml")
    for target, values in zip(carried, saved["arrays"]):
        target[...] = values
    state.t, state.dt_prev, state.steps = saved["t"], saved["dt_prev"], saved["steps"]
    sim._eigenvector, sim.mass_factor = saved["eigenvector"], saved["mass_factor"]
    sim._fresh.bit_generator.state = saved["fresh"]
    for name, value in saved["record"].items():
        setattr(run, name, value)
    run.frame_times = list(saved["frame_times"])
    for name, numbers in saved["watches"].items():
        vars(getattr(run, name)).update(numbers)


def read_checkpoint(folder: Path) -> dict:
    """The checkpoint in a run's ``folder``; OutputError when there is none to go on from."""
    path = folder / CHECKPOINT_NAME
    try:
        with open(path, "rb") as file:
            saved = pickle.load(file)
    except OSError as error:
        raise OutputError(f"'{folder}' holds no checkpoint to resume from ({error.strerror or error}): a run "
                          "writes them when its deck gives output.checkpoint_interval") from None
    except (pickle.UnpicklingError, EOFError, AttributeError, ImportError) as error:
        raise OutputError(f"'{path}' is not a checkpoint this version reads ({error})") from None
    if not isinstance(saved, dict) or saved.get("format") != FORMAT:
        raise OutputError(f"'{path}' is a checkpoint of another version of shellsim; run the deck again")
    return saved


class Checkpoints(Listener):
    """Writes a checkpoint into ``folder`` at the first frame of an explicit run at or
    after each multiple of ``interval`` (sim time) after ``start``; listed after the frame
    writers, so the frame being written counts."""

    def __init__(self, folder: Path, interval: float, start: float = 0.0):
        self.path, self.interval = folder / CHECKPOINT_NAME, interval
        self.due = self._after(start)

    def _after(self, t: float) -> float:
        """The first multiple of the interval after ``t``."""
        return (math.floor(t / self.interval * (1.0 + 1e-12)) + 1.0) * self.interval

    def on_frame(self, run: Run) -> None:
        t = run.sim.state.t
        if run.stepping is None or t < self.due * (1.0 - 1e-12):  # only the time loop's states go on
            return
        write_atomically(self.path, pickle.dumps(snapshot(run), pickle.HIGHEST_PROTOCOL))
        self.due = self._after(t)
