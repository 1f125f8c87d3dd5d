"""Copying one array into another of the same size inside compiled code, element by
element: numba compiles an array-to-array slice assignment with a shape check whose error
message formats both shapes, a few seconds of first-run compiling for each kind of array."""

from numba import njit


@njit(cache=True)
def copy_into(source, target):
    """target[...] = source, both of the same size, any shapes, element by element."""
    for i in range(source.size):
        target.flat[i] = source.flat[i]
