"""One scene run from end to end with every file it leaves behind: what ``shellsim run``
and each job of a study call."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack, closing, suppress
from pathlib import Path

from . import __version__
from .deck import Deck
from .mesh import Mesh
from .errors import NumericalError, OutputError, SceneTooLarge
from .solver.run import Listener, Listeners, Run, Stopwatch, Timed


def _silent(text: str) -> None:
    """An ``announce`` that tells nobody."""


def sized_mesh(scene: Deck, deck_folder: Path, announce: Callable[[str], None] = _silent) -> Mesh:
    """The scene's mesh (files named in the deck read relative to ``deck_folder``), its size
    and the memory a run of it holds told to ``announce``. Raises SceneTooLarge for a mesh
    that would not fit in memory."""
    from .geometry import build_mesh
    from .memory import memory_bytes, refuse_if_too_big, size_text

    announce("meshing")
    mesh = build_mesh(scene, deck_folder)
    newton = scene.solver.newton
    announce(f"{mesh.n_elements:,} elements, {mesh.n_nodes:,} nodes, {5 * mesh.n_nodes:,} DOFs: "
             f"about {size_text(memory_bytes(mesh.n_elements, newton))} of memory")
    refuse_if_too_big(mesh.n_elements, newton=newton)
    return mesh


def built_run(scene: Deck, deck_folder: Path, announce: Callable[[str], None] = _silent) -> Run:
    """A run of ``scene`` ready to start (:func:`sized_mesh`, model, simulation), with the
    seconds each took in ``run.startup``: mesh_s, model_s, and kernels_s, the first masses
    and forces (the kernels compiled, or loaded from numba's cache).
    :func:`shellsim.solver.run.integrate` adds first_dt_s. ``announce`` hears each stage."""
    from .model import build_model
    from .solver.run import prepare

    clock = Stopwatch()
    mesh = sized_mesh(scene, deck_folder, announce)
    unloading = None
    if scene.solver.imaged is not None:
        from .solver.unloaded import unloaded_mesh

        announce(f"finding the unloaded shape of the mesh imaged at t = {scene.solver.imaged.at:g}")
        mesh, unloading = unloaded_mesh(scene, mesh, announce)
    mesh_s = clock.lap()
    announce("building the model")
    model = build_model(scene, mesh)
    model_s = clock.lap()
    run = prepare(scene, mesh, model)
    run.startup |= {"mesh_s": mesh_s, "model_s": model_s, "kernels_s": clock.lap()}
    run.unloading = unloading
    return run


def solve(run: Run, listener: Listener | None = None) -> Run:
    """Solve ``run`` by its deck's method: statically, implicitly, explicitly, or
    explicitly after a static preload; a run restored from a checkpoint goes on in time."""
    from .solver.implicit import solve_implicit
    from .solver.preload import preload_then_integrate
    from .solver.run import integrate
    from .solver.static_solve import solve_static

    solver = run.deck.solver
    method = (solve_static if solver.method == "static" else solve_implicit if solver.method == "implicit" else
              integrate if solver.preload is None or run.stepping is not None else preload_then_integrate)
    return method(run, listener)


def _run_files() -> tuple[str, ...]:
    """The files and folders a run writes into its folder, renders and plots included."""
    from .deck.resolved import RESOLVED_NAME
    from .output.checkpoint import CHECKPOINT_NAME, PICKLED_NAME
    from .output.plots import PLOTS_DIR
    from .output.render import RENDERS_DIR
    from .output.series import CABLES
    from .output.vtu import FRAMES_DIR

    series = tuple(f"{name}.{kind}" for name in ("results", CABLES) for kind in ("xdmf", "h5", "pvd"))
    return (RESOLVED_NAME, "history.csv", "summary.json", CHECKPOINT_NAME, PICKLED_NAME, RENDERS_DIR, PLOTS_DIR,
            FRAMES_DIR, f"{CABLES}_{FRAMES_DIR}", *series)


def _start_afresh(folder: Path, scene: Deck, deck_path: Path) -> None:
    """``folder`` cleared of an earlier run's files, with the resolved deck of ``scene``
    (read from ``deck_path``) written in it."""
    from .deck.resolved import RESOLVED_NAME, resolved_text
    from .output.folder import clear_earlier_run, write_atomically

    clear_earlier_run(folder, _run_files())
    write_atomically(folder / RESOLVED_NAME, resolved_text(scene, deck_path, __version__))


def run_scene(scene: Deck, deck_path: Path, folder: Path, progress: Listener | None = None,
              announce: Callable[[str], None] = _silent, checkpoint: dict | None = None) -> tuple[Run, dict]:
    """Build and integrate ``scene`` (read from ``deck_path``) writing into ``folder``
    (already checked by :func:`output_folder`): deck.toml, history.csv, the frame series,
    the checkpoints the deck asks for, and summary.json whatever the end, holding the
    folder against other runs and first clearing an earlier run's files. Going on from a
    ``checkpoint`` (:func:`shellsim.output.checkpoint.read_checkpoint` of ``folder``, whose
    deck.toml ``scene`` is), the run starts from it and the files keep what was written
    up to it. Returns (run, summary); ``run.status`` tells how it ended ('completed',
    'unstable', 'interrupted', 'output failed', 'refused': too long to run) and the
    summary's ``message`` why. ``announce`` hears the stages before the first step.
    Renders are left to the caller."""
    from .output.checkpoint import Checkpoints, restore
    from .output.folder import claimed
    from .output.history import HistoryWriter
    from .output.series import FrameWriter, check_space
    from .output.summary import summary, unstarted, write_json
    from .plan import plan
    from .solver.run import output_times

    with claimed(folder):  # before anything is written; another run's files stay as they are
        try:
            current = built_run(scene, deck_path.parent, announce)
        except NumericalError as error:  # the unloaded shape not found: the folder says so, not an earlier run
            _start_afresh(folder, scene, deck_path)
            write_json(unstarted(scene, deck_path, str(error)), folder / "summary.json")
            raise
        kept_samples = kept_frames = None
        if checkpoint is None:
            _start_afresh(folder, scene, deck_path)
        else:
            restore(current, checkpoint)
            kept_samples, kept_frames = len(current.times), len(current.frame_times)
        message = None
        with ExitStack() as files:
            try:
                history = files.enter_context(closing(HistoryWriter(folder / "history.csv", kept_samples)))
                frames = files.enter_context(closing(FrameWriter(folder, current, scene.output, kept_frames)))
                check_space(folder, frames.frame_bytes() * (len(output_times(scene)) + 1))
            except OutputError as error:  # a full disk: the summary says so, if there is room for it
                files.close()
                current.status = "output failed"
                with suppress(OutputError):
                    write_json(unstarted(scene, deck_path, str(error), current.status), folder / "summary.json")
                raise
            interval = scene.output.checkpoint_interval
            checkpoints = [Checkpoints(folder, interval, current.sim.state.t)] if interval else []
            writers = Timed(Listeners(history, frames, *checkpoints))
            try:
                solve(current, Listeners(writers, progress or Listener()))
            except (NumericalError, SceneTooLarge) as error:
                message = str(error)
            except KeyboardInterrupt as stop:
                message = str(stop) or "interrupted by the user"
            except OutputError as error:
                current.status, message = "output failed", str(error)
            finally:
                try:
                    files.close()
                except OutputError as error:  # what the files still held did not fit
                    current.status, message = "output failed", str(error)
                if frames.written > len(current.frame_times):  # in every series, though a checkpoint after it failed
                    current.frame_times.append(current.sim.state.t)
                result = summary(current, deck_path, plan(scene), message, writers.seconds)
                write_json(result, folder / "summary.json")
    return current, result
