"""Time series of output frames: ``results.xdmf`` + ``results.h5`` (:mod:`.xdmf`), and
``results.pvd`` + ``frames/*.vtu`` (:mod:`.vtu`), each left readable after every frame, so a
run that stops (Ctrl-C, a numerical failure, a killed process) keeps every frame written so
far; and a written series read back."""

from __future__ import annotations

import shutil
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from ..deck.schema import Output
from ..errors import OutputError
from ..memory import size_text
from ..solver.run import Listener, Run
from .encoding import Encoding
from .fields import cable_fields, cable_mesh, frame_fields, output_mesh, source_ids
from .mirror import mirror_planes, mirrored_mesh, mirrored_values, mirrors
from .vtu import VtuSeries, pvd_entries
from .xdmf import XdmfSeries

XDMF_NAME, PVD_NAME = "results.xdmf", "results.pvd"
#: The cables' own series (line cells), beside the shells' (:func:`shellsim.output.fields.cable_mesh`).
CABLES = "cables"


SERIES = {"xdmf": XdmfSeries, "vtu": VtuSeries}
#: Room kept free beyond twice a frame's data before each frame is written [bytes]: the
#: series' metadata, the XML rewritten beside the old, a checkpoint, the summary.
FRAME_MARGIN = 2**18


class FrameWriter(Listener):
    """Writes every frame of a run to each format the deck's ``[output]`` asks for; going
    on from a checkpoint, after the first ``kept`` frames of each series in ``folder``."""

    def __init__(self, folder: Path, run: Run, output: Output, kept: int | None = None):
        self.folder = folder
        self.fields, self.vessel_axes, self.faces = list(output.fields), output.vessel_axes, tuple(output.faces)
        self.part = output_mesh(run.model, output.solid)
        self.ids = source_ids(run.mesh, run.model, self.part)  # the same in every frame
        self.copies = mirrors(mirror_planes(run.deck, run.mesh))
        self.mesh = mirrored_mesh(self.part, self.copies)
        self.run = run
        self.cables = cable_mesh(run.model)
        self.encoding = Encoding.of(output)
        self.written = kept or 0  # frames every series holds
        self.series, self.cable_series = [], []
        try:
            for kind in dict.fromkeys(output.formats):
                self.series.append(SERIES[kind](folder, self.mesh, self.encoding, kept=kept))
                if self.cables is not None:
                    self.cable_series.append(SERIES[kind](folder, self.cables, self.encoding, CABLES, kept))
        except (OSError, ET.ParseError) as error:  # a series to go on with may be damaged
            self.close()
            raise OutputError(f"cannot write the {kind} series in '{folder}': {error.strerror or error}") from None

    def _fields(self, run: Run) -> tuple[dict, dict]:
        """(point_data, cell_data) of the current state on the written (mirrored) mesh."""
        point_data, cell_data = frame_fields(run.sim, self.part, self.fields, self.vessel_axes, self.faces)
        point_data, cell_data = point_data | self.ids[0], cell_data | self.ids[1]
        if self.copies.count == 1:
            return point_data, cell_data
        return ({name: mirrored_values(v, self.copies) for name, v in point_data.items()},
                {name: mirrored_values(v, self.copies) for name, v in cell_data.items()})

    def frame_bytes(self) -> int:
        """Bytes one frame of the current state takes in every format, uncompressed (data
        only)."""
        return self._bytes(*self._fields(self.run))

    def _bytes(self, point_data: dict, cell_data: dict) -> int:
        """Bytes a frame of these fields takes in every format, uncompressed (data only)."""
        values = sum(a.size for a in (*point_data.values(), *cell_data.values()))
        return len(self.series) * values * np.dtype(self.encoding.float_type).itemsize

    def on_frame(self, run: Run) -> None:
        point_data, cell_data = self._fields(run)
        # HDF5 meeting a full disk mid-write leaves its file in a state that later crashes
        # the process: the room is made sure of first
        t = float(run.sim.state.t)  # a numpy scalar would be written as its repr
        check_space(self.folder, 2 * self._bytes(point_data, cell_data) + FRAME_MARGIN, f"the frame at t = {t:.6g} needs")
        written = [(series, point_data, cell_data) for series in self.series]
        if self.cable_series:
            written += [(series, *cable_fields(run.sim, self.cables)) for series in self.cable_series]
        for series, point_values, cell_values in written:
            try:
                series.write(t, point_values, cell_values)
            except (OSError, RuntimeError) as error:  # HDF5 reports a full disk as a RuntimeError
                raise OutputError(f"writing the frame at t = {t:.6g} to {series.path} failed: "
                                  f"{getattr(error, 'strerror', None) or error}") from None
        self.written += 1

    def close(self) -> None:
        """Close every series, each even when one before it fails; OutputError naming the
        first that could not write what it still held (a full disk)."""
        failed = None
        for series in self.series + self.cable_series:
            try:
                series.close()
            except (OSError, RuntimeError) as error:
                failed = failed or f"cannot write '{series.path}': {getattr(error, 'strerror', None) or error}"
        if failed:
            raise OutputError(failed)


def check_space(folder: Path, needed: int, what: str = "the run's frames need") -> None:
    """Raise OutputError when ``folder``'s disk has less than ``needed`` bytes free;
    ``what`` says what needs them, verb included."""
    free = shutil.disk_usage(folder).free
    if needed > free:
        raise OutputError(f"{what} about {size_text(needed)} but '{folder}' has {size_text(free)} free (the disk is "
                          "full or nearly): write fewer frames (output.interval) or fields (output.fields), or "
                          "choose another --out")


class StoredSeries:
    """A written series read back (the shells' ``results``, or the ``cables``): ``points``
    (P, 3), ``cells`` (C, k) of ``cell_type``, ``times`` of the frames; :meth:`frame` gives
    one frame's (point_data, cell_data)."""

    def __init__(self, folder: Path, name: str = "results"):
        import meshio

        self.folder = folder
        xdmf, pvd = folder / f"{name}.xdmf", folder / f"{name}.pvd"
        if xdmf.exists():
            self._reader = meshio.xdmf.TimeSeriesReader(xdmf)
            try:
                points, cells = self._reader.read_points_cells()
            except OSError as error:  # HDF5 locks a file while a run writes it
                raise OutputError(f"cannot read the series in '{folder}' ({error.strerror or error}): a run may "
                                  "still be writing it; read it once the run has ended") from None
            # the times from the XML alone: reading each frame's data here would read it twice
            self.times = [float(t.get("Value")) for t in ET.parse(xdmf).getroot().iter("Time")]
        elif pvd.exists():
            self._reader = None
            self._files = pvd_entries(pvd)
            self.times = [t for t, _ in self._files]
            first = meshio.read(folder / self._files[0][1]) if self._files else None
            points, cells = (first.points, first.cells) if first else (np.zeros((0, 3)), [])
        else:
            raise OutputError(f"'{folder}' holds no results series ({XDMF_NAME} or {PVD_NAME}); "
                              "run a deck with --out pointing there first")
        if not self.times:
            raise OutputError(f"the series in '{folder}' has no frames yet")
        self.points, self.cell_type, self.cells = points, cells[0].type, cells[0].data

    def frame(self, index: int) -> tuple[dict, dict]:
        """(point_data, cell_data) of frame ``index``, cell arrays for the one cell block."""
        import meshio

        if self._reader is not None:
            _, point_data, cell_data = self._reader.read_data(index)
        else:
            stored = meshio.read(self.folder / self._files[index][1])
            point_data, cell_data = stored.point_data, stored.cell_data
        return dict(point_data), {name: blocks[0] for name, blocks in cell_data.items()}
