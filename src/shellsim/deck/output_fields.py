"""The fields a frame may hold (``[output] fields``), each declared once: its name, what
it measures (for units), where it lives, the arrays it writes under other names and what
it needs of the scene. The deck reads the names and the needs; :mod:`shellsim.output.fields`
computes each field by the function it registers under the same name (checked there).

Where a field lives:
- ``node``: a value at each node, carried to the view's points;
- ``point``: a value at each integration point, written per sub-cell with a smoothed
  ``<name>_nodal`` version, and at the layers nearest the faces (``output.faces``);
- ``cell``: arrays on the sub-cells computed from the view's stresses or strains, and at
  the layers nearest the faces where ``faces`` says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Literal


@dataclass(frozen=True)
class FieldKind:
    """One output field. ``measures``: the kind of quantity it is, for units ("length",
    "stress"; None: a number without one); ``written_as``: the scalar arrays it writes
    instead of one array of its name (a render colours one of them); ``faces``: whether
    ``output.faces`` adds it at the faces' layers; ``missing(deck)``: why the deck's
    scene has no such field (the end of a sentence after the field's name), None where
    it has."""

    name: str
    measures: str | None
    lives: Literal["node", "point", "cell"]
    written_as: tuple[str, ...] = ()
    faces: bool = True
    missing: Callable[[object], str | None] = lambda deck: None


def _needs_contact(what: str) -> Callable[[object], str | None]:
    return lambda deck: None if deck.contact else f"is the {what} of the [[contact]] tables, and the deck has none"


def _needs_fibres(deck) -> str | None:
    models = ", ".join(repr(m.model) for m in deck.material)
    return None if any(m.ANISOTROPIC for m in deck.material) else (
        f"is of a fibre-reinforced law's fibres, and material.model = {models} has none")


def _needs_material_axes(deck) -> str | None:
    return None if deck.section.technique == 1 else (
        f"is in the axes of a hyperelastic material (section.technique = 1), and material.model = "
        f"{', '.join(repr(m.model) for m in deck.material)} with section.technique = {deck.section.technique} "
        "has none")


def _needs_vessel_axes(deck) -> str | None:
    return None if deck.output.vessel_axes is not None else (
        "reads the stress in a vessel's axes: give output.vessel_axes = { kind = 'cylindrical', axis = [...], "
        "origin = [...] } or { kind = 'centreline', points = [...] } (a fibre-reinforced material's own tube or "
        "centreline axes serve when it has them)")


#: Every output field, in the order a frame writes them.
FIELDS = (
    FieldKind("displacement", "length", "node"),
    FieldKind("director", None, "node"),
    FieldKind("thickness", "length", "node"),
    FieldKind("thickness_stretch", None, "node"),  # the fibre's length over its initial one: the wall's lambda_3
    FieldKind("cauchy_stress", "stress", "point"),
    FieldKind("lamina_stress", "stress", "point"),
    FieldKind("pressure_band", "stress", "point"),
    FieldKind("green_lagrange_strain", None, "point"),
    FieldKind("von_mises", "stress", "point"),
    FieldKind("pk2_stress", "stress", "point", missing=_needs_material_axes),
    FieldKind("material_stress", "stress", "point", missing=_needs_material_axes),
    FieldKind("contact_pressure", "stress", "node", missing=_needs_contact("pressure")),
    FieldKind("contact_gap", "length", "node", missing=_needs_contact("gap")),
    FieldKind("principal_stress", "stress", "cell", tuple(f"principal_stress_{k}" for k in (1, 2, 3))),
    FieldKind("vessel_stress", "stress", "cell", ("hoop_stress", "axial_stress", "radial_stress"),
              missing=_needs_vessel_axes),
    FieldKind("fibres", None, "cell", faces=False, missing=_needs_fibres),
    FieldKind("fibre_stretch", None, "cell", ("fibre_stretch_1", "fibre_stretch_2"), faces=False,
              missing=_needs_fibres),
)
FIELD_KINDS = {kind.name: kind for kind in FIELDS}
#: The scalar arrays a field writes under other names, by the field (a render draws them).
WRITTEN_AS = {kind.name: kind.written_as for kind in FIELDS if kind.written_as}


def field_problems(deck) -> list[str]:
    """One problem for each of the deck's ``output.fields`` its scene does not have."""
    return [f"output.fields: '{name}' {why}" for name in deck.output.fields
            if (why := FIELD_KINDS[name].missing(deck)) is not None]
