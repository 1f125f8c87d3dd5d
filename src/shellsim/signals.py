"""Signal handlers set for the length of a block: a run holds a stop while it writes a
frame (:func:`shellsim.solver.run.interrupt_deferred`), the command line turns SIGTERM
into an interrupt (:func:`shellsim.cli.sigterm_as_interrupt`)."""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

#: Signals that stop a run (Ctrl-C, and SIGTERM where the command line handles it).
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextmanager
def handling(handlers: dict[int, Callable]) -> Iterator[None]:
    """Signal number -> handler within the block, the previous handlers restored after.
    Handlers can only be set from the main thread; elsewhere the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, handler) for number, handler in handlers.items()}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
