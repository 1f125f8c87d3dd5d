"""A compiled function compiled by a second process while this one compiles others.

On an empty cache a first run compiles its kernels one after another on one core. The
element response is almost half of that, and the loops around it need only its type, as
they call it through its address (:func:`shellsim.compiled_call.held_by_address`). Where a
second CPU is free, :class:`CompiledBeside` has a second process compile the function into
the shared cache, its saves and this process's under the cache's lock
(:mod:`shellsim.cache_lock`), while a stand-in of the same type is held in its place; the
loops compile around the stand-in meanwhile, and :meth:`CompiledBeside.alongside` ends by
putting the function, loaded from the cache, in the stand-in's place.

Run as ``python -m shellsim.compile_beside``: compiles the function named by the
(module, name, signature) pickled on its standard input.
"""

from __future__ import annotations

import importlib
import os
import pickle
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from numba.core import event

from .cache_lock import lock_cache_saves
from .compiled_call import held_by_address, hold_instead
from .threads import usable_cpus


class CompiledBeside:
    """``dispatcher`` (a numba function cached on disk) compiled for ``signature`` and
    held for calls through its address (:attr:`held`).

    ``beside``: compile it in a second process (True), here at once (False), or where that
    pays (None): when the cache does not hold it yet and a second CPU is usable; never
    where the cache cannot be locked. While the second process compiles, the holder holds
    ``stand_in``, a function of the same signature; :meth:`alongside` runs the work that
    can go on meanwhile."""

    def __init__(self, dispatcher, stand_in, signature, beside: bool | None = None):
        self.dispatcher, self.signature = dispatcher, signature
        if beside is None:
            beside = usable_cpus() > 1 and not _cached(dispatcher, signature)
        beside = beside and lock_cache_saves()  # both processes save under the lock
        self._process = _start(dispatcher, signature) if beside else None
        self.held = held_by_address(stand_in if beside else dispatcher, signature)
        #: whether the holder holds the stand-in
        self.pending = beside

    @contextmanager
    def alongside(self) -> Iterator[None]:
        """The block runs while the second process compiles; after it, the function is held
        in the stand-in's place: loaded from the cache, or compiled here if the process
        failed. The wait is told as the function's compiling (the ``numba:compile`` event
        :mod:`shellsim.compile_watch` hears). A block or a wait that raises (an interrupt)
        stops the process."""
        try:
            yield
            if self._process is not None:
                data = {"dispatcher": self.dispatcher, "args": self.signature.args,
                        "return_type": self.signature.return_type}
                with event.trigger_event("numba:compile", data=data):
                    self._process.wait()
        except BaseException:
            if self._process is not None:
                self._process.kill()
                self._process.wait()
            raise
        if self.pending:
            hold_instead(self.held, self.dispatcher, self.signature)
            self.pending = False


def _cached(dispatcher, signature) -> bool:
    """Whether numba's cache holds ``dispatcher`` compiled for ``signature``. It reads
    numba's private cache index; should that change, this says True, and the function
    compiles here as it did before."""
    try:
        cache = dispatcher._cache
        return cache._index_key(signature, dispatcher.targetctx.codegen()) in cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 (any change in numba's private API)
        return True


def _start(dispatcher, signature) -> subprocess.Popen | None:
    """The second process compiling ``dispatcher`` for ``signature``, on this package's
    source; None when it cannot start (the function then compiles here)."""
    function = dispatcher.py_func
    package_parent = str(Path(__file__).resolve().parents[1])
    path = os.pathsep.join(filter(None, (package_parent, os.environ.get("PYTHONPATH"))))
    try:
        process = subprocess.Popen([sys.executable, "-m", __name__], stdin=subprocess.PIPE,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                   env=os.environ | {"PYTHONPATH": path})
        with process.stdin:
            pickle.dump((function.__module__, function.__qualname__, signature), process.stdin)
    except OSError:
        return None
    return process


def main() -> None:
    """The second process: compile the function read from standard input into the cache."""
    lock_cache_saves()
    module, name, signature = pickle.load(sys.stdin.buffer)
    getattr(importlib.import_module(module), name).compile(signature)


if __name__ == "__main__":
    main()
