"""history.csv, written row by row as the run goes (flushed, so nothing is lost if the run
stops): time, time step, energies and every probe."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ..deck.columns import ENERGY_COLUMNS
from ..errors import OutputError
from ..solver.explicit import FRICTION
from ..solver.run import Listener, Run
from .folder import open_unlinked



def energy_columns(run: Run) -> tuple[str, ...]:
    """The energies' columns of ``run``'s history."""
    return ENERGY_COLUMNS if run.sim.workspace.friction else ENERGY_COLUMNS[:FRICTION]


class HistoryWriter(Listener):
    """Appends one CSV row per history sample to ``path``; going on from a checkpoint
    (``kept`` samples), after the header and that many rows of the file there."""

    def __init__(self, path: Path, kept: int | None = None):
        self.path = path
        try:
            earlier = []
            if kept:
                with open(path, newline="", encoding="utf-8") as written:  # its rows' own line ends
                    earlier = written.readlines()[:kept + 1]
            self._file = open_unlinked(path, "w", newline="", encoding="utf-8")  # truncated in place
            self._file.writelines(earlier)
        except OSError as error:
            raise OutputError(f"cannot write '{path}': {error.strerror}") from None
        self._writer = csv.writer(self._file)
        self._header_written = bool(earlier)

    def on_sample(self, run: Run) -> None:
        if not self._header_written:
            self._writer.writerow(["time", "dt", *energy_columns(run), *run.history])  # flushed with the first row
            self._header_written = True
        energy = run.energies[-1][:len(energy_columns(run))]
        row = [run.times[-1], run.dt, *energy, *(values[-1] for values in run.history.values())]
        try:
            self._writer.writerow([f"{v:.12g}" for v in row])
            self._file.flush()
        except OSError as error:
            raise OutputError(f"cannot write '{self.path}': {error.strerror or error}") from None

    def close(self) -> None:
        """Close the file; OutputError when what it still held cannot be written (a full disk)."""
        try:
            self._file.close()
        except OSError as error:
            raise OutputError(f"cannot write '{self.path}': {error.strerror or error}") from None


def read_history(folder: Path) -> dict[str, np.ndarray]:
    """The history.csv of a run's ``folder``: column name -> (samples,) array."""
    try:
        table = np.genfromtxt(folder / "history.csv", delimiter=",", names=True, ndmin=1)
    except OSError as error:
        raise OutputError(f"'{folder}' is not a finished run's folder: {error.strerror or error} "
                          f"({error.filename})") from None
    if table.size == 0 or table.dtype.names is None:
        raise OutputError(f"'{folder / 'history.csv'}' has no samples yet")
    return {name: table[name] for name in table.dtype.names}
