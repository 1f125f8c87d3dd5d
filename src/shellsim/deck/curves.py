"""Time curves: tables of (time, factor), never expressions. Loads and prescribed motions
are ``value * curve(t)``."""

from __future__ import annotations

from typing import Literal

import numpy as np
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
        t = np.asarray(self.t)
        v = np.asarray(self.value)
        x = np.asarray(time, dtype=float)
        if len(t) == 1:
            return np.full_like(x, v[0]) if x.ndim else float(v[0])
        i = np.clip(np.searchsorted(t, x, side="right") - 1, 0, len(t) - 2)
        u = (x - t[i]) / (t[i + 1] - t[i])
        inside = (x >= t[0]) & (x <= t[-1])
        if self.interpolate == "step":
            out = np.where(x >= t[i + 1], v[i + 1], v[i])
        else:
            w = np.clip(u, 0.0, 1.0)
            if self.interpolate == "smooth":
                w = w * w * (3.0 - 2.0 * w)
            out = v[i] + w * (v[i + 1] - v[i])
        if self.extrapolate == "linear":
            linear = v[i] + u * (v[i + 1] - v[i])
            out = np.where(inside, out, linear)
        else:
            out = np.where(x < t[0], v[0], np.where(x > t[-1], v[-1], out))
        return out if x.ndim else float(out)
