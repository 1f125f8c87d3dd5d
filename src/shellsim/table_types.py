"""Value types shared by the deck models: strict numbers (TOML gives typed values, so a
string where a number belongs is a mistake, not something to coerce) and names."""

from __future__ import annotations

import typing
from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

from .printable import control_characters

#: The magnitudes a deck's numbers may have. Products of a few of them (a stiffness E h^3,
#: a frequency E / (rho L^2), an energy) must stay far inside double precision, and no
#: unit system puts a physical quantity of a shell model outside this range.
SMALLEST, LARGEST = 1e-30, 1e30


def _within_range(value: float) -> float:
    if value != 0 and not SMALLEST <= abs(value) <= LARGEST:
        raise ValueError(f"expected a magnitude between {SMALLEST:g} and {LARGEST:g} (or 0 where 0 is allowed); "
                         "choose units that keep the deck's numbers nearer 1")
    return value


_IN_RANGE = AfterValidator(_within_range)
Real = Annotated[float, Field(strict=True, allow_inf_nan=False), _IN_RANGE]
Positive = Annotated[float, Field(strict=True, gt=0, allow_inf_nan=False), _IN_RANGE]
NonNegative = Annotated[float, Field(strict=True, ge=0, allow_inf_nan=False), _IN_RANGE]
Count = Annotated[int, Field(strict=True, ge=1)]
Vec3 = tuple[Real, Real, Real]
#: Names of sets, curves and probes: a letter first, then letters, digits, '_' or '-'.
Name = Annotated[str, Field(strict=True, pattern=r"^[A-Za-z][A-Za-z0-9_\-]*$")]


def _text_without(allowed: str):
    """A validator refusing control characters other than ``allowed`` (they would act on
    the terminal the text is printed on)."""

    def check(text: str) -> str:
        found = control_characters(text, allowed)
        if found:
            raise ValueError(f"holds the control character(s) {', '.join(found)}; write the text without them")
        return text

    return AfterValidator(check)


#: One line of free text (a title): no control characters.
Line = Annotated[str, Field(strict=True), _text_without("")]
#: Free text (a description): no control characters but line breaks and tabs.
Text = Annotated[str, Field(strict=True), _text_without("\n\t")]


def need_directions(table: BaseModel, *keys: str) -> None:
    """Raises ValueError naming the first of ``keys`` whose vector on ``table`` is zero
    (an absent one, None, passes)."""
    for key in keys:
        vector = getattr(table, key)
        if vector is not None and not any(vector):
            raise ValueError(f"{key} = {list(vector)} has no direction; give a nonzero vector")


def repeated(names: list[str]) -> list[str]:
    """The names that occur more than once in ``names``, sorted."""
    return sorted({name for name in names if names.count(name) > 1})


class Section(BaseModel):
    """Base of every deck table: unknown keys are errors, values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True)


#: Keys that choose the member of a union table (builder, material model, load type, ...).
DISCRIMINATORS = ("builder", "model", "type", "kind")


def tag_of(cls: type[BaseModel]) -> tuple[str, str] | None:
    """(key, value) that selects ``cls`` in its union, e.g. ("builder", "tube"), or None."""
    for key in DISCRIMINATORS:
        field = cls.model_fields.get(key)
        if field is not None:
            args = typing.get_args(field.annotation)
            if len(args) == 1 and isinstance(args[0], str):
                return key, args[0]
    return None
