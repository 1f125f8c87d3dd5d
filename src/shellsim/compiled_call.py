"""Calling a compiled function again and again with arguments of the same types.

numba's dispatcher works out the type of every argument on every call; for the bundles
of :mod:`shellsim.bundles` (dozens of arrays) that takes about 1.8 ms a call, far more
than a small mesh's time step. A :class:`TypedCall` asks the dispatcher once, then calls
the entry point compiled for those types directly (about 13 us)."""

from __future__ import annotations

from numba import typeof


class TypedCall:
    """``dispatcher`` (a numba function) for calls whose arguments keep the types, array
    layouts included, of the first call (the caller's fixed arrays and Python scalars)."""

    def __init__(self, dispatcher):
        self.dispatcher = dispatcher
        self.entry_point = None

    def __call__(self, *args):
        if self.entry_point is not None:
            return self.entry_point(*args)
        result = self.dispatcher(*args)  # compiles, or loads from the cache
        self.entry_point = self.dispatcher.overloads[tuple(typeof(a) for a in args)].entry_point
        return result
