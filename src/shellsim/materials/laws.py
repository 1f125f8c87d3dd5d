"""The hyperelastic laws of Technique 1 (thesis 3.10.1): their registry, and their
compiled functions called by a law's code (its place in :data:`LAWS`).

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

from numba import njit

from ..table_types import tag_of
from . import guccione, hgo, lee_sacks, mooney_rivlin, st_venant_kirchhoff

#: The laws, in the order of their codes.
LAWS = (mooney_rivlin, guccione, st_venant_kirchhoff, hgo, lee_sacks)


def law_of(model: str):
    """(code, module) of the law serving the deck's ``material.model``."""
    for code, law in enumerate(LAWS):
        if any(tag_of(cls)[1] == model for cls in law.MODELS):
            return code, law
    raise KeyError(f"no hyperelastic law serves material.model = {model!r}")


def _by_code(name: str, code: int = 0):
    """A compiled f(code, params, *arrays) that calls LAWS[code].<name>(params, *arrays):
    one inlined branch per law. Compiled code cannot call a function held in a value and
    still be cached, so the branches are built here, once per function name, for the
    two arities of the law functions (two or three arrays)."""
    law = getattr(LAWS[code], name)
    three_arrays = law.py_func.__code__.co_argcount == 4
    if code == len(LAWS) - 1:
        if three_arrays:
            return njit(inline="always")(lambda which, params, a, b, c: law(params, a, b, c))
        return njit(inline="always")(lambda which, params, a, b: law(params, a, b))
    others = _by_code(name, code + 1)
    if three_arrays:
        @njit(inline="always")
        def branch3(which, params, a, b, c):
            if which == code:
                law(params, a, b, c)
            else:
                others(which, params, a, b, c)
        return branch3

    @njit(inline="always")
    def branch2(which, params, a, b):
        if which == code:
            law(params, a, b)
        else:
            others(which, params, a, b)
    return branch2


#: energy(code, params, E, W), energy_stress(code, params, E, S),
#: energy_tangent(code, params, E, dE, dS) of the law with that code.
energy = _by_code("energy")
energy_stress = _by_code("energy_stress")
energy_tangent = _by_code("energy_tangent")
