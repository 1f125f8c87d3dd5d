"""The contact penalty's push against depth, shared by every contact kind: a spring k
past a smoothing width w of touching, and within it the quadratic k (d + w)^2 / (4 w)
that meets the spring with the same value and slope at d = w and starts from nothing at
d = -w. The push and its derivative are continuous, so a Newton solve (static or
implicit) sees no kink where a node comes into contact or leaves it: a node that rests
on a surface carrying almost nothing (a ring lying flat along a plate) sits on a smooth
curve rather than at a corner its iterations would cycle around."""

from __future__ import annotations

from numba import njit

#: The smoothing width as a share of the contact's reach (the offset (h_y + h_p) / 2
#: between shells, h/2 against a tool): the push starts this far before the faces touch
#: (and an overlap of the initial shape within it is none).
TOUCHING = 1e-3


@njit(cache=True, inline="always")
def push(spring: float, depth: float, width: float) -> float:
    """The push [force] of a spring of stiffness ``spring`` [force/length] at ``depth``
    [length] (positive: overlapping) with the smoothing ``width`` [length]."""
    if depth <= -width:
        return 0.0
    if depth >= width:
        return spring * depth
    return spring * (depth + width) ** 2 / (4.0 * width)


@njit(cache=True, inline="always")
def stored(spring: float, depth: float, width: float) -> float:
    """The energy [force x length] the push of :func:`push` stores from d = -w to
    ``depth``: k (d + w)^3 / (12 w) within the width, (2/3) k w^2 + k (d^2 - w^2) / 2
    past it."""
    if depth <= -width:
        return 0.0
    if depth < width:
        return spring * (depth + width) ** 3 / (12.0 * width)
    return spring * (2.0 / 3.0 * width * width + 0.5 * (depth * depth - width * width))
