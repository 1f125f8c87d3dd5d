"""The ``[material]`` table, chosen by ``model``: the small-strain model and the models of
every law of :data:`shellsim.materials.laws.LAWS`, each defined in its law's file.

Incompressible models impose J = 1 exactly through the lamina normal strain (thesis
Technique 1), so they take no bulk modulus or Poisson ratio. Parameter names follow the
thesis; Guccione's C1..C4 are LS-DYNA MAT_128's C, B1, B2, B3.
"""

from __future__ import annotations

from typing import Annotated, Union

from pydantic import Field

from ..materials.laws import LAWS
from ..materials.linear import LinearElastic
from ..table_types import tag_of

#: The models, the small-strain one first, in the order the deck reference lists them.
MODELS = tuple(dict.fromkeys((LinearElastic, *(cls for law in LAWS for cls in law.MODELS))))

Material = Annotated[Union[MODELS], Field(discriminator="model")]

MATERIALS = {tag_of(cls)[1]: cls for cls in MODELS}
