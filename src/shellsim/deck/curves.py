"""Time curves: tables of (time, factor), given in the deck or read from a CSV file,
repeated for periodic loads, never expressions. Loads and prescribed motions are
``value * curve(t)``."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import field_validator, model_validator

from ..curve_tables import EXTRAPOLATION, INTERPOLATION, curve_value
from ..table_types import Count, Positive, Real, Section


class Curve(Section):
    """A tabulated factor of time: ``t`` and ``value``, or ``file``.

    ``interpolate``: ``linear`` between points, ``step`` (holds the value of the last point
    passed), ``smooth`` (cubic with zero slope at every point, so a ramp starts and ends
    without a jolt) or ``smooth_step`` (Abaqus' SMOOTH STEP: the quintic u^3 (10 - 15 u +
    6 u^2) between points, zero slope and curvature at each). ``extrapolate``: beyond the table, ``constant`` holds the end values,
    ``linear`` continues the end segments.

    ``file``: a CSV file of (time, value) rows (a path relative to the deck; header lines
    and ``#`` comments are skipped; columns separated by semicolons, tabs, commas or
    spaces, decimal commas read where the columns are not comma-separated), its times multiplied by ``time_scale`` and its values
    by ``value_scale`` into the deck's units (a file in ms into an SI deck takes
    ``time_scale = 0.001``; a pressure in mmHg is a factor of a load of ``value =
    133.322`` Pa). ``repeat``: the table's cycles end to end, a waveform over several
    beats; a cycle lasts ``period``, by default the table's span (its last point is then
    the next cycle's first).
    """

    t: list[Real] | None = None
    value: list[Real] | None = None
    file: str | None = None
    time_scale: Positive = 1.0
    value_scale: Real = 1.0
    interpolate: Literal["linear", "step", "smooth", "smooth_step"] = "linear"
    extrapolate: Literal["constant", "linear"] = "constant"
    repeat: Count = 1
    period: Positive | None = None

    @field_validator("t")
    @classmethod
    def _increasing(cls, t: list[float] | None) -> list[float] | None:
        if t is None:
            return t
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
    def _one_table(self) -> "Curve":
        if self.file is not None:
            if self.t is not None or self.value is not None:
                raise ValueError("give the table either as 't' and 'value' or as 'file', not both")
            return self
        if self.t is None or self.value is None:
            raise ValueError("needs 't' and 'value' (one value per time), or 'file' (a CSV of time, value rows)")
        if len(self.value) != len(self.t):
            raise ValueError(
                f"'value' has {len(self.value)} entries but 't' has {len(self.t)}; "
                "give one value per time"
            )
        if len(self.t) * self.repeat > MOST_POINTS:
            raise ValueError(f"'repeat' = {self.repeat} cycles of {len(self.t)} points make "
                             f"{len(self.t) * self.repeat:,} points; at most {MOST_POINTS:,} are expected")
        if self.period is not None and self.period < self.t[-1] - self.t[0]:
            raise ValueError(f"'period' = {self.period} is shorter than the table's span, "
                             f"{self.t[-1] - self.t[0]:g}: one cycle would overlap the next")
        return self

    def __call__(self, time: float | np.ndarray) -> float | np.ndarray:
        """Factor at ``time`` (scalar or array, same shape back)."""
        table = self.table()
        x = np.asarray(time, dtype=float)
        out = np.array([curve_value(*table, float(ti)) for ti in x.ravel()]).reshape(x.shape)
        return out if x.ndim else float(out)

    def table(self) -> tuple[np.ndarray, np.ndarray, int, int]:
        """(times, values, interpolation code, extrapolation code) for :func:`curve_value`,
        the cycles repeated. Only for a curve with its table (a file's is read by
        :func:`with_file_tables`)."""
        t, v = np.asarray(self.t, dtype=float), np.asarray(self.value, dtype=float)
        period = self.period if self.period is not None else t[-1] - t[0]
        if self.repeat > 1 and period > 0:
            joined = period == t[-1] - t[0]  # the last point is the next cycle's first
            later_t, later_v = (t[1:], v[1:]) if joined else (t, v)
            t = np.concatenate([t] + [later_t + k * period for k in range(1, self.repeat)])
            v = np.concatenate([v] + [later_v] * (self.repeat - 1))
        return t, v, INTERPOLATION[self.interpolate], EXTRAPOLATION[self.extrapolate]


def with_file_tables(curve: Curve, base_dir: Path | None) -> Curve:
    """``curve`` with its file's table in place of the file (times and values scaled, the
    scales then 1), so the resolved deck holds it; a curve without a file as it is.
    Raises ValueError naming the file, the line and what was expected."""
    if curve.file is None:
        return curve
    path = Path(curve.file)
    path = path if path.is_absolute() or base_dir is None else base_dir / path
    t, value = read_table(path)
    data = curve.model_dump(exclude={"file", "time_scale", "value_scale"}, exclude_none=True)
    data.update(t=[curve.time_scale * x for x in t], value=[curve.value_scale * x for x in value])
    return Curve.model_validate(data)


#: The largest waveform file read (a CSV of a million rows is about 20 MB) and the most
#: points a curve may hold once repeated: a mistyped size or repeat count would otherwise
#: fill the memory.
MOST_BYTES, MOST_POINTS = 64 * 2**20, 10**7


def read_table(path: Path) -> tuple[list[float], list[float]]:
    """The (time, value) rows of a CSV file, the first two columns; lines before the first
    row of numbers (a header) and ``#`` comments skipped; a byte-order mark accepted.

    Columns are separated by semicolons, tabs, commas or spaces, the file's first data
    row deciding which: with semicolons or tabs between the columns, a comma inside a
    number is a decimal comma (``0,5;80,0`` is 0.5 and 80.0, as spreadsheets in many
    locales write it); with commas between them, a decimal comma cannot be told from a
    column and the file must use points. Raises ValueError naming the file and line for
    a row that is not two finite numbers, decreasing times, a file that is not a regular
    file or is larger than MOST_BYTES."""
    try:
        if not path.is_file():
            raise ValueError(f"file '{path}' not found" if not path.exists() else
                             f"file '{path}' is not a regular file (a pipe or device cannot be a waveform)")
        if path.stat().st_size > MOST_BYTES:
            raise ValueError(f"file '{path}' has {path.stat().st_size / 2**20:.0f} MiB; a waveform table is "
                             f"expected to be under {MOST_BYTES // 2**20} MiB")
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"file '{path}' cannot be read: {getattr(error, 'strerror', None) or error}") from None
    t: list[float] = []
    value: list[float] = []
    separator = None
    for number, line in enumerate(lines, start=1):
        text = line.split("#")[0].strip()
        if not text:
            continue
        row_separator = separator or _separator(text)
        row = _numbers(text, row_separator)
        if row is None:
            if not t:
                continue  # a header
            raise ValueError(f"file '{path}' line {number}: expected a time and a value, found '{line.strip()}'")
        separator = row_separator
        if not all(np.isfinite(row)):
            raise ValueError(f"file '{path}' line {number}: expected finite numbers, found '{line.strip()}'")
        if t and row[0] <= t[-1]:
            raise ValueError(f"file '{path}' line {number}: times must be strictly increasing, but "
                             f"{row[0]:g} follows {t[-1]:g}")
        t.append(row[0])
        value.append(row[1])
    if not t:
        raise ValueError(f"file '{path}' holds no (time, value) rows")
    return t, value


def _separator(text: str) -> str:
    """The column separator of a data row: ';', a tab, ',' or spaces (' ')."""
    for candidate in (";", "\t", ","):
        if candidate in text:
            return candidate
    return " "


def _numbers(text: str, separator: str) -> list[float] | None:
    """The first two columns of a row as numbers (non-finite ones included), or None when
    they are not numbers (a header). Decimal commas are read where the separator is not
    a comma."""
    fields = [f.strip() for f in (text.split() if separator == " " else text.split(separator))]
    fields = [f for f in fields if f]
    if len(fields) < 2:
        return None
    if separator != ",":
        fields = [f.replace(",", ".") for f in fields[:2]]
    try:
        return [float(f) for f in fields[:2]]
    except ValueError:
        return None
