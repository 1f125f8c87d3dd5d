"""The load factors: each curve's factor at the load time (the static ramp's too), a
measure family (:mod:`shellsim.measures`) every scene with a curve has; no table asks
for it."""

from __future__ import annotations

from ..curve_tables import factor
from ..bundles import Model
from ..mesh import Mesh
from .column import Column


def load_factor_columns(deck) -> dict[str, int]:
    """The history columns of the curves' factors at the load time, each with its curve's
    index in the model's tables: ``load_factor_<curve>`` for every deck curve, and
    ``load_factor`` for the ramp that the loads without a curve of a static solve or a
    preload follow."""
    columns = {f"load_factor_{name}": deck.curve_index(name) for name in deck.curves}
    if deck.solver.ramp_end is not None:
        columns["load_factor"] = deck.curve_index(None)
    return columns


def columns(deck) -> list[Column]:
    """Each curve's load factor, named by shellsim."""
    return [Column(name, f"curves.{name.removeprefix('load_factor_')}" if name != "load_factor" else "the static ramp",
                   "a curve's load factor", chosen=False) for name in load_factor_columns(deck)]


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
