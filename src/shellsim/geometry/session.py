"""The one way shellsim talks to gmsh: imported lazily, initialised without taking over
Ctrl-C (so an interrupted run can still close its files), set up for complete
second-order quadrilaterals, and always finalised with the SIGINT handler restored."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def gmsh_session(name: str = "shellsim", verbose: bool = False) -> Iterator[Any]:
    """A fresh gmsh model for the duration of the block; yields the ``gmsh`` module.

    Options set: 9-node quads (``SecondOrderIncomplete = 0``), high-order nodes on the
    curved geometry (``SecondOrderLinear = 0``), recombination into quads.
    """
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGINT) if in_main_thread else None
    import gmsh  # lazily: importing gmsh may touch signal handlers in some versions

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 1 if verbose else 0)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        gmsh.option.setNumber("Mesh.SecondOrderLinear", 0)
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.model.add(name)
        yield gmsh
    finally:
        gmsh.finalize()
        if in_main_thread and signal.getsignal(signal.SIGINT) is not previous:
            signal.signal(signal.SIGINT, previous)
