"""How one evaluation of the element goes, decided once from the material's path: the
constitutive path is set when the model is built (:class:`shellsim.bundles.Material`'s
``path``), and an evaluation is either the response at the state (forces and stresses)
or the stiffness product K v. Every phase below reads the decisions by name from
:class:`Steps` instead of working them out again from a mode and a technique."""

from __future__ import annotations

from typing import NamedTuple

from numba import njit

#: The constitutive paths (thesis 3.10): the constant lamina tensor at small strain (total
#: or incremental), a strain energy under zero normal stress (Technique 1), and the
#: constant tensor's stresses accumulated, turned and stretched (Techniques 2 and 3).
SMALL_STRAIN, HYPERELASTIC, CONVECTED = 0, 1, 2


class Steps(NamedTuple):
    """The decisions of one evaluation.

    total: the strain from the total deformation (Almansi), else from the field (ue, ve);
    product: the stiffness product (the state's stresses act through the field's gradient,
    the field's stresses are not kept); hyperelastic: Technique 1 (the element on its
    initial fibre lengths, its deformation gradient and untied strains kept);
    incremental: the stresses gathered and C~ times the strain increment added;
    convected: Techniques 2-3's turning and stretching of those stresses; keep_gradient:
    the field's gradient kept (initial stress, material spin); update_lengths: the fibre
    lengths follow the normal stretch (thesis 3.11), from the step's when convected, from
    the initial ones otherwise."""

    total: bool
    product: bool
    hyperelastic: bool
    incremental: bool
    convected: bool
    keep_gradient: bool
    update_lengths: bool


@njit(cache=True, inline="always")
def steps_of(material, product):
    """The :class:`Steps` of the response (``product`` False) or of the stiffness product
    of ``material`` (:class:`shellsim.bundles.Material`)."""
    hyperelastic = material.path == HYPERELASTIC
    convected = material.path == CONVECTED and not product
    total = not product and not material.incremental
    return Steps(total=total, product=product, hyperelastic=hyperelastic,
                 incremental=material.incremental and not product, convected=convected,
                 keep_gradient=product or convected,
                 update_lengths=material.thickness_update and ((hyperelastic and total) or convected))
