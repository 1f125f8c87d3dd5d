"""How a series stores its numbers: their precision and compression (deck:
``output.precision``, ``output.compress``), and a symmetric tensor as its six components."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..deck.schema import Output

#: A symmetric tensor's six components as written: (row, column) in VTK's order, which
#: ParaView names XX, YY, ZZ, XY, YZ, XZ whatever the reader (nine components it numbers 0-8).
SYMMETRIC_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))
_ROWS, _COLUMNS = np.array(SYMMETRIC_PAIRS).T


@dataclass(frozen=True)
class Encoding:
    """Floats stored as ``float_type`` (float32 or float64), compressed (losslessly) or not."""

    float_type: type = np.float32
    compress: bool = True

    @classmethod
    def of(cls, output: Output) -> "Encoding":
        return cls(np.float32 if output.precision == "single" else np.float64, output.compress)

    def floats(self, values: np.ndarray) -> np.ndarray:
        """``values`` as contiguous floats of the stored precision: beyond float32's range,
        +-inf (the last frame of a run that blew up is written as it is, without a warning)."""
        with np.errstate(over="ignore"):
            return np.ascontiguousarray(values, dtype=self.float_type)


def symmetric_columns(tensors: np.ndarray) -> np.ndarray:
    """Symmetric tensors (..., 3, 3) as their six components (..., 6), in SYMMETRIC_PAIRS' order."""
    return tensors[..., _ROWS, _COLUMNS]


def symmetric_tensors(columns: np.ndarray) -> np.ndarray:
    """The symmetric tensors (..., 3, 3) of their six components (..., 6)."""
    tensors = np.empty((*columns.shape[:-1], 3, 3), dtype=columns.dtype)
    tensors[..., _ROWS, _COLUMNS] = columns
    tensors[..., _COLUMNS, _ROWS] = columns
    return tensors
