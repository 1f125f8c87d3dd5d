"""The study file (TOML): which decks, which variants of each, and optional points of
other programs to draw beside ours.

::

    [meta]
    title = "Quick study"

    [[deck]]
    path = "../verification/test02_cantilever_uniform_load_3.toml"   # relative to the study
    family = "Test 2 cantilever"          # one curve of the error-versus-time plot

    [[deck.variant]]
    label = "3 elements"                  # the deck as it is

    [[deck.variant]]
    label = "6 elements"
    set = { "mesh.divisions.length" = 6 } # deck keys replaced (dotted paths; list items by index)

    [external]
    path = "peers.csv"                    # columns: family, program, label, error_percent, wall_time_s

Checks beyond the decks' references, for stability studies: ``meta.balance_within_percent``
bounds every completed run's energy balance error, and a deck's ``dt_falls_by`` asks its
time step to shrink at least that many times over the run (a stiffening scene).
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, ValidationError, model_validator

from ..table_types import Section, repeated
from ..errors import DeckError

Text = Annotated[str, Field(strict=True, min_length=1)]
Value = bool | int | float | str | list


Positive = Annotated[float, Field(strict=False, gt=0.0)]


class StudyMeta(Section):
    title: Text
    description: str = ""
    balance_within_percent: Positive | None = None


class Variant(Section):
    """One rung of a ladder: a label, the deck keys it replaces, and how the run is
    expected to end: ``completed`` and within its references (the default), ``unstable``
    (made unstable on purpose) or ``missed`` (completes but misses a reference: a mesh
    known to be too coarse, kept to set beside the thesis' own coarse meshes)."""

    label: Text
    set: dict[Text, Value] = {}
    expect: Literal["completed", "unstable", "missed"] = "completed"


class StudyDeck(Section):
    """A deck and its ladder (the deck as it is when no variant is given)."""

    path: Text
    family: str = ""
    dt_falls_by: Positive | None = None
    variant: list[Variant] = [Variant(label="as is")]

    @model_validator(mode="after")
    def _unique_labels(self) -> "StudyDeck":
        twice = repeated([v.label for v in self.variant])
        if twice:
            raise ValueError(f"variant labels of '{self.path}' repeat: {', '.join(twice)}")
        return self


class External(Section):
    """Other programs' error and wall time on the same problems (CSV)."""

    path: Text


class Study(Section):
    meta: StudyMeta
    deck: list[StudyDeck]
    external: External | None = None


def load_study(path: Path) -> Study:
    """Read and validate a study file; deck paths stay relative to it."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        return Study.model_validate(data)
    except FileNotFoundError:
        raise DeckError(str(path), ["file not found"]) from None
    except tomllib.TOMLDecodeError as error:
        raise DeckError(str(path), [f"not valid TOML: {error}"]) from None
    except ValidationError as error:
        raise DeckError(str(path), [f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in error.errors()]) from None
