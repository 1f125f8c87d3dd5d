"""Calling a compiled function again and again with arguments of the same types.

numba's dispatcher works out the type of every argument on every call; for the bundles
of :mod:`shellsim.bundles` (dozens of arrays) that takes about 1.8 ms a call, far more
than a small mesh's time step. A :class:`TypedCall` asks the dispatcher once, then calls
the entry point compiled for those types directly (about 13 us). A compiled function that
other compiled functions take as an argument is handed to them held
(:func:`held_by_address`), and they call it through its address."""

from __future__ import annotations

from numba import njit, typeof, types
from numba.typed import List


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


def held_by_address(dispatcher, signature) -> List:
    """``dispatcher`` (a numba function) compiled for ``signature`` (argument types exact:
    no conversions), held for compiled callers that take it as an argument ``f`` and
    call ``f[0](...)`` through its address, as numba's first-class functions are called.

    A callee named in its caller's code, or handed over as itself, is linked into the
    caller, whose compiling then optimises and emits the callee's whole code once more.
    The holder is a typed list of one: a first-class function handed over from Python
    is looked up on every call (about 0.1 ms), a typed list only once, here."""
    return _entry_point(_hold, (types.FunctionType(signature),))(dispatcher)


def hold_instead(held: List, dispatcher, signature) -> None:
    """Put ``dispatcher``, compiled for ``signature`` (or loaded from the cache), in the
    holder ``held`` (:func:`held_by_address`, the same signature) in place of the function
    it holds: the callers given the holder call it from then on."""
    _entry_point(_put, (typeof(held), types.FunctionType(signature)))(held, dispatcher)


def hold_also(held: List, dispatcher, signature) -> None:
    """Append ``dispatcher``, compiled for ``signature``, to the holder ``held``
    (:func:`held_by_address`, the same signature): callers call it as ``f[1](...)``,
    ``f[2](...)``, ... in the order held."""
    _entry_point(_append, (typeof(held), types.FunctionType(signature)))(held, dispatcher)


def _entry_point(dispatcher, argument_types):
    """The code of ``dispatcher`` compiled for exactly ``argument_types`` (or loaded from
    the cache), called without numba's typing: a function handed over as the function type
    it is converted to, not as its own dispatcher's type."""
    dispatcher.compile(argument_types)
    return dispatcher.overloads[argument_types].entry_point


@njit(cache=True)
def _hold(function):
    held = List()
    held.append(function)
    return held


@njit(cache=True)
def _put(held, function):
    held[0] = function


@njit(cache=True)
def _append(held, function):
    held.append(function)
