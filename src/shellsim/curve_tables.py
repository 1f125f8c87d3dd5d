"""Time curves evaluated from their tables, compiled: the deck's :class:`~shellsim.deck.curves.Curve`
and the time loop read factors through the same function."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .bundles import Curves

#: Codes of a table's interpolation and extrapolation.
INTERPOLATION = {"linear": 0, "step": 1, "smooth": 2, "smooth_step": 3}
EXTRAPOLATION = {"constant": 0, "linear": 1}


@njit(cache=True)
def curve_value(t: np.ndarray, v: np.ndarray, interpolate: int, extrapolate: int, time: float) -> float:
    """A curve's factor at ``time`` from its table t, v (K,); codes as in INTERPOLATION and
    EXTRAPOLATION."""
    n = t.shape[0]
    if n == 1:
        return v[0]
    if time <= t[0] or time >= t[n - 1]:
        i = 0 if time <= t[0] else n - 2
        if extrapolate == 1:
            return v[i] + (time - t[i]) / (t[i + 1] - t[i]) * (v[i + 1] - v[i])
        return v[0] if time <= t[0] else v[n - 1]
    i = knot_interval(t, time)
    u = (time - t[i]) / (t[i + 1] - t[i])
    if interpolate == 1:
        return v[i]
    if interpolate == 2:
        u = u * u * (3.0 - 2.0 * u)
    elif interpolate == 3:
        u = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
    return v[i] + u * (v[i + 1] - v[i])


# a bisection of its own: np.searchsorted compiles numba's comparisons for every dtype,
# complex ones included, for about a second on a first run
@njit(cache=True)
def knot_interval(t, time):
    """i with t[i] <= time < t[i + 1] (the last such knot where knots repeat), for a time
    strictly inside the table t (K,), ascending."""
    low, high = 0, t.shape[0] - 1
    while high - low > 1:
        middle = (low + high) // 2
        if t[middle] <= time:
            low = middle
        else:
            high = middle
    return low


@njit(cache=True)
def factor(curves, index, time):
    """Factor of curve ``index`` of the tables ``curves`` (:class:`shellsim.bundles.Curves`)
    at ``time``; 1 for index -1 (a constant load)."""
    if index < 0:
        return 1.0
    n = curves.length[index]
    return curve_value(curves.t[index, :n], curves.v[index, :n], curves.interp[index], curves.extrap[index], time)


@njit(cache=True)
def rate(curves, index, time):
    """The time derivative of curve ``index``'s factor at ``time`` (central differences
    over a millionth of its table's span; the mean of the two slopes at a knot); 0 for
    index -1."""
    if index < 0 or curves.length[index] < 2:
        return 0.0
    n = curves.length[index]
    step = 1e-6 * (curves.t[index, n - 1] - curves.t[index, 0])
    return (factor(curves, index, time + step) - factor(curves, index, time - step)) / (2.0 * step)


def held_from(curves: Curves, which=None) -> float:
    """The time from which every curve of ``curves`` (or those of the indices ``which``)
    holds its value: the latest of their last changes (0 for none; inf when one is
    extrapolated linearly past a change)."""
    latest = 0.0
    for c in range(len(curves.length)) if which is None else which:
        n = int(curves.length[c])
        t, v = curves.t[c, :n], curves.v[c, :n]
        changes = np.flatnonzero(v[1:] != v[:-1])
        if not changes.size:
            continue
        if curves.extrap[c] == EXTRAPOLATION["linear"] and changes[-1] == n - 2:
            return math.inf
        latest = max(latest, float(t[changes[-1] + 1]))
    return latest
