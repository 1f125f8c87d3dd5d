"""Signal handlers set for the length of a block: a run holds a stop while it writes a
frame (:func:`shellsim.solver.run.interrupt_deferred`), the command line turns SIGTERM
into an interrupt (:func:`shellsim.cli.sigterm_as_interrupt`), and a solve notes each stop
that arrives (:func:`noting_stops`)."""

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


@contextmanager
def noting_stops() -> Iterator[list[int]]:
    """Within the block each stop signal whose handler is Python's own is noted in the list
    yielded, then handled as before. A stop that lands while a compiled call converts its
    arguments surfaces as that conversion's error (numba's "can't unbox ... as a <NULL>"),
    not as the handler's KeyboardInterrupt; the list tells that such an error was a stop."""
    arrived: list[int] = []

    def noted(previous: Callable) -> Callable:
        def note(number: int, frame: object) -> None:
            arrived.append(number)
            previous(number, frame)
        return note

    current = {number: signal.getsignal(number) for number in STOP_SIGNALS}
    with handling({number: noted(handler) for number, handler in current.items() if callable(handler)}):
        yield arrived
