"""The element loop as the static solver calls it from Python (:class:`ElementLoop`): the
internal forces of element groups, summed at the nodes as the time loop sums them, and
the tangent blocks of elements, both through one compiled entry.

One entry, whose compiling the gathers and the group's arrays then need once, for both.
It calls the element response through its address
(:func:`shellsim.element.response.response_by_address`), so its compiling does not take
in the response's code. It is a serial loop that releases the interpreter's lock, shared
out over threads from Python (:func:`shellsim.threads.over_threads`): it spares a static
scene the time loop's parallel loop.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .assembly import after_groups, run_groups
from .steps import steps_of
from .tangent import ELEMENT_DOFS, element_tangents
from ..compiled_call import TypedCall
from ..threads import over_threads


@njit(cache=True, nogil=True, error_model="numpy")
def static_elements(response, first, last, tangents, structure, shape, converged, parts, differences, central, k):  # noqa: PLR0913 (flat bundles)
    """The tangent blocks k (ne, 45, 45) of elements first..last-1 when ``tangents``
    (:func:`shellsim.element.tangent.element_tangents`, ``differences`` and ``central``
    its steps and kind), else the responses of groups first..last-1 into their slots of
    ``parts`` (:func:`shellsim.element.assembly.run_groups`) and the stresses.

    response: the element response by its address; structure: (rule, body, material);
    shape: the current :class:`~shellsim.bundles.Shape`; converged: (dx, dd, stress), the
    increments (n, 3) since the converged state and the stress (ne, nq, nt, 5) (the forces
    write it)."""
    if tangents:
        element_tangents(response, structure, shape, converged, differences, central, (first, last), k)
        return
    rule, body, material = structure
    dx, dd, stress = converged
    run_groups(response, first, last, steps_of(material, np.bool_(False)), rule, body, material, shape, dx, dd, stress,
               parts)


#: What a forces call passes for the tangent's arguments: the same types, nothing done with them.
_NO_STEPS = (0.0, 0.0)
_NO_BLOCKS = np.zeros((0, ELEMENT_DOFS, ELEMENT_DOFS))


class ElementLoop:
    """The internal forces and the element tangents as Python calls them where no time loop
    runs. The forces are the same to the bit as the time loop's
    (:func:`shellsim.element.assembly.internal_forces`). One per model: each kind of call
    keeps the argument types of its first; ``response`` is the element response by its
    address (:func:`shellsim.element.response.response_by_address`)."""

    def __init__(self, response):
        self._steps, self._after = TypedCall(steps_of), TypedCall(after_groups)
        self._forces, self._tangents = TypedCall(static_elements), TypedCall(static_elements)
        self._response = response

    def forces(self, structure, shape, dx, dd, stress, f, fr, parts) -> None:
        """As :func:`shellsim.element.assembly.internal_forces`."""
        rule, body, material = structure
        over_threads(lambda first, last: self._forces(self._response, first, last, False, structure, shape,
                                                      (dx, dd, stress), parts, _NO_STEPS, False, _NO_BLOCKS),
                     len(body.group_part))
        self._after(self._steps(material, np.bool_(False)), body, shape, parts, f, fr)

    def tangents(self, structure, shape, converged, differences, central, parts, k) -> None:
        """k (ne, 45, 45): every element's tangent block, as
        :func:`shellsim.element.tangent.element_tangents` forms it; ``parts``
        (:class:`~shellsim.element.assembly.Assembly`) as the forces' (left as it is)."""
        over_threads(lambda first, last: self._tangents(self._response, first, last, True, structure, shape,
                                                        converged, parts, differences, central, k), len(k))
