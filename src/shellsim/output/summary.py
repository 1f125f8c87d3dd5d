"""summary.json: what was run, how long it took, the energy balance, what the scene used
and left out, each measure family's entry (contact's cost, a valve's measures) and each
reference check."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .. import __version__
from ..plan import Plan
from ..solver.explicit import DAMPED, EXTERNAL, FRICTION, INTERNAL, KINETIC
from ..solver.run import Run, dt_statistics
from ..verify.check import check
from .folder import write_atomically


def reference_results(run: Run) -> list[dict]:
    """One entry per [reference] of the deck, from the recorded histories: a measure
    taken at some samples only (a valve's) from those samples. A run that did not complete has only its
    ``at_time`` values judged: a final value, an extreme or a peak over a run cut short
    is not the run's, so those are not judged (``passed`` None, with a note saying why)."""
    times = np.asarray(run.times)
    sparse = {column for measure in run.measures if measure.sparse for column in measure.columns}
    results = []
    for ref in run.deck.reference:
        values = np.asarray(run.history[ref.probe])
        taken = ~np.isnan(values) if ref.probe in sparse else slice(None)
        entry = check(ref, times[taken], values[taken])
        if run.status != "completed" and ref.measure != "at_time":
            entry |= {"computed": None, "error": None, "error_percent": None, "passed": None,
                      "note": f"not judged: the run ended {run.status} at t = {run.sim.state.t:.6g}, and its "
                              f"{ref.measure} is of the whole run"}
        results.append(entry)
    return results


def summary(run: Run, deck_path: Path, plan: Plan, message: str | None = None, output_seconds: float = 0.0) -> dict:
    """The record of a run; ``output_seconds`` is the part of the wall time spent writing
    histories and frames."""
    state, model = run.sim.state, run.model
    e = state.energy
    steps = max(state.steps, 1)
    scale = max(abs(e[EXTERNAL]), e[INTERNAL] + e[KINETIC], 1e-300)
    large_strain = {}
    if plan.large_strain:
        large_strain["volume_change_percent"] = 100.0 * (run.sim.volume() / run.sim.volume(initial=True) - 1.0)
    return {
        "deck": str(deck_path),
        "title": run.deck.meta.title,
        "version": __version__,
        "status": run.status,
        "method": run.deck.solver.method + (" after a static preload" if run.deck.solver.preload else ""),
        "message": message,
        "elements": model.n_elements,
        "nodes": model.n_nodes,
        "dofs": 5 * model.n_nodes,
        "steps": state.steps,
        "sim_time": state.t,
        "wall_time_s": run.wall_time,
        "output_wall_time_s": output_seconds,
        "frames": len(run.frame_times),
        "units": run.deck.meta.units,
        "us_per_element_step": 1e6 * (run.wall_time - output_seconds) / (steps * model.n_elements),
        "startup_s": run.startup,
        "dt": dt_statistics(run),
        "element_quality": element_quality(run),
        "breaking_frame_time": run.breaking_frame,
        "energy": {
            "internal": float(e[INTERNAL]), "kinetic": float(e[KINETIC]),
            "external_work": float(e[EXTERNAL]), "damping_work": float(e[DAMPED]),
            **({"friction_work": float(e[FRICTION])} if run.sim.workspace.friction else {}),
            "balance_error": run.balance_error,
            "balance_error_percent": 100.0 * run.balance_error / scale,
        },
        "features": {"used": plan.used(), "left_out": plan.left_out()},
        **large_strain,
        **({"static": static_record(run)} if run.deck.solver.ramp_end is not None else {}),
        **({"implicit": static_record(run)} if run.deck.solver.method == "implicit" else {}),
        **{measure.NAME: entry for measure in run.measures
           if (entry := measure.record(run, output_seconds)) is not None},
        **({"mass_scaling": {"factor": run.sim.mass_factor, "added_mass_percent": 100.0 * (run.sim.mass_factor - 1.0),
                             "rescalings": run.mass_rescalings}}
           if run.deck.solver.mass_scaling is not None else {}),
        **({"relaxation": run.relaxing.record(run.sim)} if run.relaxing is not None else {}),
        **({"unloaded_shape": run.unloading.record()} if run.unloading is not None else {}),
        "reference": reference_results(run),
    }


def unstarted(scene, deck_path: Path, message: str, status: str = "not converged") -> dict:
    """The record of a run that failed before its first step (an imaged scene whose
    unloaded shape was not found; 'output failed', a disk too full for its first files):
    what was run, its status and why."""
    return {"deck": str(deck_path), "title": scene.meta.title, "version": __version__, "status": status,
            "method": scene.solver.method, "message": message, "steps": 0, "reference": []}


def static_record(run: Run) -> dict:
    """A static solve's load steps (an implicit one's time steps): how many, the Newton iterations, tangents formed and
    cut-backs over them (``tangents``: those of the tries that converged; ``tangents_formed``
    and their ``tangent_seconds`` [s]: every one, the stability checks' and the cut tries'
    too), the largest relative residual a step ended with, the load time
    reached at the end and the largest on the way (an arc-length path's clock can end
    short of its load) with each curve's largest load factor, each step, and where the
    path lost or regained stability (:meth:`.stability.StabilityWatch.events`)."""
    steps = [vars(step) for step in run.newton]
    factors = run.measure("load_factors").columns if run.measure("load_factors") else []
    return {"load_steps": len(steps), "iterations": sum(s["iterations"] for s in steps),
            "load_time_reached": steps[-1]["load_time"] if steps else 0.0,
            "largest_load_time": max((s["load_time"] for s in steps), default=0.0),
            "largest_load_factors": {column: max(run.history[column], default=0.0) for column in factors},
            "tangents": sum(s["tangents"] for s in steps),
            "tangents_formed": len(run.tangent_seconds), "tangent_seconds": sum(run.tangent_seconds),
            "cutbacks": sum(s["cutbacks"] for s in steps),
            "largest_residual": max((s["residual"] for s in steps), default=0.0),
            "stability": run.stability.events() if run.stability is not None else [], "steps": steps}


def element_quality(run: Run) -> dict:
    """The worst element's Jacobian ratio (det J / det J0, 1 undistorted, 0 folded) at the
    last step update and the lowest over the run, each with the element (from 1) and time."""

    def entry(worst) -> dict | None:
        return None if worst is None else {"element": worst.element + 1, "ratio": worst.ratio, "t": worst.t}

    return {"last": entry(run.worst), "lowest": entry(run.lowest)}


def write_json(data: dict, path: Path) -> None:
    """Write ``data`` as strict JSON, atomically: a number that is not finite (an energy
    balance with nothing to balance, a ratio of zeros) is written as null."""
    write_atomically(path, json.dumps(_finite(data), indent=2, allow_nan=False) + "\n")


def _finite(value):
    """``value`` with every non-finite float inside it replaced by None."""
    if isinstance(value, dict):
        return {key: _finite(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
