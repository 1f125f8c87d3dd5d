"""Work that sits in C code for long, run in a child process so a stop ends it at once.

gmsh meshes a surface without coming back to Python, where a Ctrl-C or SIGTERM would be
handled, for as long as the meshing takes (minutes for a size far too small); run in a
forked child, the parent waits on a pipe, which a signal interrupts, and kills the child.

A stop signal that arrives while the child is forked is noted and raised after (one
that arrived inside the fork's own hooks, the logging module's, was dropped there), and
the child is killed by the system when its parent dies however it dies (a parent killed
outright left gmsh meshing on, a full core and its memory, holding its caller's pipes
open).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
from collections.abc import Callable
from typing import Any

from ..errors import MeshError
from ..signals import STOP_SIGNALS, handling

#: prctl's option that has the system send a signal to a process when its parent dies (Linux).
PR_SET_PDEATHSIG = 1


def in_child(function: Callable[..., Any], *args: Any) -> Any:
    """``function(*args)`` in a forked child process: its result, or its exception raised
    here. A KeyboardInterrupt (or any exception) while waiting kills the child first."""
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_serve, args=(send, os.getpid(), function, args), daemon=True)
    try:
        _start(child)
        send.close()
        succeeded, value = receive.recv()
    except EOFError:  # the child died without an answer (killed, out of memory)
        child.join()
        raise MeshError(f"the meshing process ended without an answer (exit code {child.exitcode})") from None
    finally:
        if child.pid is not None:  # started
            if child.is_alive():
                child.kill()
            child.join()
        receive.close()
    if succeeded:
        return value
    raise value


def _start(child) -> None:
    """Fork ``child``, a stop signal that arrives meanwhile only noted, and raised once the
    fork is done. Raised while the fork runs its hooks (the logging module's), the
    interrupt was printed as ignored there and lost; blocking the signal in this thread
    is not enough, as another thread (a progress display's) may take it for the process."""
    noted: list[int] = []
    with handling({number: lambda number, frame: noted.append(number) for number in STOP_SIGNALS}):
        child.start()
    if noted:
        signal.raise_signal(noted[0])  # to the handler the caller has


def _die_with(parent: int) -> None:
    """Have the system kill this process when its parent (pid ``parent``) dies; if it
    has died already, end now. Where prctl is not to be had (not Linux), nothing."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:
        os._exit(1)


def _serve(send, parent: int, function: Callable[..., Any], args: tuple) -> None:
    """The child: it dies with its ``parent``, the stop signals end it at once (the
    parent reports them), and the outcome goes back through ``send`` as (succeeded,
    result or exception)."""
    _die_with(parent)
    for number in STOP_SIGNALS:
        signal.signal(number, signal.SIG_DFL)
    try:
        outcome = (True, function(*args))
    except Exception as error:  # noqa: BLE001 - every failure is the parent's to raise
        outcome = (False, error)
    send.send(outcome)
    send.close()
