"""Wall time of stepping on one thread, on every usable CPU, and on the count the thread
chooser picks (shellsim.threads), on an idle machine and under a background load of one
busy process per CPU: the case where parallel loops wait at their ends for a thread the
scheduler took away. Steps the Scordelis-Lo roof (Mooney-Rivlin, Technique 1) at two mesh
sizes from rest at the critical step over 1.25; each configuration is run ``--repeats``
times in turn and the median reported. Prints a Markdown table; nothing is asserted.

The threads wait at a loop's end as libgomp's GOMP_SPINCOUNT says, read when they start:
shellsim sets 10,000 turns unless the environment says otherwise, so libgomp's own
default is measured as ``GOMP_SPINCOUNT=300000 .venv/bin/python benchmarks/...``; the
count in effect heads the table.

    .venv/bin/python benchmarks/threads_under_load.py [--divisions 8 16] [--seconds 4] [--repeats 3] [--loads 0 2]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from contextlib import contextmanager

import numba

from shellsim.bench import MOONEY_RIVLIN, scordelis_lo
from shellsim.threads import ThreadChooser, kernel_threads, usable_cpus

BUSY = "while True: pass"


@contextmanager
def background_load(processes: int):
    """``processes`` busy Python processes for the block's duration."""
    busy = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(processes)]
    try:
        time.sleep(1.0)
        yield
    finally:
        for p in busy:
            p.kill()
            p.wait()


def us_per_element_step(divisions: int, count: int, choose: bool, seconds: float) -> tuple[float, int]:
    """(microseconds per element-step, the chooser's count at the end) for ``seconds`` of
    stepping on ``count`` threads, chosen against one thread when ``choose``."""
    with kernel_threads(count):
        sim = scordelis_lo(divisions, MOONEY_RIVLIN, {"technique": 1})
        sim.threads = ThreadChooser(count, choose=choose)
        dt = sim.critical_time_step() / 1.25
        sim.advance(sim.state.t + 10 * dt, dt, 10)  # loads the kernels
        start, steps = time.perf_counter(), 0
        while time.perf_counter() - start < seconds:
            steps += sim.advance(sim.state.t + 200 * dt, dt, 200)
        elapsed = time.perf_counter() - start
    return 1e6 * elapsed / (steps * sim.model.n_elements), sim.threads.current


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", type=int, nargs="+", default=[8, 16])
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--loads", type=int, nargs="+", default=[0, usable_cpus()],
                        help="busy background processes of each round (default: none, then one per usable CPU)")
    args = parser.parse_args()
    most = min(numba.config.NUMBA_NUM_THREADS, usable_cpus())
    configs = [("1 thread", 1, False), (f"{most} threads", most, False), (f"chosen from 1 and {most}", most, True)]
    policy, spins = os.environ.get("OMP_WAIT_POLICY"), os.environ.get("GOMP_SPINCOUNT", "libgomp's default")
    waiting = f"OMP_WAIT_POLICY={policy}" if policy else f"{spins} spin turns"
    print(f"Threads wait: {waiting}\n")
    print(f"| load | elements | {' | '.join(c[0] for c in configs)} |")
    print("|---|---|" + "---|" * len(configs))
    for load in args.loads:
        with background_load(load):
            for divisions in args.divisions:
                runs = {c[0]: [] for c in configs}
                ends = {c[0]: [] for c in configs}
                for _ in range(args.repeats):
                    for label, count, choose in configs:
                        us, end = us_per_element_step(divisions, count, choose, args.seconds)
                        runs[label].append(us)
                        ends[label].append(end)
                cells = [f"{statistics.median(runs[c[0]]):.2f} us" + (f" (ends on {statistics.mode(ends[c[0]])})"
                                                                       if c[2] else "") for c in configs]
                print(f"| {'idle' if not load else f'{load} busy processes'} | {divisions * divisions} | "
                      + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
