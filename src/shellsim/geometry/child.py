"""Work that sits in C code for long, run in a child process so a stop ends it at once.

gmsh meshes a surface without coming back to Python, where a Ctrl-C or SIGTERM would be
handled, for as long as the meshing takes (minutes for a size far too small); run in a
forked child, the parent waits on a pipe, which a signal interrupts, and kills the child.
"""

from __future__ import annotations

import multiprocessing
import signal
from collections.abc import Callable
from typing import Any

from ..errors import MeshError


def in_child(function: Callable[..., Any], *args: Any) -> Any:
    """``function(*args)`` in a forked child process: its result, or its exception raised
    here. A KeyboardInterrupt (or any exception) while waiting kills the child first."""
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_serve, args=(send, function, args), daemon=True)
    child.start()
    send.close()
    try:
        succeeded, value = receive.recv()
    except EOFError:  # the child died without an answer (killed, out of memory)
        child.join()
        raise MeshError(f"the meshing process ended without an answer (exit code {child.exitcode})") from None
    finally:
        if child.is_alive():
            child.kill()
        child.join()
        receive.close()
    if succeeded:
        return value
    raise value


def _serve(send, function: Callable[..., Any], args: tuple) -> None:
    """The child: the stop signals end it at once (the parent reports them), and the
    outcome goes back through ``send`` as (succeeded, result or exception)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        outcome = (True, function(*args))
    except Exception as error:  # noqa: BLE001 - every failure is the parent's to raise
        outcome = (False, error)
    send.send(outcome)
    send.close()
