"""How a model file's user materials become a shellsim law (``shellsim import
--user-material``): a file's user materials all run its one user subroutine, so one
mapping, said once, serves every material of that law, each with its own constants.

The mapping is ``MODEL: KEY = VALUE, ...``, a VALUE either ``$n``, the material's n-th
constant (from 1, in the order ``*USER MATERIAL`` lists them), or a number; e.g. the law
W = C0/2 (I1 - 3) + C1/2 (exp(C2 (I1 - 3)^2) - 1) with constants C0, C1, C2 is Lee-Sacks
at delta = 1: ``lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..deck.material import MATERIALS
from ..errors import DeckError

#: One ``KEY = VALUE`` of a mapping.
_ENTRY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(\$[1-9][0-9]*|[-+0-9.eE]+)\s*$")


@dataclass(frozen=True)
class UserLaw:
    """A user material's law: the deck's ``model`` and each key's value, a constant's
    index (int, from 0) or a number (float)."""

    model: str
    keys: dict[str, int | float]

    @classmethod
    def parse(cls, text: str) -> "UserLaw":
        """The mapping ``text``; DeckError (naming the option) where it does not read."""
        where = "--user-material"
        model, colon, rest = text.partition(":")
        model = model.strip()
        if not colon or model not in MATERIALS:
            raise DeckError(where, [f"got '{text}': expected 'MODEL: KEY = $n | number, ...' with MODEL one of "
                                    f"{', '.join(MATERIALS)}"])
        keys: dict[str, int | float] = {}
        for entry in rest.split(","):
            found = _ENTRY.match(entry)
            if found is None:
                raise DeckError(where, [f"'{entry.strip()}': expected KEY = $n (the n-th constant) or KEY = a number"])
            key, value = found.groups()
            try:
                keys[key] = int(value[1:]) - 1 if value.startswith("$") else float(value)
            except ValueError:
                raise DeckError(where, [f"'{entry.strip()}': '{value}' is not a number"]) from None
        return cls(model, keys)

    def table(self, constants: list[float]) -> dict | None:
        """The material table of a user material with these ``constants`` (without its
        density); None where the mapping names a constant it does not have."""
        if any(isinstance(v, int) and v >= len(constants) for v in self.keys.values()):
            return None
        return {"model": self.model} | {key: constants[v] if isinstance(v, int) else v for key, v in self.keys.items()}
