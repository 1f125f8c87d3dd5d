"""Cost per element-step and fixed costs against mesh size: the bench plate and the
default artery tube from about 100 to about 100,000 elements.

Each size runs in a fresh process (so its peak memory is its own): meshing, model build,
first masses and forces (kernels compiled or loaded from the cache), first critical
step, then a few hundred steps (fewer on the largest meshes) timed for microseconds per
element-step, the thread chooser's trials among them, as in a run; the set-up (mesh,
model, kernels, first step) over 1,000 steps at that pace. Prints a Markdown table;
nothing is asserted.

    .venv/bin/python benchmarks/scaling.py [--sizes 100 1000 10000 100000] [--threads N]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: One size of one scene, in a child process; prints a JSON row.
CHILD = """
import json, resource, sys, time, tomllib
from shellsim.deck import deck_from_data
from shellsim.execute import built_run
scene, divisions, steps = sys.argv[1], json.loads(sys.argv[2]), int(sys.argv[3])
path = {"plate": "decks/bench/plate_step.toml", "tube": "decks/artery_inflation.toml"}[scene]
data = tomllib.loads(open(path).read())
data["mesh"]["divisions"] = divisions
run = built_run(deck_from_data(data), ROOT)
sim = run.sim
start = time.perf_counter()
dt = sim.critical_time_step() / 1.25
first_dt = time.perf_counter() - start
sim.advance(5 * dt, dt, 5)
# every step asked for: a call returns early while the thread chooser tries a count on a few
taken, start = 0, time.perf_counter()
while taken < steps:
    taken += sim.advance(sim.state.t + (steps - taken) * dt, dt, steps - taken)
seconds = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"scene": scene, "elements": sim.model.n_elements, "steps": taken,
                  "us_per_element_step": 1e6 * seconds / (taken * sim.model.n_elements),
                  "peak_bytes_per_element": peak / sim.model.n_elements, **run.startup, "first_dt_s": first_dt}))
"""


def divisions(scene: str, elements: int) -> dict:
    """Mesh divisions giving about ``elements`` elements: a square plate quarter, or a
    tube four times as long as its quarter circumference, with its cap."""
    if scene == "plate":
        n = max(1, round(math.sqrt(elements)))
        return {"length": n, "width": n}
    around = max(2, 2 * round(math.sqrt(elements / 4.75) / 2))  # wall 4 a^2 + cap 3 (a/2)^2
    return {"around": around, "axial": 4 * around}


def steps_for(elements: int) -> int:
    """About 2 million element-steps, between 20 and 300 steps."""
    return int(min(300, max(20, 2e6 / elements)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10000, 100000])
    parser.add_argument("--threads", type=int, default=None, help="kernel threads (default: numba's, every core)")
    parser.add_argument("--scenes", nargs="+", default=["plate", "tube"], choices=["plate", "tube"])
    args = parser.parse_args()
    env = dict(os.environ)
    if args.threads:
        env["NUMBA_NUM_THREADS"] = str(args.threads)
    print("| scene | elements | steps | us/element-step | peak memory/element [kB] | mesh [s] | model [s] "
          "| kernels [s] | first dt [s] | set-up / 1,000 steps |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for scene in args.scenes:
        for size in args.sizes:
            split = divisions(scene, size)
            done = subprocess.run([sys.executable, "-c", f"ROOT = {str(ROOT)!r}\n" + CHILD, scene, json.dumps(split),
                                   str(steps_for(size))], capture_output=True, text=True, env=env, cwd=ROOT)
            if done.returncode:
                print(f"| {scene} | ~{size} | failed: {done.stderr.strip().splitlines()[-1]} |", flush=True)
                continue
            r = json.loads(done.stdout.strip().splitlines()[-1])
            set_up = r["mesh_s"] + r["model_s"] + r["kernels_s"] + r["first_dt_s"]
            thousand = 1e3 * r["us_per_element_step"] * 1e-6 * r["elements"]  # 1,000 steps at the pace timed
            print(f"| {scene} | {r['elements']:,} | {r['steps']} | {r['us_per_element_step']:.1f} "
                  f"| {r['peak_bytes_per_element'] / 1e3:.1f} | {r['mesh_s']:.2f} | {r['model_s']:.2f} "
                  f"| {r['kernels_s']:.2f} | {r['first_dt_s']:.2f} | {set_up / thousand:.3f} |", flush=True)


if __name__ == "__main__":
    main()
