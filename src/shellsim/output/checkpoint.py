"""Checkpoints of an explicit run, and a run restored from one to go on.

At output frames ``output.checkpoint_interval`` apart, everything the time loop carries
from one step to the next is written to ``checkpoint.npz`` in the run's folder (replacing
the last one atomically): the simulation's arrays, the loop's scratch that carries over
(the incremental formulation's increments, kinetic damping's watch), every array of the
loads (whatever a load kind keeps between steps), the critical-step estimator's start vector and
random state, when the next estimate is due, and the run's record (history, energies,
time steps, frames written). Restored into a run built afresh from the folder's resolved
deck, the run goes on as it would have: the explicit path is deterministic, so its history
is the same to the last bit.

Run folders are shared, so a checkpoint holds data and nothing that could run: arrays
read with ``allow_pickle=False`` and one JSON document, whose objects are rebuilt only as
the few record types named in :data:`RECORD_TYPES`, field by field. It names the version
that wrote it and a fingerprint of the resolved deck and mesh, and is refused, with the
reason, by another version or beside an edited deck.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import stat
import zipfile
from collections import deque
from pathlib import Path

import numpy as np

from .. import __version__
from ..errors import OutputError
from ..solver.quality import Worst
from ..solver.run import Listener, Run, Stepping
from ..solver.static import NewtonStep
from ..solver.timestep import EstimateSchedule
from .folder import write_atomically

CHECKPOINT_NAME = "checkpoint.npz"
#: What earlier versions wrote: a pickle, never read (unpickling can run code).
PICKLED_NAME = "checkpoint.pkl"
#: Raised when what a checkpoint holds changes, so an older one is refused, not misread.
FORMAT = 2
#: The run's record, saved as it is.
RECORD = ("dt", "dt_critical", "dt_history", "times", "history", "energies", "wall_time", "startup", "ratios", "worst",
          "lowest", "newton", "stepping", "mass_rescalings")
#: The only objects a checkpoint's record rebuilds, by name.
RECORD_TYPES = {cls.__name__: cls for cls in (Worst, Stepping, EstimateSchedule, NewtonStep)}


class Maybe:
    """A record spec: None, or what ``spec`` says."""

    def __init__(self, spec):
        self.spec = spec


class QueueOf:
    """A record spec: a deque of what ``spec`` says."""

    def __init__(self, spec):
        self.spec = spec


#: What each record entry and record type's field holds (checked before anything is
#: restored): a type, [spec] a list, (spec, ...) a tuple, {str: spec} a dict, Maybe, QueueOf.
SPECS = {
    "dt": float, "dt_critical": float, "wall_time": float, "dt_history": [(float, float, float)], "times": [float],
    "history": {str: [float]}, "energies": [np.ndarray], "startup": {str: float}, "ratios": Maybe(np.ndarray),
    "worst": Maybe(Worst), "lowest": Maybe(Worst), "newton": [NewtonStep], "stepping": Maybe(Stepping),
    "mass_rescalings": int,
    Worst: {"t": float, "element": int, "ratio": float},
    NewtonStep: {"t": float, "load_time": float, "iterations": int, "tangents": int, "residual": float,
                 "cutbacks": int},
    Stepping: {"schedule": EstimateSchedule, "interval": int, "since_update": int},
    EstimateSchedule: {"safety": float, "most": int, "interval": int, "_seen": QueueOf((int, float))},
}


def _conforms(value, spec) -> bool:
    """Whether ``value`` is what ``spec`` (see SPECS) says."""
    if isinstance(spec, Maybe):
        return value is None or _conforms(value, spec.spec)
    if isinstance(spec, QueueOf):
        return isinstance(value, deque) and all(_conforms(item, spec.spec) for item in value)
    if isinstance(spec, list):
        return isinstance(value, list) and all(_conforms(item, spec[0]) for item in value)
    if isinstance(spec, tuple):
        return (isinstance(value, tuple) and len(value) == len(spec)
                and all(_conforms(item, part) for item, part in zip(value, spec)))
    if isinstance(spec, dict):
        return isinstance(value, dict) and all(_conforms(item, spec[str]) for item in value.values())
    if spec in SPECS:
        fields = SPECS[spec]
        return (type(value) is spec and vars(value).keys() == fields.keys()
                and all(_conforms(vars(value)[name], part) for name, part in fields.items()))
    if spec is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if spec is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, spec)


#: The JSON document's member in the archive; the arrays are "a0", "a1", ...
DOCUMENT = "document"
#: Larger files are refused before they are read [bytes]: no run's state comes near it.
LARGEST = 64 * 2**30


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


def _watches(run: Run) -> dict:
    """The objects of ``run`` that keep plain numbers between samples, by name: a
    relaxation's watch for rest, and each measure family that has some (a valve's next
    measurement time)."""
    watching = {"relaxing": run.relaxing} if run.relaxing is not None else {}
    return watching | {measure.NAME: measure for measure in run.measures if _numbers(measure)}


def fingerprint(run: Run) -> str:
    """A hash of the scene ``run`` was built from: its resolved deck and its mesh."""
    digest = hashlib.sha256(json.dumps(run.deck.model_dump(mode="json"), sort_keys=True).encode())
    for array in (run.mesh.x, run.mesh.conn):
        digest.update(np.ascontiguousarray(array).tobytes())
    return digest.hexdigest()


def snapshot(run: Run) -> dict:
    """What :func:`restore` needs to continue ``run`` from now, the frame of now written."""
    sim, state = run.sim, run.sim.state
    return {"format": FORMAT, "version": __version__, "scene": fingerprint(run),
            "t": state.t, "dt_prev": state.dt_prev, "steps": state.steps,
            "arrays": [array.copy() for array in _carried(run)],
            "eigenvector": sim.eigenvector, "fresh": sim.fresh.bit_generator.state, "mass_factor": sim.mass_factor,
            "record": {name: getattr(run, name) for name in RECORD}, "frame_times": [*run.frame_times, state.t],
            "watches": {name: _numbers(watch) for name, watch in _watches(run).items()}}


def _encoded(value, arrays: list[np.ndarray]):
    """``value`` as JSON data, its arrays appended to ``arrays`` and named by their place."""
    if isinstance(value, np.ndarray):
        arrays.append(value)
        return {"$array": len(arrays) - 1}
    if isinstance(value, (np.integer, np.floating, np.bool_)):
        return value.item()
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (list, tuple, deque)):
        items = [_encoded(item, arrays) for item in value]
        return items if isinstance(value, list) else {"$tuple" if isinstance(value, tuple) else "$deque": items}
    if isinstance(value, dict):
        return {"$dict": {str(key): _encoded(item, arrays) for key, item in value.items()}}
    if type(value).__name__ in RECORD_TYPES:
        return {"$object": type(value).__name__, "fields": _encoded(vars(value), arrays)}
    raise TypeError(f"a checkpoint cannot hold a {type(value).__name__}")


def _decoded(data, arrays):
    """The value :func:`_encoded` wrote, its arrays read from ``arrays`` (an npz archive
    read without pickles); ValueError for anything it did not write."""
    if data is None or isinstance(data, (bool, int, float, str)):
        return data
    if isinstance(data, list):
        return [_decoded(item, arrays) for item in data]
    if not isinstance(data, dict) or len(data) not in (1, 2):
        raise ValueError(f"unexpected {type(data).__name__}")
    if "$array" in data:
        return arrays[f"a{int(data['$array'])}"]
    if "$tuple" in data:
        return tuple(_decoded(data["$tuple"], arrays))
    if "$deque" in data:
        return deque(_decoded(data["$deque"], arrays))
    if "$dict" in data:
        return {key: _decoded(item, arrays) for key, item in data["$dict"].items()}
    if data.get("$object") in RECORD_TYPES:
        fields = _decoded(data["fields"], arrays)
        made = object.__new__(RECORD_TYPES[data["$object"]])  # no code of the file's choosing runs
        made.__dict__.update(fields)
        return made
    raise ValueError(f"unexpected entry {sorted(data)}")


def checkpoint_bytes(saved: dict) -> bytes:
    """``saved`` (a :func:`snapshot`) as the bytes of an npz archive: its arrays and one JSON document."""
    arrays: list[np.ndarray] = []
    document = json.dumps(_encoded(saved, arrays))
    buffer = io.BytesIO()
    np.savez(buffer, **{f"a{k}": array for k, array in enumerate(arrays)},
             **{DOCUMENT: np.frombuffer(document.encode("utf-8"), dtype=np.uint8)})
    return buffer.getvalue()


def _check_fits(run: Run, saved: dict) -> None:
    """ValueError (or KeyError, TypeError) unless every entry of ``saved`` is what a
    checkpoint of ``run``'s scene holds, so that restoring it changes nothing half way."""
    carried = _carried(run)
    arrays = saved["arrays"]
    if not isinstance(arrays, list) or len(arrays) != len(carried) or any(
            not isinstance(b, np.ndarray) or a.shape != b.shape or a.dtype != b.dtype for a, b in zip(carried, arrays)):
        raise ValueError("its arrays are not the scene's")
    if not all(_conforms(saved[name], spec) for name, spec in (
            ("t", float), ("dt_prev", float), ("steps", int), ("mass_factor", float), ("frame_times", [float]),
            ("eigenvector", Maybe(np.ndarray)), ("fresh", {str: object}), ("watches", {str: {str: Maybe(float)}}))):
        raise ValueError("its clock, estimator or watches are not a run's")
    if saved["eigenvector"] is not None and saved["eigenvector"].shape != (5 * run.model.n_nodes,):
        raise ValueError("its estimator's vector is not the scene's")
    watches = _watches(run)
    for name, numbers in saved["watches"].items():
        if name not in watches or not numbers.keys() <= vars(watches[name]).keys():
            raise ValueError(f"its watch {name!r} is not the scene's")
    record = saved["record"]
    if not isinstance(record, dict) or record.keys() != set(RECORD):
        raise ValueError("its record is not a run's")
    wrong = [name for name in RECORD if not _conforms(record[name], SPECS[name])]
    if wrong or record["history"].keys() != run.history.keys():
        raise ValueError(f"its record's {', '.join(wrong) or 'history columns'} are not a run's")
    type(run.sim.fresh.bit_generator)().state = saved["fresh"]  # a generator of the kind takes it


def restore(run: Run, saved: dict) -> None:
    """Put a checkpoint's state into ``run``, built from the same deck and not yet started;
    OutputError, with the reason and ``run`` untouched, for a checkpoint of another version
    or another scene (the folder's deck.toml edited since), or one that is damaged."""
    if saved.get("version") != __version__:
        raise OutputError(f"the checkpoint was written by shellsim {saved.get('version')}, this is {__version__}: "
                          "run the deck again")
    if saved.get("scene") != fingerprint(run):
        raise OutputError("the checkpoint is of another scene than the folder's deck.toml (another deck, or the "
                          "deck or its mesh changed since it was written): run the deck again")
    try:
        _check_fits(run, saved)
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise OutputError(f"the checkpoint is damaged ({type(error).__name__}: {error}): run the deck again") from None
    sim, state = run.sim, run.sim.state
    for target, values in zip(_carried(run), saved["arrays"]):
        target[...] = values
    state.t, state.dt_prev, state.steps = float(saved["t"]), float(saved["dt_prev"]), saved["steps"]
    sim.eigenvector, sim.mass_factor = saved["eigenvector"], float(saved["mass_factor"])
    sim.fresh.bit_generator.state = saved["fresh"]
    for name, value in saved["record"].items():
        setattr(run, name, value)
    run.frame_times = [float(t) for t in saved["frame_times"]]
    watches = _watches(run)
    for name, numbers in saved["watches"].items():
        vars(watches[name]).update(numbers)


def _regular_file_bytes(path: Path) -> bytes:
    """The bytes of ``path``, a regular file (not a link, a FIFO or a device) of at most
    LARGEST bytes; OSError otherwise."""
    handle = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(handle, "rb") as file:
        status = os.fstat(handle)
        if not stat.S_ISREG(status.st_mode):
            raise OSError("not a regular file")
        if status.st_size > LARGEST:
            raise OSError(f"{status.st_size:,} bytes, more than a checkpoint holds")
        return file.read()


def read_checkpoint(folder: Path) -> dict:
    """The checkpoint in a run's ``folder``; OutputError when there is none to go on from,
    or it is not a checkpoint (no code in the file runs: see the module's note)."""
    path = folder / CHECKPOINT_NAME
    if not os.path.lexists(path):
        older = " (its checkpoint.pkl, an older shellsim's, is not read: a pickle can run code)" \
            if os.path.lexists(folder / PICKLED_NAME) else ""
        raise OutputError(f"'{folder}' holds no checkpoint to resume from{older}: a run writes them when its deck "
                          "gives output.checkpoint_interval")
    try:
        content = _regular_file_bytes(path)
    except OSError as error:
        raise OutputError(f"cannot read the checkpoint '{path}': {error.strerror or error}") from None
    try:
        with np.load(io.BytesIO(content), allow_pickle=False) as arrays:
            document = json.loads(bytes(arrays[DOCUMENT]).decode("utf-8"))
            saved = _decoded(document, {name: arrays[name] for name in arrays.files if name != DOCUMENT})
    except (ValueError, KeyError, TypeError, AttributeError, OSError, EOFError, MemoryError, RecursionError, UnicodeError,
            zipfile.BadZipFile) as error:
        raise OutputError(f"'{path}' is not a checkpoint shellsim reads ({type(error).__name__}: {error})") from None
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
        write_atomically(self.path, checkpoint_bytes(snapshot(run)))
        self.due = self._after(t)
