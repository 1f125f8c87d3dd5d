"""Speed, measured: the element kernel on the Scordelis-Lo 16 x 16 mesh (microseconds per
element per step, GFLOP/s from the operation count below), the cost of each constitutive
path on one scene, and the peer-comparison plate (decks/bench/plate_step.toml) on a ladder
of meshes (error of the first peak, wall time). Nothing here asserts a time; it reports."""

from __future__ import annotations

import time
import tomllib
from pathlib import Path

import numpy as np

from .deck import deck_from_data, parse_deck
from .geometry import build_mesh
from .model import build_model
from .solver.run import integrate, prepare
from .solver.simulation import Simulation
from .verify.check import check

DECKS = Path(__file__).resolve().parents[2] / "decks"


def flops_per_element(n_thick: int = 2) -> int:
    """Floating-point operations (additions, multiplications, divisions, square roots; a
    fused multiply-add counts 2) of one element's internal force in the total formulation,
    counted from :func:`shellsim.element.kernels._element_response`.

    Per point (25 in-plane points: 9 integration + 16 membrane tying points, times n_thick):
      geometry: Jacobian 252, determinant 14, inverse 36, lamina frame 60, gradient
      vectors gN, gM 198 -> 560; total Almansi strain: F 45, inverse of F F^T 80,
      rotation to the lamina 70 -> 195; covariant membrane strains: in-plane tensor 165,
      three contractions 81, mean 6 -> 252; covariant transverse shears: lamina
      tangents 20, contractions 6, their effective stress 6 -> 32; forces: tying terms
      108, gather into the nine nodes 324 -> 432.
    Per integration point and thickness point (9 x n_thick): tensor from the covariant
      change 90, rotation 165, stress 50 -> 305; gathering the contravariant stresses 228;
      lamina stress to global 59; shear tying and its 2 x 2 solve 34, their adjoint 34 -> 68.
    Plane-strain sections add the volumetric projection (not counted here).
    Per in-plane integration point: tying interpolations 36 and their adjoint 39.
    """
    points, integration = 25 * n_thick, 9 * n_thick
    return points * (560 + 195 + 252 + 32 + 432) + integration * (305 + 228 + 59 + 68) + 9 * (36 + 39)


def kernel_speed(divisions: int = 16, steps: int = 200) -> dict:
    """Microseconds per element per step of the full time step (forces, update) on the
    Scordelis-Lo roof with ``divisions`` x ``divisions`` elements."""
    text = (DECKS / "verification" / "test05_scordelis_lo_6x6.toml").read_text()
    deck = parse_deck(text.replace("around = 6, along = 6", f"around = {divisions}, along = {divisions}"))
    sim = Simulation(build_model(deck, build_mesh(deck)))
    us = _us_per_element_step(sim, steps, 1.25)
    flops = flops_per_element(len(sim.model.rule.tz))
    return {"elements": sim.model.n_elements, "steps": steps, "us_per_element_step": us,
            "flops_per_element_step": flops, "gflops": flops / (us * 1e3)}


def _us_per_element_step(sim: Simulation, steps: int, safety_factor: float) -> float:
    """Microseconds per element per step of ``steps`` full time steps at the critical step
    over ``safety_factor``, after ten steps that compile and warm up."""
    dt = sim.critical_time_step() / safety_factor
    sim.advance(10 * dt, dt, 10)
    start = time.perf_counter()
    taken = sim.advance(sim.state.t + steps * dt, dt, steps)
    return 1e6 * (time.perf_counter() - start) / (taken * sim.model.n_elements)


#: Constitutive paths compared by :func:`technique_costs`: (label, material, section keys).
LINEAR = {"model": "linear_elastic", "E": 1.0e5, "nu": 0.3, "density": 1050.0}
MOONEY_RIVLIN = {"model": "mooney_rivlin", "C1": 20.0e3, "C2": 5.0e3, "density": 1050.0}
PATHS = [
    ("small strain (linear elastic)", LINEAR, {}),
    ("Technique 1, St. Venant-Kirchhoff", LINEAR, {"technique": 1}),
    ("Technique 1, Mooney-Rivlin", MOONEY_RIVLIN, {"technique": 1}),
    ("Technique 1, Mooney-Rivlin, no thickness update", MOONEY_RIVLIN, {"technique": 1, "thickness_update": False}),
    ("Technique 1, Guccione (anisotropic)", None, {"technique": 1}),
    ("Technique 2", LINEAR, {"technique": 2}),
    ("Technique 3", LINEAR, {"technique": 3}),
]


def technique_costs(steps: int = 300) -> list[dict]:
    """Microseconds per element per step of the full time step for each constitutive path
    of :data:`PATHS` on the Test 9 tube (decks/verification/test09_aorta_slow_M2.toml,
    19 elements, Guccione where the material is None), from the same state and step."""
    base = tomllib.loads((DECKS / "verification" / "test09_aorta_slow_M2.toml").read_text())
    rows = []
    for label, material, section in PATHS:
        data = dict(base, reference=[])
        data["section"] = {k: v for k, v in base["section"].items() if k != "technique"} | section
        if material is not None:
            data["material"] = material
        deck = deck_from_data(data)
        sim = Simulation(build_model(deck, build_mesh(deck)))
        rows.append({"path": label, "us_per_element_step": _us_per_element_step(sim, steps, 2.0)})
    return rows


def plate_ladder(divisions=(2, 4, 8)) -> list[dict]:
    """The bench plate per mesh: first-peak error, wall time of the run to t = 0.18 s."""
    text = (DECKS / "bench" / "plate_step.toml").read_text()
    rows = []
    for n in divisions:
        deck = parse_deck(text.replace("length = 2, width = 2", f"length = {n}, width = {n}"))
        mesh = build_mesh(deck)
        run = integrate(prepare(deck, mesh, build_model(deck, mesh)))
        times = np.asarray(run.times)
        results = {r.measure: check(r, times, np.asarray(run.history[r.probe])) for r in deck.reference}
        rows.append({
            "mesh": f"{n}x{n}", "elements": mesh.n_elements, "steps": run.sim.state.steps,
            "wall_time_s": run.wall_time, "peak_error_percent": results["min"]["error_percent"],
            "peak_time_error_percent": results["first_peak_time"]["error_percent"],
            "us_per_element_step": 1e6 * run.wall_time / (run.sim.state.steps * mesh.n_elements),
        })
    return rows
