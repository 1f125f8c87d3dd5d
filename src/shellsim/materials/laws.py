"""The hyperelastic laws of Technique 1 (thesis 3.10.1): their registry, and a law's
compiled functions held for the element path (:func:`held_laws`).

A law is one module of this package with
- ``INCOMPRESSIBLE``: J = 1 (zero normal stress by the determinant condition), or a
  compressible law whose S_33 is linear in E_33;
- ``MODELS``: the deck's material models it serves (pydantic tables, ``model`` their
  tag; the deck accepts exactly the models of the registered laws);
- ``parameters(material)``: its parameter array (P,) from the deck's ``[material]``;
- compiled lane functions ``energy(params, E, W)``, ``energy_stress(params, E, S)``
  (S^w = dW/dE) and ``energy_tangent(params, E, dE, dS)`` (dS^w = CC^w : dE), with E, S,
  dE, dS (3, 3, G) Green-Lagrange strains and second Piola stresses in the material frame
  and W (G,), G the lanes of an element group;
- an anisotropic law also gives ``fibres(params)``: (k, 2) the directions of its k fibre
  families in material axes 1, 2, which the outputs draw.
Adding a law is writing its module and adding it to :data:`LAWS`.
"""

from __future__ import annotations

from numba import types

from ..compiled_call import held_by_address, hold_also
from ..table_types import tag_of
from . import guccione, hgo, lee_sacks, mooney_rivlin, st_venant_kirchhoff
from .linear import LinearElastic

#: The laws, in the order of their codes.
LAWS = (mooney_rivlin, guccione, st_venant_kirchhoff, hgo, lee_sacks)
# the small-strain model's message for a nu out of range names the incompressible models
LinearElastic.INCOMPRESSIBLE_MODELS = tuple(tag_of(cls)[1] for law in LAWS if law.INCOMPRESSIBLE for cls in law.MODELS)


def law_of(model: str):
    """(code, module) of the law serving the deck's ``material.model``."""
    for code, law in enumerate(LAWS):
        if any(tag_of(cls)[1] == model for cls in law.MODELS):
            return code, law
    raise KeyError(f"no hyperelastic law serves material.model = {model!r}")


#: The types of a law's lane functions: params (P,), then tensors (3, 3, G).
_PARAMS, _TENSOR = types.Array(types.float64, 1, "C"), types.Array(types.float64, 3, "C")


def held_laws(codes: list[int]) -> tuple:
    """(energy_stress, energy_tangent) of the laws with those codes, one per part of the
    model, each held for the element path (:class:`shellsim.bundles.Material`), which
    calls the part's through its address (:func:`shellsim.compiled_call.held_by_address`):
    only a scene's own laws compile, and the element path compiles none of the laws' code
    into its own."""
    held = []
    for name, signature in (("energy_stress", types.none(_PARAMS, _TENSOR, _TENSOR)),
                            ("energy_tangent", types.none(_PARAMS, _TENSOR, _TENSOR, _TENSOR))):
        functions = held_by_address(getattr(LAWS[codes[0]], name), signature)
        for code in codes[1:]:
            hold_also(functions, getattr(LAWS[code], name), signature)
        held.append(functions)
    return tuple(held)
