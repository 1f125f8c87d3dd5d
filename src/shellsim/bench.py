"""Speed, measured: every constitutive path on the Scordelis-Lo 16 x 16 mesh on one thread
and on every core (microseconds per element per step; GFLOP/s from the operation count
below, against a one-thread matrix product), the peer-comparison plate
(decks/bench/plate_step.toml) on a ladder of meshes (error of the first peak, wall time),
and the cost of contact between shells on two stacked plates whose every node touches.
Nothing here asserts a time; it reports."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
import tomllib
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np

from .deck import deck_from_data, parse_deck
from .geometry import build_mesh
from .loads import calibrate
from .mesh import Mesh, NamedSet
from .model import build_model
from .output.mesh_files import write_mesh_vtu
from .execute import built_run
from .solver.run import integrate
from .solver.simulation import Simulation
from .threads import ThreadChooser
from .verify.check import check

DECKS = Path(__file__).resolve().parents[2] / "decks"


def flops_per_element(n_thick: int = 2) -> int:
    """Floating-point operations (additions, multiplications, divisions, square roots; a
    fused multiply-add counts 2) of one element's internal force in the total formulation,
    counted from :func:`shellsim.element.response.group_response`.

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


#: Materials of the hyperelastic paths, as stiff as the roof's E = 4.32e8 at small strain
#: (Mooney-Rivlin: E = 6 (C1 + C2); Guccione: about C1 C2 along the fibre).
MOONEY_RIVLIN = {"model": "mooney_rivlin", "C1": 5.76e7, "C2": 1.44e7, "density": 36.7}
GUCCIONE = {"model": "guccione", "C1": 4.32e7, "C2": 10.0, "C3": 5.0, "C4": 5.0, "density": 36.7,
            "axes": {"kind": "fixed", "direction": [0.0, 1.0, 0.0]}}
#: Constitutive paths measured by :func:`path_speeds`: (label, [material] table or None for
#: the roof's own linear elastic one, [section] keys).
PATHS = [
    ("small strain (linear elastic)", None, {}),
    ("Technique 1, St. Venant-Kirchhoff", None, {"technique": 1}),
    ("Technique 1, Mooney-Rivlin", MOONEY_RIVLIN, {"technique": 1}),
    ("Technique 1, Mooney-Rivlin, no thickness update", MOONEY_RIVLIN, {"technique": 1, "thickness_update": False}),
    ("Technique 1, Guccione (anisotropic)", GUCCIONE, {"technique": 1}),
    ("Technique 2", None, {"technique": 2}),
    ("Technique 3", None, {"technique": 3}),
]


def scordelis_lo(divisions: int, material: dict | None = None, section: dict | None = None) -> Simulation:
    """The Scordelis-Lo roof (decks/verification/test05_scordelis_lo_6x6.toml) on
    ``divisions`` x ``divisions`` elements, with another material or section keys."""
    data = tomllib.loads((DECKS / "verification" / "test05_scordelis_lo_6x6.toml").read_text())
    data["mesh"]["divisions"] = {"around": divisions, "along": divisions}
    data["reference"] = []
    if material is not None:
        data["material"] = material
    data["section"] = data["section"] | (section or {})
    deck = deck_from_data(data)
    return Simulation(build_model(deck, build_mesh(deck)))


def path_speeds(divisions: int = 16, steps: int = 100, threads: tuple[int, ...] | None = None,
                on_path: Callable[[str, int], None] = lambda label, count: None) -> list[dict]:
    """Microseconds per element per step of the full time step (forces, update) for each
    constitutive path of :data:`PATHS` on the Scordelis-Lo roof, on each number of
    ``threads`` (default: one, and every core numba may use), each from rest at the
    critical step over 1.25. GFLOP/s where the operation count is known (the small-strain
    path, :func:`flops_per_element`). ``on_path(label, threads)`` hears of each path as it
    starts."""
    threads = threads or tuple(sorted({1, numba.config.NUMBA_NUM_THREADS}))
    rows = []
    for label, material, section in PATHS:
        for count in threads:
            on_path(label, count)
            numba.set_num_threads(count)
            sim = scordelis_lo(divisions, material, section)
            sim.threads = ThreadChooser(count, choose=False)
            us = _us_per_element_step(sim, steps, 1.25)
            row = {"path": label, "threads": count, "elements": sim.model.n_elements, "steps": steps,
                   "us_per_element_step": us}
            if not section and material is None:
                flops = flops_per_element(len(sim.model.rule.tz))
                row |= {"flops_per_element_step": flops, "gflops": flops / (us * 1e3)}
            rows.append(row)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return rows


def _us_per_element_step(sim: Simulation, steps: int, safety_factor: float) -> float:
    """Microseconds per element per step of ``steps`` full time steps at the critical step
    over ``safety_factor``, after ten steps that compile and warm up."""
    dt = sim.critical_time_step() / safety_factor
    sim.advance(10 * dt, dt, 10)
    start = time.perf_counter()
    taken = sim.advance(sim.state.t + steps * dt, dt, steps)
    return 1e6 * (time.perf_counter() - start) / (taken * sim.model.n_elements)


#: A matrix product on one thread in a fresh process: the rate this core reaches on
#: dense fp64 arithmetic, against which the kernel's GFLOP/s is read.
DGEMM = """
import time, numpy as np
n = 1024
a, b = np.random.default_rng(0).standard_normal((2, n, n))
best = min((lambda t0: (a @ b, time.perf_counter() - t0)[1])(time.perf_counter()) for _ in range(5))
print(2 * n**3 / best / 1e9)
"""


def dgemm_gflops() -> float:
    """GFLOP/s of numpy's matrix product (BLAS dgemm, 1024 x 1024) on one thread."""
    one = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    done = subprocess.run([sys.executable, "-c", DGEMM], capture_output=True, text=True, check=True,
                          env=os.environ | one)
    return float(done.stdout)


def plate_ladder(divisions=(2, 4, 8)) -> list[dict]:
    """The bench plate per mesh: first-peak error, wall time of the run to t = 0.18 s."""
    text = (DECKS / "bench" / "plate_step.toml").read_text()
    rows = []
    for n in divisions:
        deck = parse_deck(text.replace("length = 2, width = 2", f"length = {n}, width = {n}"))
        run = integrate(built_run(deck, DECKS / "bench"))
        times = np.asarray(run.times)
        results = {r.measure: check(r, times, np.asarray(run.history[r.probe])) for r in deck.reference}
        rows.append({
            "mesh": f"{n}x{n}", "elements": run.mesh.n_elements, "steps": run.sim.state.steps,
            "wall_time_s": run.wall_time, "peak_error_percent": results["min"]["error_percent"],
            "peak_time_error_percent": results["first_peak_time"]["error_percent"],
            "us_per_element_step": 1e6 * run.wall_time / (run.sim.state.steps * run.mesh.n_elements),
            "startup_s": run.startup,
        })
    return rows


#: The stacked plates' deck (its geometry to add): linear elastic, thickness 0.01.
PLATES = """
[meta]
title = "two stacked plates"
[material]
model = "linear_elastic"
E = 1000.0
nu = 0.3
density = 1.0
[section]
thickness = 0.01
[solver]
end_time = 1.0
"""


def stacked_plates(path: Path, lower: int | tuple[int, int], upper: int | tuple[int, int], lift: float = 0.0,
                   thickness: float = 0.01) -> Path:
    """A mesh file of two unit plates: ``lower`` elements (n for n x n, or (along x, along
    y)) at z = 0 and ``upper`` at z = thickness + lift (their faces touching at lift 0),
    as surface sets 'lower' and 'upper' beside the builder's sets of the lower one (x0,
    y1, ...) and of the upper one, named upper_x0, upper_y1, ..."""
    def plate(n: int | tuple[int, int], z: float) -> Mesh:
        length, width = (n, n) if isinstance(n, int) else n
        deck = parse_deck(PLATES + '[geometry]\nbuilder = "rectangle"\nlength = 1.0\nwidth = 1.0\n'
                                   f'[mesh]\ndivisions = {{ length = {length}, width = {width} }}\n')
        mesh = build_mesh(deck)
        mesh.x[:, 2] += z
        return mesh

    def shifted(named: NamedSet) -> NamedSet:
        return NamedSet(named.kind, a.n_nodes + named.nodes,
                        elements=None if named.elements is None else a.n_elements + named.elements,
                        edges=None if named.edges is None else a.n_nodes + named.edges)

    a, b = plate(lower, 0.0), plate(upper, thickness + lift)
    sets = dict(a.sets) | {f"upper_{name}": shifted(named) for name, named in b.sets.items() if name != "all"} \
        | {"lower": NamedSet("surface", np.arange(a.n_nodes), elements=np.arange(a.n_elements)),
           "upper": shifted(NamedSet("surface", np.arange(b.n_nodes), elements=np.arange(b.n_elements)))}
    write_mesh_vtu(Mesh(x=np.vstack([a.x, b.x]), conn=np.vstack([a.conn, b.conn + a.n_nodes]),
                        director=np.vstack([a.director, b.director]),
                        thickness=np.full(a.n_nodes + b.n_nodes, thickness), sets=sets), path)
    return path


def contact_cost(divisions: int = 70, steps: int = 50) -> list[dict]:
    """Microseconds per element-step of the full time step on two stacked plates of
    ``divisions`` x ``divisions`` elements each (2 divisions^2 elements), their faces
    touching so that every node is in contact, without contact and with self-contact of
    both plates as one set (the search over every face, node against face both ways):
    the share of the step that contact takes."""
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        path = stacked_plates(Path(folder) / "plates.vtu", divisions, divisions)
        touching = '[[contact]]\ntype = "shells"\nname = "touching"\n'
        for label, contact in (("without contact", ""), ("self-contact of both plates", touching)):
            deck = parse_deck(PLATES + f'[geometry]\nbuilder = "file"\npath = "{path.as_posix()}"\n' + contact)
            model = build_model(deck, build_mesh(deck))
            sim = Simulation(model)
            if contact:
                calibrate(model, sim.state.mt, sim.state.mr, sim.critical_time_step())
            rows.append({"scene": label, "elements": model.n_elements, "steps": steps,
                         "us_per_element_step": _us_per_element_step(sim, steps, 1.25)})
    rows[1]["contact_share"] = 1.0 - rows[0]["us_per_element_step"] / rows[1]["us_per_element_step"]
    return rows
