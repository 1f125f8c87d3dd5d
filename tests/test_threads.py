"""The element loop shares elements out over threads; every result must be the same to
the last bit for any number of threads (each element writes its own slots, and nodes
add them in one fixed order)."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

#: A short run of a distorted, pressurised Mooney-Rivlin open tube quarter (free, so it also moves as a body) (Technique 1 with
#: the fibre-length update) and of the same tube with Technique 2 (incremental, its own
#: fibre-length update): positions, directors, fibre lengths, stresses and the energies'
#: sums after 40 steps (289 nodes: two blocks of the node loops, shellsim.solver.explicit),
#: then the forces evaluated again from Python (shellsim.element.static_loop.ElementLoop).
SCRIPT = """
import sys
import numpy as np
from shellsim.deck import parse_deck
from shellsim.geometry import build_mesh
from shellsim.model import build_model
from shellsim.solver.simulation import Simulation
from shellsim.solver.explicit import NODE_BLOCK
from shellsim.threads import ThreadChooser
from tests.conftest import deck_text

CHOOSE = sys.argv[2] == "choose"

def run(material, section):
    text = deck_text('builder = "tube"\\ninner_radius = 1.0\\nlength = 1.0',
                     '[mesh]\\ndivisions = { around = 8, axial = 8 }\\n'
                     '[[load]]\\ntype = "pressure"\\nset = "wall"\\nvalue = 40.0\\nface = "bottom"\\n')
    text = text.replace('model = "linear_elastic"\\nE = 1000.0\\nnu = 0.3', material)
    text = text.replace("[section]", "[section]\\n" + section).replace("thickness = 0.01", "thickness = 0.1")
    deck = parse_deck(text)
    sim = Simulation(build_model(deck, build_mesh(deck)), static=True)  # its forces from Python: the element loop
    if CHOOSE:  # try the other count on every second block of 4 steps
        sim.threads = ThreadChooser(sim.threads.current, probe_interval=0.0, probe_seconds=0.0, longest_interval=0.0)
    dt = 0.5 * sim.critical_time_step()
    while sim.state.steps < 40:
        sim.advance(40 * dt, dt, 40 - sim.state.steps)
    assert sim.state.steps == 40
    s = sim.state
    assert s.x.shape[0] > NODE_BLOCK
    stepped = [a.copy() for a in (s.x, s.d, s.h, s.stress, s.f_int, s.fr_int, s.fields.work, s.fields.energy)]
    sim.evaluate_forces()  # the element loop called from Python, its groups over the threads
    return stepped + [s.h, s.stress, s.f_int, s.fr_int]

arrays = (run('model = "mooney_rivlin"\\nC1 = 200.0\\nC2 = 50.0', "technique = 1")
          + run('model = "linear_elastic"\\nE = 1000.0\\nnu = 0.3', "technique = 2"))
np.savez(sys.argv[1], *arrays)
"""


def _results(threads: int, folder, choose: bool = False) -> list[np.ndarray]:
    out = folder / f"threads{threads}{'choose' * choose}.npz"
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    subprocess.run([sys.executable, "-c", SCRIPT, str(out), "choose" if choose else "fixed"], check=True, env=env,
                   cwd=os.path.dirname(os.path.dirname(__file__)))
    with np.load(out) as data:
        return [data[name] for name in data.files]


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores to run two threads")
def test_one_and_two_threads_give_identical_bits(tmp_path):
    """Also when the thread chooser moves the steps between one and two threads every
    few steps (:mod:`shellsim.threads`)."""
    one, two, moving = _results(1, tmp_path), _results(2, tmp_path), _results(2, tmp_path, choose=True)
    assert len(one) == len(two) == len(moving) == 24
    for a, b, c in zip(one, two, moving):
        assert np.abs(a).max() > 0.0
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)


def test_kernels_compile_at_llvm_level_1_unless_told_and_each_level_has_its_own_cache():
    """shellsim sets numba's optimisation level to 1 (docs/verification.md: a fifth less
    compiling, the same speed and bits); a level the user sets wins, and the compiled-code
    cache folder differs by level, so no level loads another's code."""
    probe = "import shellsim, numba, os; print(int(numba.config.OPT), os.environ['NUMBA_CACHE_DIR'])"
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_OPT", "NUMBA_CACHE_DIR")}
    default = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True)
    told = subprocess.run([sys.executable, "-c", probe], env=env | {"NUMBA_OPT": "3"}, capture_output=True, text=True,
                          check=True)
    (level, folder), (told_level, told_folder) = default.stdout.split(), told.stdout.split()
    assert (level, told_level) == ("1", "3") and folder != told_folder


def test_waiting_threads_spin_10000_turns_unless_the_user_says_how_they_wait():
    """shellsim shortens libgomp's spin before a waiting thread sleeps (300,000 turns held
    the CPUs a late thread needed on a busy machine: docs/verification.md, "Threads on a
    busy machine"); the user's own GOMP_SPINCOUNT or OMP_WAIT_POLICY is kept."""
    probe = "import shellsim, os; print(os.environ.get('GOMP_SPINCOUNT', 'unset'))"
    env = {k: v for k, v in os.environ.items() if k not in ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")}

    def spins(**told):
        return subprocess.run([sys.executable, "-c", probe], env=env | told, capture_output=True, text=True,
                              check=True).stdout.strip()

    assert (spins(), spins(GOMP_SPINCOUNT="500"), spins(OMP_WAIT_POLICY="PASSIVE")) == ("10000", "500", "unset")


def test_numba_imported_before_shellsim_still_uses_its_cache_folder_and_level():
    """A script that imports numba first had numba read its settings before shellsim set
    them: its kernels compiled at level 3 into the source tree's __pycache__, where numba
    checks each function against its own file only (stale element code in a cached loop)."""
    probe = ("import numba, shellsim, os; from shellsim.element import response; "
             "print(int(numba.config.OPT), response.group_response._cache._cache_path, os.environ['NUMBA_CACHE_DIR'])")
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_OPT", "NUMBA_CACHE_DIR")}
    level, path, folder = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True,
                                         check=True).stdout.split()
    assert level == "1" and path.startswith(folder) and "__pycache__" not in path
