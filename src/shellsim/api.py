"""shellsim from Python: a scene from a deck file or a dict of its tables, run into a
folder as ``shellsim run`` does, and its results read back as arrays.

    import shellsim

    scene = shellsim.load("decks/verification/test09_aorta_static.toml")
    results = shellsim.run(scene, "out/test09")
    results.status                      # 'completed'
    results.history["inner_radius"]     # (samples,) array
    points, cells = results.points, results.cells
    point_data, cell_data = results.frame(-1)

Errors are the command line's: a :class:`~shellsim.errors.DeckError` naming the key and
what it expects, an :class:`~shellsim.errors.OutputError` naming the file.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .deck import Deck, deck_from_data, load_deck
from .errors import OutputError


def load(deck: str | Path | dict, base_dir: str | Path | None = None) -> Deck:
    """A validated scene from a deck file, or from a dict of its tables as TOML would give
    them; the files a dict names (a mesh, a waveform) are found in ``base_dir`` (default:
    the working folder)."""
    if isinstance(deck, dict):
        return deck_from_data(deck, "<dict>", Path(base_dir or Path.cwd()))
    return load_deck(deck)


def run(deck: Deck | str | Path | dict, out: str | Path, base_dir: str | Path | None = None,  # noqa: PLR0913 (each defaulted)
        renders: bool = True, progress: bool | Callable[[dict], None] = True) -> Results:
    """Run a scene (a :class:`~shellsim.deck.Deck`, a deck file or a dict, as :func:`load`
    takes) into the folder ``out``: the files and renders ``shellsim run`` writes. Returns
    its :class:`Results`; a run that ends short (unstable, not converged, interrupted)
    returns too, its ``status`` and ``summary["message"]`` telling why. ``progress``:
    True shows what ``shellsim run`` shows on the standard error (the stages, compiling,
    a bar on a terminal or a line every tenth of the run), False nothing, a function is
    called at every history sample with ``{"t", "end_time", "steps", "status"}`` (the
    status the bar shows)."""
    from contextlib import closing

    from rich.console import Console

    from .compile_watch import watching_compiles
    from .execute import run_scene
    from .output.folder import claimed, output_folder
    from .output.progress import ProgressDisplay, ProgressCallback
    from .output.render import deck_renders

    is_file = isinstance(deck, (str, Path))
    scene = deck if isinstance(deck, Deck) else load(deck, base_dir)
    deck_path = Path(deck) if is_file else Path(base_dir or Path.cwd()) / "deck.toml"
    folder = output_folder(Path(out))
    end = scene.solver.end_time
    shown = ProgressDisplay(Console(stderr=True), end, quiet=progress is not True)
    listener = ProgressCallback(progress, shown) if callable(progress) else shown
    with claimed(folder):  # the renders too
        with closing(shown), watching_compiles(shown.compiling, shown.compiled):
            current, _ = run_scene(scene, deck_path, folder, listener, shown.announce)
        if renders and current.status == "completed":
            deck_renders(scene, folder)
    return Results(folder)


class Results:
    """A run's folder read back: ``summary`` (summary.json as a dict), ``status``,
    ``history`` (history.csv: column name -> (samples,) array), the frames' ``times``, the
    viewing mesh's ``points`` (P, 3) and ``cells`` (C, k), and :meth:`frame`."""

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        from .output.history import read_history

        try:
            self.summary = json.loads((self.folder / "summary.json").read_text())
        except (OSError, json.JSONDecodeError) as error:
            raise OutputError(f"'{self.folder}' holds no finished run's summary.json: "
                              f"{getattr(error, 'strerror', None) or error}") from None
        self.history = read_history(self.folder)
        self._series = None

    @property
    def status(self) -> str:
        return self.summary["status"]

    @property
    def series(self):
        """The frames' :class:`~shellsim.output.series.StoredSeries`, read on first use."""
        from .output.series import StoredSeries

        if self._series is None:
            self._series = StoredSeries(self.folder)
        return self._series

    @property
    def times(self) -> list[float]:
        return self.series.times

    @property
    def points(self) -> np.ndarray:
        return self.series.points

    @property
    def cells(self) -> np.ndarray:
        return self.series.cells

    def frame(self, index: int) -> tuple[dict, dict]:
        """(point_data, cell_data) of frame ``index`` (negative from the end): field name ->
        (P, ...) and (C, ...) arrays (docs/outputs.md lists them)."""
        count = len(self.times)
        if not -count <= index < count:
            raise OutputError(f"frame {index}: '{self.folder}' holds {count} frames (0 to {count - 1}, or -1 the last)")
        return self.series.frame(range(count)[index])
