"""The units renders and plots show: the deck's unit system (``meta.units``) names each
kind's unit, and ``output.display_units`` may show lengths, stresses and times in others
(mm, kPa, mmHg, ms), the numbers converted for the picture only."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..deck.output_fields import FIELDS
from ..deck.schema import SYSTEMS, UNIT_SIZES

#: A field's smoothed nodal version: ``<field>_nodal``; its values nearest a face (output.faces).
NODAL_SUFFIX, FACE_SUFFIXES = "_nodal", ("_bottom", "_top")
#: What each field, written array or probe quantity measures.
FIELD_KIND = {"position": "length", "stress": "stress", "time": "time",
              **{name: kind.measures for kind in FIELDS if kind.measures
                 for name in (kind.name, *kind.written_as)}}
#: Kinds that are a power of another: (base kind, power).
POWERS = {"area": ("length", 2), "volume": ("length", 3)}


@dataclass(frozen=True)
class DisplayUnits:
    """Units of a deck's unit ``system`` (SYSTEMS' keys), with the ``shown`` ones (kind:
    unit) instead where given. A field or quantity of kind length, stress, pressure, time
    or area and volume (:data:`POWERS`) has a unit; others are drawn as they are."""

    system: str = "consistent"
    shown: dict[str, str] = field(default_factory=dict)

    @classmethod
    def of(cls, deck) -> "DisplayUnits":
        return cls(deck.meta.units, dict(deck.output.display_units))

    def _kind(self, name: str) -> tuple[str, int]:
        """(base kind, power) of a field, quantity or kind: an area is length squared."""
        field = name.removesuffix(NODAL_SUFFIX)
        for suffix in FACE_SUFFIXES:
            field = field.removesuffix(suffix)
        kind = FIELD_KIND.get(field, field)
        return POWERS.get(kind, (kind, 1))

    def _shown(self, kind: str) -> str | None:
        """The unit asked for ``kind``: a pressure's follows the stresses' unless given."""
        return self.shown.get(kind) or (self.shown.get("stress") if kind == "pressure" else None)

    def unit(self, name: str) -> str:
        """The unit ``name`` (a field, probe quantity or kind) is shown in; '' for none."""
        kind, power = self._kind(name)
        unit = self._shown(kind) or SYSTEMS[self.system].get(kind, "")
        return f"{unit}^{power}" if unit and power > 1 else unit

    def scale(self, name: str) -> float:
        """The factor taking a value of ``name`` from the deck's units to the shown ones."""
        kind, power = self._kind(name)
        shown = self._shown(kind)
        if shown is None:
            return 1.0
        sizes = UNIT_SIZES[kind]
        return (sizes[SYSTEMS[self.system][kind]] / sizes[shown]) ** power

    def label(self, text: str, name: str) -> str:
        """``text`` with the unit of ``name`` in brackets, where it has one."""
        unit = self.unit(name)
        return f"{text} ({unit})" if unit else text
