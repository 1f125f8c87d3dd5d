"""What a scene needs from the solver, decided from the deck alone: everything not listed
as used is left out of the time loop."""

from __future__ import annotations

from dataclasses import dataclass

from .deck import Deck


@dataclass(frozen=True)
class Plan:
    """Solver features of one scene (each True only when the deck needs it)."""

    large_strain: bool
    hyperelastic: bool
    anisotropic: bool
    thickness_update: bool
    plane_strain: bool
    follower_pressure: bool
    dead_pressure: bool
    edge_loads: bool
    point_loads: bool
    body_force: bool
    prescribed_motion: bool
    damping: bool

    def used(self) -> list[str]:
        return [name for name, on in vars(self).items() if on]

    def left_out(self) -> list[str]:
        return [name for name, on in vars(self).items() if not on]


def plan(deck: Deck) -> Plan:
    """The features ``deck`` needs."""
    load_types = {load.type for load in deck.load}
    pressures = [load for load in deck.load if load.type == "pressure"]
    return Plan(
        large_strain=deck.section.technique is not None,
        hyperelastic=deck.material.HYPERELASTIC,
        anisotropic=deck.material.ANISOTROPIC,
        thickness_update=deck.thickness_update,
        plane_strain=deck.section.plane_strain,
        follower_pressure=any(p.follower for p in pressures),
        dead_pressure=any(not p.follower for p in pressures),
        edge_loads=bool(load_types & {"edge_force", "edge_pressure", "edge_moment"}),
        point_loads=bool(load_types & {"point_force", "point_moment"}),
        body_force="body_force" in load_types,
        prescribed_motion=any(bc.type == "prescribed" for bc in deck.boundary),
        damping=deck.solver.damping > 0.0,
    )
