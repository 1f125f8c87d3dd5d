"""Shared test helpers: a minimal valid deck to build variants from."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
# The console the command line prints to is 80 columns wide in every test, whatever the
# terminal the suite runs in: messages and tables wrap the same way, so no outcome depends
# on it (subprocesses inherit it too).
os.environ["COLUMNS"] = "80"
os.environ.pop("LINES", None)
if os.environ.get("PYTEST_XDIST_WORKER"):
    # one test process per core already: a worker's kernels run on one thread each
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")

ROOT = Path(__file__).resolve().parents[1]
#: Scene decks shipped (studies, which name decks, live in decks/studies and are not decks).
DECKS = sorted(p for p in (ROOT / "decks").rglob("*.toml") if "studies" not in p.relative_to(ROOT / "decks").parts)
STUDIES = sorted((ROOT / "decks" / "studies").glob("*.toml"))

BASE = """
[meta]
title = "test scene"

[material]
model = "linear_elastic"
E = 1000.0
nu = 0.3
density = 1.0

[section]
thickness = 0.01

[solver]
end_time = 1.0
"""


def pytest_configure(config):
    """Under pytest-xdist, compile the numba cache here, once, before the workers start:
    workers compiling the same kernels into one cache at once have crashed (the pitfall
    the study executor avoids the same way)."""
    if getattr(config.option, "numprocesses", None) and not hasattr(config, "workerinput"):
        import time

        from shellsim.compile_watch import watching_compiles
        from shellsim.study.executor import warm_numba_cache

        start = time.perf_counter()
        compiled = []
        note = ("compiling the kernels of three scenes, once for this version: about a minute and a half on 2 idle "
                "cores, several times that on a busy machine")
        with watching_compiles(lambda name: compiled or print(note, flush=True),
                               lambda name, seconds: compiled.append(name)):
            warm_numba_cache()
        if compiled:
            print(f"compiled {len(compiled)} kernels in {time.perf_counter() - start:.0f} s", flush=True)


def prepared(deck, base_dir: Path | None = None):
    """A run of ``deck`` ready to start as ``shellsim run`` builds it: mesh (a mesh file's
    path relative to ``base_dir``; an imaged scene's unloaded shape), model and simulation."""
    from shellsim.execute import built_run

    return built_run(deck, base_dir)


def initial_shape(model):
    """A :class:`shellsim.bundles.Shape` of ``model``'s initial state (copies)."""
    from shellsim.bundles import Shape

    return Shape(x=model.x0.copy(), d=model.d0.copy(), e1=model.e1f0.copy(), h=model.h0.copy())


def initial_external_forces(model, t: float = 0.0):
    """(f, g) (n, 3): the external forces of ``model`` at time t on its initial shape, and
    their director-conjugate part (which external_forces turns into rotational forces)."""
    import numpy as np

    from shellsim.loads import external_forces

    n = model.n_nodes
    f, fr, g = np.zeros((n, 3)), np.zeros((n, 2)), np.zeros((n, 3))
    external_forces(float(t), model, initial_shape(model), f, fr, g)
    return f, g


def run_deck(deck, base_dir: Path | None = None):
    """``deck`` run to its end time (or solved statically over it)."""
    from shellsim.execute import solve

    return solve(prepared(deck, base_dir))


#: The thickness of the plates :func:`pressed_plates` presses together.
PLATE_THICKNESS = 0.01


def pressed_plates_deck(path: Path, p: float, solver: str, held: str = '["x", "y"]', more: str = "") -> str:
    """A deck of the upper of :func:`shellsim.bench.stacked_plates` (3 x 3 over 4 x 4,
    thickness PLATE_THICKNESS, written to ``path``) pushed onto the clamped lower one by a
    pressure p, its translations ``held`` (TOML list), under the ``solver`` table, with
    ``more`` keys of the contact table and tables after it."""
    from shellsim.bench import stacked_plates

    return deck_text(f'builder = "file"\npath = "{stacked_plates(path, 4, 3, thickness=PLATE_THICKNESS).as_posix()}"', f'''
[[boundary]]
type = "clamped"
set = "lower"
[[boundary]]
type = "fixed"
set = "upper"
translations = {held}
[[load]]
type = "pressure"
set = "upper"
value = {-p}
[[contact]]
type = "shells"
name = "between"
set = "upper"
against = "lower"
{more}''').replace("[solver]\nend_time = 1.0", solver)


def pressed_plates(path: Path, p: float, method: str):
    """The plates of :func:`pressed_plates_deck` solved statically or explicitly with
    damping until they settle."""
    from shellsim.deck import parse_deck

    solver = ('[solver]\nmethod = "static"\nend_time = 1.0\nstatic = { newton = "full" }' if method == "static"
              else "[solver]\nend_time = 1.0\ndamping = 50.0")
    return run_deck(parse_deck(pressed_plates_deck(path, p, solver)))


#: A 2 x 1 plate's geometry and tables for deck_text: clamped along x = 0, a pressure of
#: 0.01 on every element; the pressure's table comes last, open for a curve key.
CLAMPED_PLATE = ('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', """
[[boundary]]
type = "clamped"
set = "x0"

[[load]]
type = "pressure"
value = 0.01
set = "all"
""")


#: A rectangle strip on rollers along its edges x0 and y0 and held in its plane z = 0
#: (the builder's sets): free to stretch and contract in its plane.
ROLLERS = """
[[boundary]]
type = "symmetry"
set = "x0"
normal = [1.0, 0.0, 0.0]
[[boundary]]
type = "symmetry"
set = "y0"
normal = [0.0, 1.0, 0.0]
[[boundary]]
type = "fixed"
set = "all"
translations = ["z"]
"""


def deck_text(geometry: str, extra: str = "", base: str = BASE) -> str:
    """A valid deck: ``base`` + [geometry] body + extra tables."""
    return f"{base}\n[geometry]\n{geometry}\n{extra}"


def problems_of(text: str) -> str:
    """The message a deck of ``text`` is refused with (read as 'broken.toml', which the
    message names first)."""
    from shellsim.deck import parse_deck
    from shellsim.errors import DeckError

    with pytest.raises(DeckError) as caught:
        parse_deck(text, name="broken.toml")
    message = str(caught.value)
    assert message.startswith("broken.toml:")
    return message


@pytest.fixture
def scene():
    """Parse a deck built by :func:`deck_text`."""
    from shellsim.deck import parse_deck

    return lambda geometry, extra="": parse_deck(deck_text(geometry, extra))


def cylinder_stl(path: Path, radius: float, length: float, around: int = 128, along: int = 48) -> Path:
    """An open cylinder about z, z in [0, length], as 2 x around x along facets."""
    from shellsim.verify.surfaces import tube_facets, write_facets

    return write_facets(path, *tube_facets(radius, radius, length, around, along))


@pytest.fixture
def ctrl_c_delivered():
    """Ctrl-C raising KeyboardInterrupt in this process for the test, and the default
    action in the processes it starts, however the suite was started and whatever ran
    before in its worker: a shell starting it in the background (``make test &``) has it
    ignored, and children inherit that (and a blocked signal)."""

    def in_the_child() -> None:  # a child's preexec_fn
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    yield in_the_child
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    signal.signal(signal.SIGINT, previous)
