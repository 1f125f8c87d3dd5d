"""One-dimensional hyperelastic laws of a cable (chordae tendineae): the nominal stress P
[stress] (force per initial cross-section) at the stretch lambda = l / L, and its
derivative dP/dlambda. A cable carries tension only: where lambda < 1 both are 0 (at
lambda = 1 the slope is the taut side's, so that Newton's first tangent from rest has it).

    linear       P = E (lambda - 1)                         (the elastic catenary's law)
    ogden        P = 2 mu / alpha (lambda^(alpha-1) - lambda^(-alpha/2-1))
                 (incompressible, uniaxial; alpha = 2 is neo-Hooke, P = mu (lambda - lambda^-2))
    exponential  P = a exp(b (I1 - 3)) (lambda - lambda^-2),  I1 = lambda^2 + 2 / lambda
                 (Demiray 1972, W = a / (2 b) (exp(b (I1 - 3)) - 1), incompressible, uniaxial)

A law is a deck table (``model``), its parameters as three numbers and one branch of
:func:`nominal_stress`.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

import numpy as np
from numba import njit
from pydantic import Field

from ..table_types import Positive, Section

LINEAR, OGDEN, EXPONENTIAL = range(3)


class Linear(Section):
    """Tension E A (lambda - 1): a linear law in the engineering strain."""

    model: Literal["linear"]
    E: Positive


class NeoHookean(Section):
    """Incompressible neo-Hookean in uniaxial tension: P = mu (lambda - lambda^-2)."""

    model: Literal["neo_hookean"]
    mu: Positive


class Ogden(Section):
    """Incompressible one-term Ogden in uniaxial tension:
    P = 2 mu / alpha (lambda^(alpha-1) - lambda^(-alpha/2-1))."""

    model: Literal["ogden"]
    mu: Positive
    alpha: Positive


class Exponential(Section):
    """Incompressible exponential (Demiray) in uniaxial tension:
    P = a exp(b (I1 - 3)) (lambda - lambda^-2)."""

    model: Literal["exponential"]
    a: Positive
    b: Positive


CABLE_LAWS = (Linear, NeoHookean, Ogden, Exponential)
CableLaw = Annotated[Union[CABLE_LAWS], Field(discriminator="model")]


def code_and_parameters(law) -> tuple[int, np.ndarray]:
    """(code, parameters (3,)) of a deck's cable ``law`` for :func:`nominal_stress`."""
    if law.model == "linear":
        return LINEAR, np.array([law.E, 0.0, 0.0])
    if law.model == "exponential":
        return EXPONENTIAL, np.array([law.a, law.b, 0.0])
    alpha = 2.0 if law.model == "neo_hookean" else law.alpha
    return OGDEN, np.array([law.mu, alpha, 0.0])


@njit(cache=True, inline="always")
def nominal_stress(law, params, stretch):
    """(P, dP/dlambda) of law ``law`` with ``params`` (3,) at ``stretch``; (0, 0) where the
    cable is shorter than at rest."""
    if stretch < 1.0:
        return 0.0, 0.0
    if law == LINEAR:
        return params[0] * (stretch - 1.0), params[0]
    if law == OGDEN:
        mu, alpha = params[0], params[1]
        p = 2.0 * mu / alpha * (stretch ** (alpha - 1.0) - stretch ** (-0.5 * alpha - 1.0))
        dp = 2.0 * mu / alpha * ((alpha - 1.0) * stretch ** (alpha - 2.0)
                                 + (0.5 * alpha + 1.0) * stretch ** (-0.5 * alpha - 2.0))
        return p, dp
    a, b = params[0], params[1]
    grow = a * np.exp(b * (stretch * stretch + 2.0 / stretch - 3.0))
    shape = stretch - stretch ** -2
    return grow * shape, grow * (2.0 * b * shape * shape + 1.0 + 2.0 * stretch ** -3)
