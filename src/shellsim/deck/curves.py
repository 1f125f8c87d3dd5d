"""Time curves: tables of (time, factor), never expressions. Loads and prescribed motions
are ``value * curve(t)``."""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit
from pydantic import field_validator, model_validator

from .types import Real, Section


class Curve(Section):
    """A tabulated factor of time.

    ``interpolate``: ``linear`` between points, ``step`` (holds the value of the last point
    passed) or ``smooth`` (cubic with zero slope at every point, so a ramp starts and ends
    without a jolt). ``extrapolate``: beyond the table, ``constant`` holds the end values,
    ``linear`` continues the end segments.
    """

    t: list[Real]
    value: list[Real]
    interpolate: Literal["linear", "step", "smooth"] = "linear"
    extrapolate: Literal["constant", "linear"] = "constant"

    @field_validator("t")
    @classmethod
    def _increasing(cls, t: list[float]) -> list[float]:
        if len(t) < 1:
            raise ValueError("needs at least one point")
        steps = np.diff(t)
        if np.any(steps <= 0):
            bad = int(np.argmax(steps <= 0))
            raise ValueError(
                f"times must be strictly increasing, but t[{bad + 1}] = {t[bad + 1]} "
                f"follows t[{bad}] = {t[bad]}"
            )
        return t

    @model_validator(mode="after")
    def _same_length(self) -> "Curve":
        if len(self.value) != len(self.t):
            raise ValueError(
                f"'value' has {len(self.value)} entries but 't' has {len(self.t)}; "
                "give one value per time"
            )
        return self

    def __call__(self, time: float | np.ndarray) -> float | np.ndarray:
        """Factor at ``time`` (scalar or array, same shape back)."""
        table = self.table()
        x = np.asarray(time, dtype=float)
        out = np.array([curve_value(*table, float(ti)) for ti in x.ravel()]).reshape(x.shape)
        return out if x.ndim else float(out)

    def table(self) -> tuple[np.ndarray, np.ndarray, int, int]:
        """(times, values, interpolation code, extrapolation code) for :func:`curve_value`."""
        return (np.asarray(self.t, dtype=float), np.asarray(self.value, dtype=float),
                INTERPOLATION[self.interpolate], EXTRAPOLATION[self.extrapolate])


INTERPOLATION = {"linear": 0, "step": 1, "smooth": 2}
EXTRAPOLATION = {"constant": 0, "linear": 1}


@njit(cache=True)
def curve_value(t: np.ndarray, v: np.ndarray, interpolate: int, extrapolate: int, time: float) -> float:
    """A curve's factor at ``time``; codes as in INTERPOLATION and EXTRAPOLATION. Used by
    :class:`Curve` and inside the compiled time loop alike."""
    n = t.shape[0]
    if n == 1:
        return v[0]
    if time <= t[0] or time >= t[n - 1]:
        i = 0 if time <= t[0] else n - 2
        if extrapolate == 1:
            return v[i] + (time - t[i]) / (t[i + 1] - t[i]) * (v[i + 1] - v[i])
        return v[0] if time <= t[0] else v[n - 1]
    i = np.searchsorted(t, time, side="right") - 1
    u = (time - t[i]) / (t[i + 1] - t[i])
    if interpolate == 1:
        return v[i]
    if interpolate == 2:
        u = u * u * (3.0 - 2.0 * u)
    return v[i] + u * (v[i + 1] - v[i])
