"""What numba is compiling, told as it happens.

A new version of shellsim (or a new machine) compiles its kernels on the first run and
caches them; that takes minutes, and a frozen progress line looks like a hang. numba
announces each compilation as an event: :func:`watching_compiles` hears the outermost
ones and tells a callback which kernel is compiling and, when it is done, how long it took.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from numba.core import event

#: What a user is told when a scene's kernels compile: once per version, and how long for
#: a first scene from an empty cache (docs/verification.md; a later scene with other load
#: or contact kinds compiles its own time loop, a fraction of that).
FIRST_RUN_NOTE = ("once for this version of shellsim: about half a minute for a first scene on 2 idle cores, "
                  "several times that on a busy machine; later runs load them")
#: Kernels that compile longer than this [s] are named when done; the rest pass quietly.
WORTH_TELLING = 5.0


def finished_text(name: str, seconds: float) -> str | None:
    """The line that tells a kernel has compiled, for one that took a while (else None)."""
    return f"compiled {name} in {seconds:.0f} s" if seconds >= WORTH_TELLING else None


def kernel_name(dispatcher) -> str:
    """A compiled function's name as the package knows it: 'solver.explicit.forces'."""
    function = dispatcher.py_func
    return f"{function.__module__.removeprefix('shellsim.')}.{function.__qualname__}"


class CompileListener(event.Listener):
    """Calls ``on_start(name)`` when an outermost compilation begins and
    ``on_end(name, seconds)`` when it ends (the kernels it calls compile inside it)."""

    def __init__(self, on_start: Callable[[str], None], on_end: Callable[[str, float], None]):
        self.on_start_kernel, self.on_end_kernel = on_start, on_end
        self.depth = 0
        self.started = 0.0

    def on_start(self, ev) -> None:
        self.depth += 1
        if self.depth == 1:
            self.started = time.perf_counter()
            self.on_start_kernel(kernel_name(ev.data["dispatcher"]))

    def on_end(self, ev) -> None:
        self.depth -= 1
        if self.depth == 0:
            self.on_end_kernel(kernel_name(ev.data["dispatcher"]), time.perf_counter() - self.started)


@contextmanager
def watching_compiles(on_start: Callable[[str], None], on_end: Callable[[str, float], None]) -> Iterator[None]:
    """Inside the block, every outermost compilation is told to ``on_start`` and ``on_end``."""
    with event.install_listener("numba:compile", CompileListener(on_start, on_end)):
        yield
