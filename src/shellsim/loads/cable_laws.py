"""One-dimensional hyperelastic laws of a cable (chordae tendineae): the nominal stress P
[stress] (force per initial cross-section) at the stretch lambda = l / L, and its
derivative dP/dlambda. A cable carries tension only: where lambda < 1 both are 0 (at
lambda = 1 the slope is the taut side's, so that Newton's first tangent from rest has it).

    linear       P = E (lambda - 1)                         (the elastic catenary's law)
    ogden        P = sum_i 2 mu_i / alpha_i (lambda^(alpha_i-1) - lambda^(-alpha_i/2-1)), up to
                 six terms (incompressible, uniaxial, of Abaqus' W = sum_i 2 mu_i / alpha_i^2
                 (lambda_1^alpha_i + lambda_2^alpha_i + lambda_3^alpha_i - 3); one term of
                 alpha = 2 is neo-Hooke, P = mu (lambda - lambda^-2))
    exponential  P = a exp(b (I1 - 3)) (lambda - lambda^-2),  I1 = lambda^2 + 2 / lambda
                 (Demiray 1972, W = a / (2 b) (exp(b (I1 - 3)) - 1), incompressible, uniaxial)

A law is a deck table (``model``), its parameters as PARAMETERS numbers and one branch of
:func:`nominal_stress`.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

import numpy as np
from numba import njit
from pydantic import Field

from pydantic import model_validator

from ..table_types import Positive, Real, Section

LINEAR, OGDEN, EXPONENTIAL = range(3)
#: The most terms an Ogden law takes (Abaqus' N <= 6), and the numbers a law's parameters
#: take: (mu_i, alpha_i) for each term.
OGDEN_TERMS = 6
PARAMETERS = 2 * OGDEN_TERMS


class Linear(Section):
    """Tension E A (lambda - 1): a linear law in the engineering strain."""

    model: Literal["linear"]
    E: Positive


class NeoHookean(Section):
    """Incompressible neo-Hookean in uniaxial tension: P = mu (lambda - lambda^-2)."""

    model: Literal["neo_hookean"]
    mu: Positive


class Ogden(Section):
    """Incompressible Ogden in uniaxial tension, P = sum_i 2 mu_i / alpha_i
    (lambda^(alpha_i-1) - lambda^(-alpha_i/2-1)): Abaqus' ``*HYPERELASTIC, OGDEN, N=n``
    (W = sum_i 2 mu_i / alpha_i^2 (lambda_1^alpha_i + lambda_2^alpha_i + lambda_3^alpha_i
    - 3)). ``mu`` and ``alpha`` are numbers (one term) or lists of up to six, one per term;
    each term stiffens in tension (mu_i alpha_i > 0, Ogden's condition), and terms of one
    exponent act as one term with their mu summed."""

    model: Literal["ogden"]
    mu: Real | list[Real]
    alpha: Real | list[Real]

    @model_validator(mode="after")
    def _terms_fit(self) -> "Ogden":
        mu, alpha = self.terms()
        if len(mu) != len(alpha) or not 1 <= len(mu) <= OGDEN_TERMS:
            raise ValueError(f"'mu' and 'alpha' give one number per term, 1 to {OGDEN_TERMS} terms of each; got "
                             f"{len(mu)} and {len(alpha)}")
        for i, (m, a) in enumerate(zip(mu, alpha)):
            if not m * a > 0.0:
                raise ValueError(f"term {i + 1}: mu = {m:g}, alpha = {a:g}; each term needs mu * alpha > 0 "
                                 "(it stiffens in tension)")
        return self

    def terms(self) -> tuple[list[float], list[float]]:
        """(mu_i, alpha_i) of each term, as lists."""
        as_list = lambda v: list(v) if isinstance(v, list) else [v]  # noqa: E731
        return as_list(self.mu), as_list(self.alpha)


class Exponential(Section):
    """Incompressible exponential (Demiray) in uniaxial tension:
    P = a exp(b (I1 - 3)) (lambda - lambda^-2)."""

    model: Literal["exponential"]
    a: Positive
    b: Positive


CABLE_LAWS = (Linear, NeoHookean, Ogden, Exponential)
CableLaw = Annotated[Union[CABLE_LAWS], Field(discriminator="model")]


def code_and_parameters(law) -> tuple[int, np.ndarray]:
    """(code, parameters (PARAMETERS,)) of a deck's cable ``law`` for :func:`nominal_stress`:
    an Ogden law's terms as (mu_i, alpha_i) pairs, those of one exponent merged (their mu
    summed: exact, P is linear in mu), the unused pairs (0, 1) adding nothing."""
    params = np.zeros(PARAMETERS)
    if law.model == "linear":
        params[0] = law.E
        return LINEAR, params
    if law.model == "exponential":
        params[:2] = law.a, law.b
        return EXPONENTIAL, params
    merged: dict[float, float] = {}
    for mu, alpha in zip(*(law.terms() if law.model == "ogden" else ([law.mu], [2.0]))):
        merged[alpha] = merged.get(alpha, 0.0) + mu
    params[1::2] = 1.0
    for i, (alpha, mu) in enumerate(merged.items()):
        params[2 * i:2 * i + 2] = mu, alpha
    return OGDEN, params


@njit(cache=True, inline="always")
def nominal_stress(law, params, stretch):
    """(P, dP/dlambda) of law ``law`` with ``params`` (PARAMETERS,) at ``stretch``; (0, 0)
    where the cable is shorter than at rest."""
    if stretch < 1.0:
        return 0.0, 0.0
    if law == LINEAR:
        return params[0] * (stretch - 1.0), params[0]
    if law == OGDEN:
        p, dp = 0.0, 0.0
        for i in range(0, len(params), 2):
            mu, alpha = params[i], params[i + 1]
            if mu != 0.0:
                p += 2.0 * mu / alpha * (stretch ** (alpha - 1.0) - stretch ** (-0.5 * alpha - 1.0))
                dp += 2.0 * mu / alpha * ((alpha - 1.0) * stretch ** (alpha - 2.0)
                                          + (0.5 * alpha + 1.0) * stretch ** (-0.5 * alpha - 2.0))
        return p, dp
    a, b = params[0], params[1]
    grow = a * np.exp(b * (stretch * stretch + 2.0 / stretch - 3.0))
    shape = stretch - stretch ** -2
    return grow * shape, grow * (2.0 * b * shape * shape + 1.0 + 2.0 * stretch ** -3)
