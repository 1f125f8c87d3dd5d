"""Time curves: tables of (time, factor), never expressions. Loads and prescribed motions
are ``value * curve(t)``."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import field_validator, model_validator

from ..curve_tables import EXTRAPOLATION, INTERPOLATION, curve_value
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
