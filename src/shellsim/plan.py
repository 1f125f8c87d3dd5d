"""What a scene needs from the solver, decided from the deck alone: the features it
uses, reported by ``shellsim check`` and in summary.json. The model is built from the
deck itself (:func:`shellsim.model.build_model`); a feature not used costs nothing there
because its tables are empty (no loads of a kind, no prescribed motion, no damping)."""

from __future__ import annotations

from dataclasses import dataclass

from .deck import Deck
from .loads import DECK_KEYS
from .loads import features as load_features


@dataclass(frozen=True)
class Plan:
    """Solver features of one scene, by name: True where the deck needs it."""

    features: dict[str, bool]

    @property
    def large_strain(self) -> bool:
        return self.features["large_strain"]

    def used(self) -> list[str]:
        return [name for name, on in self.features.items() if on]

    def left_out(self) -> list[str]:
        return [name for name, on in self.features.items() if not on]


def plan(deck: Deck) -> Plan:
    """The features ``deck`` needs."""
    return Plan({
        "large_strain": deck.section.technique is not None,
        "hyperelastic": any(m.HYPERELASTIC for m in deck.material),
        "anisotropic": any(m.ANISOTROPIC for m in deck.material),
        "thickness_update": deck.thickness_update,
        "plane_strain": deck.section.plane_strain,
        **load_features([table for key in DECK_KEYS for table in getattr(deck, key)]),
        "prescribed_motion": any(bc.type == "prescribed" for bc in deck.boundary),
        "damping": deck.solver.damping > 0.0,
        "kinetic_damping": deck.solver.relaxation is not None,
    })
