"""The step-pressure plate (decks/bench/plate_step.toml) against an outside code, side by
side in one session: OpenSees' 4-node shells through openseespy, and shellsim's 9-node
element, on a ladder of meshes each, alternating between the codes round by round.
Prints, per code and mesh, the error of the first peak of the centre deflection against
the deck's Kirchhoff reference (judged by the same :func:`shellsim.verify.check`), the
time of that peak, and the wall time of the run: for both from the built model to the
end, the critical step's estimate (shellsim's Lanczos, OpenSees' eigenvalues) and the
analysis' set-up included, imports and building the model excluded. Serial against
serial: OpenSees runs on one thread, and so does shellsim unless ``--threads`` says
otherwise. Nothing is asserted.

The outside code is not a dependency; install it into the environment first:

    .venv/bin/pip install openseespy
    .venv/bin/python benchmarks/peer_plate.py [--ours 2 4 8] [--theirs 4 8 16] [--rounds 3]

The same quarter plate in OpenSees: a uniform m x m grid of 4-node shells with an
``ElasticMembranePlateSection`` (E, nu, h, rho); hard simple supports on x = 0 and y = 0
(w = 0 and no rotation about the edge's normal), symmetry on x = y = a; drilling rotations
fixed (the 9-node element has none); nodal rotary inertia rho h^3 / 12 per tributary
area (OpenSees' shells lump translational mass only); the step pressure as tributary
nodal forces. Explicit central differences at 0.9 of the critical step 2 / omega_max,
omega_max from the full generalized eigenproblem of the assembled K and M.
ASDShellQ4 runs under ``ExplicitDifference``; ShellMITC4 under ``CentralDifference``:
with ``ExplicitDifference`` its first period came out sqrt(2) short (half the mass;
the mass matrix of ``eigen`` gives the right period), which would not be a fair point.
Both with ``algorithm Linear -factorOnce``, as OpenSees' manual advises for an elastic
system: the step's matrix (M / dt^2 for central differences at a fixed step) is set up
and factorised once, not at every step (``--refactor`` every step, as before).
"""

from __future__ import annotations

import argparse
import ctypes
import importlib.util
import math
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "decks" / "bench" / "plate_step.toml"
#: (element, time integrator) of the outside code.
PEERS = [("ASDShellQ4", "ExplicitDifference"), ("ShellMITC4", "CentralDifference")]


def load_opensees():
    """openseespy, after preloading the BLAS it bundles (its Linux build needs it loaded
    globally first)."""
    spec = importlib.util.find_spec("openseespylinux")
    if spec is not None:
        blas = Path(spec.submodule_search_locations[0]) / "lib" / "libblas.so.3"
        if blas.exists():
            ctypes.CDLL(str(blas), mode=ctypes.RTLD_GLOBAL)
    import openseespy.opensees as ops

    return ops


def plate_parameters(deck) -> dict:
    """Quarter-plate size, section, material (the deck's one) and pressure from the deck."""
    material, = deck.material
    return {"a": deck.geometry.length, "h": deck.section.thickness, "E": material.E, "nu": material.nu,
            "rho": material.density, "q": deck.load[0].value, "end": deck.solver.end_time,
            "sample": deck.output.interval}


def build_opensees(ops, m: int, element: str, p: dict) -> tuple[int, int]:
    """The quarter plate on an m x m grid; returns (the centre node's tag, the number of
    free DOFs)."""
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    xs = np.linspace(0.0, p["a"], m + 1)
    da = p["a"] / m

    def tag(i, j):
        return 1 + i + j * (m + 1)

    ops.section("ElasticMembranePlateSection", 1, p["E"], p["nu"], p["h"], p["rho"])
    for j in range(m + 1):
        for i in range(m + 1):
            ops.node(tag(i, j), xs[i], xs[j], 0.0)
    for j in range(m):
        for i in range(m):
            ops.element(element, 1 + i + j * m, tag(i, j), tag(i + 1, j), tag(i + 1, j + 1), tag(i, j + 1), 1)
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    free = 0
    for j in range(m + 1):
        for i in range(m + 1):
            fixed = [0, 0, 0, 0, 0, 1]  # ux uy uz rx ry rz
            if i == 0:
                fixed[2] = fixed[3] = 1
            if j == 0:
                fixed[2] = fixed[4] = 1
            if i == m:
                fixed[0] = fixed[4] = 1
            if j == m:
                fixed[1] = fixed[3] = 1
            ops.fix(tag(i, j), *fixed)
            free += 6 - sum(fixed)
            area = da * da * (0.5 if i in (0, m) else 1.0) * (0.5 if j in (0, m) else 1.0)
            inertia = p["rho"] * p["h"] ** 3 / 12.0 * area
            ops.mass(tag(i, j), 0.0, 0.0, 0.0, inertia, inertia, 0.0)
            ops.load(tag(i, j), 0.0, 0.0, p["q"] * area, 0.0, 0.0, 0.0)
    return tag(m, m), free


def opensees_critical_step(ops, free: int) -> float:
    """2 / omega_max of the model built, from all ``free`` eigenvalues of its assembled
    K and M."""
    ops.wipeAnalysis()
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.algorithm("Linear")
    ops.integrator("CentralDifference")
    ops.analysis("Transient")
    values = ops.eigen("-fullGenLapack", free)
    ops.wipeAnalysis()
    return 2.0 / math.sqrt(max(values))


def run_opensees(ops, m: int, element: str, integrator: str, p: dict,
                 refactor: bool = False) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(times, centre deflections sampled every p['sample'], wall time [s], dt); the step's
    matrix factorised once, or at every step with ``refactor``."""
    centre, free = build_opensees(ops, m, element, p)
    start = time.perf_counter()  # as shellsim's run time, from the built model
    dt_critical = opensees_critical_step(ops, free)
    dt = 0.9 * dt_critical
    steps = math.ceil(p["end"] / dt)
    dt = p["end"] / steps
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("Diagonal" if integrator == "ExplicitDifference" else "BandGeneral")
    ops.algorithm("Linear", *([] if refactor else ["-factorOnce"]))
    ops.integrator(integrator)
    ops.analysis("Transient")
    times, values = [0.0], [0.0]
    every = max(1, round(p["sample"] / dt))
    for k in range(1, steps + 1):
        ops.analyze(1, dt)
        if k % every == 0 or k == steps:
            times.append(k * dt)
            values.append(ops.nodeDisp(centre, 3))
    wall = time.perf_counter() - start
    return np.asarray(times), np.asarray(values), wall, dt


def judged(deck, times, values) -> dict:
    """Error of the first peak and of its time [%] by the deck's own references."""
    from shellsim.verify.check import check

    results = {r.measure: check(r, times, values) for r in deck.reference}
    return {"peak_error_percent": results["min"]["error_percent"],
            "peak_time_error_percent": results["first_peak_time"]["error_percent"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ours", type=int, nargs="+", default=[2, 4, 8], help="9-node meshes (n x n)")
    parser.add_argument("--theirs", type=int, nargs="+", default=[4, 8, 16], help="4-node meshes (m x m)")
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds; wall times are medians")
    parser.add_argument("--refactor", action="store_true", help="OpenSees factorises its step's matrix every step")
    parser.add_argument("--threads", type=int, default=1, help="shellsim's kernel threads (OpenSees runs on one)")
    args = parser.parse_args()
    import numba

    numba.set_num_threads(args.threads)
    from shellsim.bench import plate_ladder
    from shellsim.deck import parse_deck

    deck = parse_deck(DECK.read_text())
    p = plate_parameters(deck)
    ops = load_opensees()
    rows: dict[tuple[str, int], dict] = {}
    for _ in range(args.rounds):
        for row in plate_ladder(tuple(args.ours)):
            n = int(row["mesh"].split("x")[0])
            entry = rows.setdefault(("shellsim 9-node", n), {"nodes": (2 * n + 1) ** 2, "walls": []})
            entry |= {"peak_error_percent": row["peak_error_percent"],
                      "peak_time_error_percent": row["peak_time_error_percent"]}
            entry["walls"].append(row["wall_time_s"])
        for element, integrator in PEERS:
            for m in args.theirs:
                times, values, wall, dt = run_opensees(ops, m, element, integrator, p, args.refactor)
                entry = rows.setdefault((f"OpenSees {element} ({integrator})", m), {"nodes": (m + 1) ** 2, "walls": []})
                entry |= judged(deck, times, values) | {"dt": dt}
                entry["walls"].append(wall)
    print(f"shellsim on {args.threads} thread(s), OpenSees on 1")
    print("| code | mesh | nodes | first-peak error [%] | peak-time error [%] | wall time [s] (median) |")
    print("|---|---|---|---|---|---|")
    for (code, size), r in rows.items():
        print(f"| {code} | {size} x {size} | {r['nodes']} | {r['peak_error_percent']:+.3f} "
              f"| {r['peak_time_error_percent']:+.3f} | {statistics.median(r['walls']):.3f} |")


if __name__ == "__main__":
    main()
