"""The element response compiled by a second process on a first run: the cache's saves
under a lock, the function loaded here from what the other process saved (not compiled
again), a failed process leaving it to compile here, a failed run stopping it, and a
simulation built that way giving the same forces to the bit."""

from __future__ import annotations

import fcntl
import functools
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from numba import njit, typeof, types
from numba.core import caching

from shellsim.array_copy import copy_into
from shellsim.cache_lock import LOCK_FILE, lock_cache_saves
from shellsim.compile_beside import CompiledBeside
from shellsim.element.response import response_signature
from shellsim.element.work_arrays import group_arrays
from shellsim.element.steps import steps_of
from shellsim.solver import simulation
from shellsim.solver.simulation import Simulation

from .test_element import MOONEY_RIVLIN, make_model, moved


def test_a_cache_save_holds_its_folders_lock(tmp_path, monkeypatch):
    """numba reads the index, picks a data file's number and writes both; a second process
    doing the same at once would pick the same number for another signature. Each save
    holds the folder's lock throughout: another descriptor cannot take it meanwhile."""
    assert lock_cache_saves()
    seen = []
    write_index = caching.IndexDataCacheFile._save_index

    def save_index_noting_the_lock(self, overloads):
        with open(tmp_path / LOCK_FILE, "rb+") as other:
            try:
                fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
                seen.append("free")
            except BlockingIOError:
                seen.append("held")
        write_index(self, overloads)

    monkeypatch.setattr(caching.IndexDataCacheFile, "_save_index", save_index_noting_the_lock)
    index = caching.IndexDataCacheFile(str(tmp_path), "f", source_stamp=(0.0, 0))
    index.save("first signature", b"code 1")
    index.save("second signature", b"code 2")
    assert seen == ["held", "held"]
    assert (index.load("first signature"), index.load("second signature")) == (b"code 1", b"code 2")
    with open(tmp_path / LOCK_FILE, "rb+") as other:
        fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)  # free again after the saves


#: In a process of its own on an empty cache: copy_into compiled by a second process (and a
#: function of this script, which the second process cannot import, compiled here), each
#: called through its holder before and after; prints what happened as JSON.
BESIDE_SCRIPT = """
import json
import numpy as np
from numba import njit, types
from shellsim.array_copy import copy_into
from shellsim.compile_beside import CompiledBeside
from shellsim.element.response import response_signature
from shellsim.element.work_arrays import group_arrays
from shellsim.element.steps import steps_of

@njit
def call(held, a, b):
    held[0](a, b)

@njit
def stand_in(a, b):
    pass

@njit
def doubled_into(a, b):
    b[:] = 2.0 * a

signature = types.none(types.float64[::1], types.float64[::1])
a = np.arange(1.0, 4.0)
report = {}
for name, function in (("copy_into", copy_into), ("doubled_into", doubled_into)):
    beside = CompiledBeside(function, stand_in, signature, beside=True)
    b = np.zeros(3)
    call(beside.held, a, b)
    before = b.tolist()
    with beside.alongside():
        pass
    call(beside.held, a, b)
    report[name] = {"before": before, "after": b.tolist(), "pending": beside.pending,
                    "loaded": sum(function.stats.cache_hits.values()),
                    "compiled": sum(function.stats.cache_misses.values())}
print(json.dumps(report))
"""


def test_a_function_compiled_beside_is_loaded_here_and_a_failed_process_leaves_it_to_compile_here(tmp_path):
    """The stand-in answers until the block ends; then the function answers, loaded from the
    cache the second process wrote (the same signature's entry: not compiled again here).
    A function the second process cannot reach compiles here after it fails."""
    env = os.environ | {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", BESIDE_SCRIPT], env=env, capture_output=True, text=True,
                          check=True, cwd=tmp_path)
    report = json.loads(done.stdout.splitlines()[-1])
    copied, doubled = report["copy_into"], report["doubled_into"]
    assert copied["before"] == doubled["before"] == [0.0, 0.0, 0.0]
    assert copied["after"] == [1.0, 2.0, 3.0] and doubled["after"] == [2.0, 4.0, 6.0]
    assert not copied["pending"] and not doubled["pending"]
    assert (copied["loaded"], copied["compiled"]) == (1, 0)
    assert (doubled["loaded"], doubled["compiled"]) == (0, 1)


@pytest.mark.parametrize("static", [False, True], ids=["explicit", "static"])
def test_a_simulation_whose_response_compiled_beside_gives_the_same_forces_to_the_bit(static, monkeypatch):
    """Built with the response compiled by a second process (the loops first run around the
    stand-in): the same initial state, and the same forces at a moved one, as built with
    the response at once (a Mooney-Rivlin tube whose fibre lengths follow the stretch)."""
    _, model = make_model('builder = "tube"\ninner_radius = 1.0\nlength = 1.0', "divisions = { around = 4, axial = 3 }",
                          material=MOONEY_RIVLIN)
    built = {}
    for beside in (False, True):
        monkeypatch.setattr(simulation, "CompiledBeside", functools.partial(CompiledBeside, beside=beside))
        built[beside] = Simulation(model, static=static)
    at_once, beside = built[False], built[True]
    rng = np.random.default_rng(3)
    x, d, e1 = moved(model, 0.05, rng.standard_normal((model.n_nodes, 3)), rng.standard_normal((model.n_nodes, 2)))
    for name in ("f_int", "fr_int", "stress", "h", "mt", "mr"):
        np.testing.assert_array_equal(getattr(at_once.state, name), getattr(beside.state, name))
    for sim in (at_once, beside):
        sim.state.x[:], sim.state.d[:], sim.state.e1[:] = x, d, e1
        sim.evaluate_forces()
    assert np.abs(at_once.state.f_int).max() > 0.0
    for name in ("f_int", "fr_int", "stress", "h"):
        np.testing.assert_array_equal(getattr(at_once.state, name), getattr(beside.state, name))


@pytest.mark.parametrize("material", [None, MOONEY_RIVLIN], ids=["small strain", "Mooney-Rivlin"])
def test_the_response_signature_made_in_python_has_the_compiled_functions_types(material):
    """The signature the second process compiles the response for takes the types of the
    group's arrays and decisions from their Python versions: they must be the types the
    compiled ones give, else the response would be compiled again here."""
    _, model = make_model('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', "divisions = { length = 2, width = 2 }",
                          material=material)
    rule = model.rule
    signature = response_signature(rule, model.material)
    arrays = group_arrays(rule.N.shape[0], len(rule.tz), len(rule.wq), rule.vol_basis.shape[1])
    assert signature.args[3:6] == tuple(typeof(a) for a in arrays)
    assert signature.args[0] == typeof(steps_of(model.material, np.bool_(False)))


def test_work_that_fails_meanwhile_stops_the_second_process():
    """A run that fails while the response compiles beside (a bad mesh, an interrupt) ends
    with no process left compiling behind it."""
    signature = types.none(types.float64[::1], types.float64[::1])
    beside = CompiledBeside(copy_into, njit(lambda a, b: None), signature, beside=True)
    with pytest.raises(RuntimeError, match="the model broke"):
        with beside.alongside():
            raise RuntimeError("the model broke")
    assert beside._process.poll() is not None and beside.pending
