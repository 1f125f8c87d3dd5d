"""The load factors: each curve's factor at the load time (the static ramp's too), a
measure family (:mod:`shellsim.solver.measures`) whose columns
:func:`shellsim.deck.columns.load_factor_columns` names."""

from __future__ import annotations

from ...curve_tables import factor
from ...deck.columns import load_factor_columns
from ...mesh import Mesh
from ...model import Model


class LoadFactors:
    """Each curve's factor at the run's load time (an arc-length path's own)."""

    NAME = "load_factors"
    sparse = False

    def __init__(self, curves: dict[str, int]):
        self.curves = curves  # column -> the curve's index in the model's tables
        self.columns = list(curves)

    def sample(self, run) -> list[float]:
        return [factor(run.model.curves, index, run.load_time) for index in self.curves.values()]

    def record(self, run, output_seconds: float) -> None:
        """A static run's summary gives the largest factors (``static``); nothing of its own."""


def resolve(deck, mesh: Mesh, model: Model) -> LoadFactors | None:
    """The deck's curves' factors (None without a curve or a static ramp)."""
    curves = load_factor_columns(deck)
    return LoadFactors(curves) if curves else None
