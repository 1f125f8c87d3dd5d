"""What contact carries: each ``[[contact]]`` table's force, contact area and spring
energy (:class:`shellsim.loads.ToolForces`), a measure family
(:mod:`shellsim.measures`); its summary entry says what contact costs."""

from __future__ import annotations

from ..loads import ToolForces, measure_names
from ..bundles import Model
from ..mesh import Mesh
from .column import Column


class ContactMeasures:
    """The contact tables' columns, by their names."""

    NAME = "contact"
    sparse = False

    def __init__(self, model: Model, names: list[str]):
        self.forces = ToolForces(model, names)
        self.columns = measure_names(names)

    def sample(self, run) -> list[float]:
        return list(self.forces(run.load_time, run.sim.state.fields.shape).values())

    def record(self, run, output_seconds: float) -> dict:
        """The contact forces' wall time per evaluation (search included, timed on the
        last shape) and, of an explicit run, its share of the mean step."""
        per_evaluation = self.forces.seconds_per_evaluation(run.load_time, run.sim.state.fields.shape)
        record = {"us_per_evaluation": 1e6 * per_evaluation}
        if run.deck.solver.method == "explicit" and run.sim.state.steps:
            record["share_of_step"] = per_evaluation * run.sim.state.steps / max(run.wall_time - output_seconds, 1e-300)
        return record


def columns(deck) -> list[Column]:
    """Each ``[[contact]]``'s force, contact area and spring energy."""
    return [Column(column, f"contact[{i}].name", "a contact's") for i, contact in enumerate(deck.contact)
            for column in measure_names([contact.name])]


def resolve(deck, mesh: Mesh, model: Model) -> ContactMeasures | None:
    """The deck's contact tables' measures (None without any)."""
    names = [contact.name for contact in deck.contact]
    return ContactMeasures(model, names) if names else None
