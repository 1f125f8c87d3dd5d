"""Value types shared by the deck models: strict numbers (TOML gives typed values, so a
string where a number belongs is a mistake, not something to coerce) and names."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

Real = Annotated[float, Field(strict=True, allow_inf_nan=False)]
Positive = Annotated[float, Field(strict=True, gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(strict=True, ge=0, allow_inf_nan=False)]
Count = Annotated[int, Field(strict=True, ge=1)]
Vec3 = tuple[Real, Real, Real]
#: Names of sets, curves and probes: a letter first, then letters, digits, '_' or '-'.
Name = Annotated[str, Field(strict=True, pattern=r"^[A-Za-z][A-Za-z0-9_\-]*$")]


class Section(BaseModel):
    """Base of every deck table: unknown keys are errors, values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True)
