"""Time to the first answer from an empty compiled-code cache: for each deck, a fresh
process with a cache folder of its own runs the scene until its second frame (the first
after the initial state: a load step of a static run, an output interval of an explicit
one) and stops. Reports the wall time from the process' start to that frame, the part
numba spent compiling (its outermost compile events), and the same with the cache then
warm. Prints a Markdown table; nothing is asserted.

    .venv/bin/python benchmarks/cold_start.py [DECK ...]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DECKS = ["decks/tissue/carotid_hgo_pulse.toml", "decks/verification/test02_cantilever_uniform_load_3.toml",
         "decks/verification/test09_aorta_static.toml"]

#: Run in the fresh process: the scene until its second frame, then a JSON line of times.
CHILD = """
import json, sys, time
start = time.perf_counter()
from pathlib import Path
import shellsim
from shellsim.compile_watch import watching_compiles
from shellsim.deck import load_deck
from shellsim.execute import run_scene
from shellsim.solver.run import Listener

class StopAtSecondFrame(Listener):
    frames = 0
    def on_frame(self, run):
        self.frames += 1
        if self.frames == 2:
            raise KeyboardInterrupt("second frame")

compiling = []
deck = Path(sys.argv[1])
with watching_compiles(lambda name: None, lambda name, seconds: compiling.append(seconds)):
    run, summary = run_scene(load_deck(deck), deck, Path(sys.argv[2]), StopAtSecondFrame())
print(json.dumps({"wall": time.perf_counter() - start, "compiling": sum(compiling), "status": run.status}))
"""


def first_answer(deck: str, cache: str) -> dict:
    """The child's times for ``deck`` with the compiled-code cache in ``cache``."""
    with tempfile.TemporaryDirectory() as out:
        done = subprocess.run([sys.executable, "-c", CHILD, deck, out], cwd=ROOT, capture_output=True, text=True,
                              env={**os.environ, "NUMBA_CACHE_DIR": cache}, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    decks = sys.argv[1:] or DECKS
    print("| deck | cold: to the first answer | of it compiling | warm: to the first answer |")
    print("|---|---|---|---|")
    for deck in decks:
        with tempfile.TemporaryDirectory() as cache:
            cold = first_answer(deck, cache)
            warm = first_answer(deck, cache)
        print(f"| {Path(deck).stem} | {cold['wall']:.1f} s | {cold['compiling']:.1f} s | {warm['wall']:.1f} s |",
              flush=True)


if __name__ == "__main__":
    main()
