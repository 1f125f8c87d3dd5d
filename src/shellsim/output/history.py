"""history.csv, written row by row as the run goes (flushed, so nothing is lost if the run
stops): time, time step, energies and every probe."""

from __future__ import annotations

import csv
from pathlib import Path

from ..errors import OutputError
from ..solver.run import Listener, Run

ENERGY_COLUMNS = ("internal_energy", "kinetic_energy", "external_work", "damping_work")


class HistoryWriter(Listener):
    """Appends one CSV row per history sample to ``path``."""

    def __init__(self, path: Path):
        self.path = path
        try:
            self._file = open(path, "w", newline="", encoding="utf-8")
        except OSError as error:
            raise OutputError(f"cannot write '{path}': {error.strerror}") from None
        self._writer = csv.writer(self._file)
        self._header_written = False

    def on_sample(self, run: Run) -> None:
        if not self._header_written:
            self._writer.writerow(["time", "dt", *ENERGY_COLUMNS, *run.history])
            self._header_written = True
        energy = run.energies[-1]
        row = [run.times[-1], run.dt, *energy, *(values[-1] for values in run.history.values())]
        self._writer.writerow([f"{v:.12g}" for v in row])
        self._file.flush()

    def close(self) -> None:
        self._file.close()
