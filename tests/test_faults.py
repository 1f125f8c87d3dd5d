"""Faults that end in a message and an exit code, never a traceback, a hang or a silent
wrong answer: each as a user meets it."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from shellsim.cli import EXIT_UNSTABLE, app
from shellsim.errors import MeshError
from shellsim.foreign import read_foreign
from shellsim.imported_deck import import_model
from shellsim.output.derived import principal_stresses

from .conftest import ROOT, pressed_plates_deck, problems_of
from .test_import import feb_held, strip_inp, tethered_plate_feb
from .test_run_folder import PLATE

runner = CliRunner()


def test_a_static_solve_whose_first_tangent_is_singular_stops_naming_the_node(tmp_path):
    """The tethered plate with its chord's end held by the chord alone: at rest the chord
    gives that node no stiffness across it, so the first tangent has no factors. The run
    stops at once with exit code 3 naming the node and where it is, and its summary says
    'not converged' with the same message."""
    model = tmp_path / "slack.feb"
    model.write_text(tethered_plate_feb("4.0").replace(feb_held("4.0", "Across", "End", "yz"), ""))
    done = import_model(model, tmp_path / "imported")
    result = runner.invoke(app, ["run", str(done.deck), "--out", str(tmp_path / "run"), "--quiet"])
    message = " ".join(result.output.split())
    assert result.exit_code == EXIT_UNSTABLE, result.output
    assert "tangent stiffness is singular" in message and "no stiffness in some direction: nodes 10 (the first at " \
        "(2, 0, 0))" in message
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["status"] == "not converged" and "nodes 10" in summary["message"]


def test_check_warns_of_a_node_that_hangs_on_a_slack_chord_alone(tmp_path):
    """`check` of the same deck says beforehand that node 10 hangs on the chord alone and
    what to do; with the chord's end held across it (the model as written) it says
    nothing of it."""
    def checked(text: str) -> str:
        model = tmp_path / "tethered.feb"
        model.write_text(text)
        done = import_model(model, tmp_path / f"imported{len(text)}")
        result = runner.invoke(app, ["check", str(done.deck)])
        assert result.exit_code == 0, result.output
        return " ".join(result.output.split())

    held = tethered_plate_feb("4.0")
    said = checked(held.replace(feb_held("4.0", "Across", "End", "yz"), ""))
    assert "warning: 1 node(s) hang on cables alone with none of their chords in tension at the start: nodes 10 " \
           "(the first at (2, 0, 0))" in said and "rest_length < 1" in said
    assert "hang on cables" not in checked(held)


def test_principal_stresses_of_a_state_gone_to_no_number_are_no_number():
    """The breaking frame of a run whose stresses went NaN: the principal stresses there
    are NaN, those of the finite stresses beside them their eigenvalues, and nothing
    raises (LAPACK's eigensolver refuses NaN)."""
    sigma = np.array([np.diag([1.0, 3.0, 2.0]), np.full((3, 3), np.nan), [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0],
                                                                        [0.0, 0.0, 0.0]]])
    sigma[1, 0, 0] = np.inf
    values, directions = principal_stresses(sigma)
    np.testing.assert_allclose(values[[0, 2]], [[3.0, 2.0, 1.0], [1.0, 0.0, -1.0]], atol=1e-15)
    assert np.isnan(values[1]).all() and np.isnan(directions[1]).all()
    np.testing.assert_allclose(np.abs(directions[0]), [[0, 1, 0], [0, 0, 1], [1, 0, 0]], atol=1e-15)


@pytest.mark.skipif(not hasattr(os, "fork") or sys.platform != "linux", reason="limits a process's memory on Linux")
def test_a_model_file_too_large_for_the_memory_is_a_message(tmp_path):
    """A 21 MB input file read by a process allowed 600 MB of address space (imports take
    about 350 MB): a message naming the file and its size, exit code 2, no traceback."""
    model = tmp_path / "big.inp"
    model.write_text("*Heading\n*Node\n" + "".join(f"{i}, {i * 1e-3:.6f}, {i * 2e-3:.6f}, 0.\n"
                                                   for i in range(1, 600_001)))
    limit = 600 * 2**20
    script = ("import resource, sys\n"
              f"resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))\n"
              "from shellsim.cli import app\n"
              "app(sys.argv[1:])\n")
    done = subprocess.run([sys.executable, "-c", script, "import", str(model), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, env=os.environ | {"COLUMNS": "300"}, timeout=300)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert f"model file '{model}' (21 MB) does not fit in the memory" in " ".join(done.stderr.split())


HGO_STRIP = strip_inp().replace("*Elastic\n200000., 0.0", "*Anisotropic Hyperelastic, holzapfel, local directions=2\n"
                                                          "0.0035, 0., 2.3632, 0.8393, 0.226").replace(
    "*Shell Section, elset=Whole, material=Steel",
    "*Distribution, name=Fibres, location=ELEMENT, Table=T\n, 1., 0., 0., 0., 1., 0.\n7, 0., 1., 0., -1., 0., 0.\n"
    "*Orientation, name=Ori, local directions=2\nFibres\n3, 0.\n0.7660444, 0.6427876, 0.\n0.7660444, -0.6427876, 0.\n"
    "*Shell Section, elset=Whole, material=Steel, orientation=Ori")


def _model(tmp_path, text: str, name: str = "model.inp"):
    path = tmp_path / name
    path.write_text(text)
    return read_foreign(path)


def test_what_an_abaqus_file_says_wrongly_is_named_not_dropped_or_guessed(tmp_path):
    """Supports on degrees of freedom a shell node does not have (7-9) are listed, not
    taken for rotations or dropped unsaid; an element label defined twice is refused
    naming both lines; a zero direction, of an element's axis or of a fibre family, is
    refused or listed, never taken for an angle of 0."""
    held = _model(tmp_path, strip_inp(extra_model="*Boundary\nStrip-1.Tip, 7, 9"))
    assert any("degrees of freedom 7 to 9 of 'Strip-1.Tip': a shell node has 1-6" in line and "none is read" in line
               for line in held.unmapped)
    assert [b["set"] for b in held.tables["boundary"]] == ["Fixed"]
    partly = _model(tmp_path, strip_inp(extra_model="*Boundary\nStrip-1.Tip, 3, 8"))
    assert any("degrees of freedom 3 to 8" in line and "the others are read" in line for line in partly.unmapped)
    tip, = [b for b in partly.tables["boundary"] if b["set"] != "Fixed"]
    assert tip["translations"] == ["z"] and tip["director"] == "fixed"
    twice = strip_inp().replace("*Nset, nset=Root", "*Element, type=S4R\n7, 1, 2, 13, 12\n*Nset, nset=Root")
    with pytest.raises(MeshError, match=r": element 7 is defined a second time \(first at model\.inp:\d+\)"):
        _model(tmp_path, twice)
    with pytest.raises(MeshError, match=r"the direction of elements strip-1\.7 is \(0, 0, 0\)"):
        _model(tmp_path, HGO_STRIP.replace("7, 0., 1., 0., -1., 0., 0.", "7, 0., 0., 0., 0., 0., 0."))
    flat = _model(tmp_path, HGO_STRIP.replace("0.7660444, -0.6427876, 0.", "0., 0., 1."))
    assert "material" not in flat.tables or flat.tables["material"].get("model") != "hgo"
    assert any("has no length in the shell's plane" in line for line in flat.unmapped)


def test_deck_values_that_can_only_be_mistakes_are_refused_naming_the_key(tmp_path):
    """A friction coefficient of 11, and a contact or a probe named after one of
    history.csv's own columns (two 'time' columns made the file ambiguous), are refused
    with the key and what is expected."""
    plates = pressed_plates_deck(tmp_path / "plates.vtu", 1.0, "[solver]\nend_time = 1.0", more="friction = 11.0")
    assert "contact[0].friction" in problems_of(plates) and "less than or equal to 2" in problems_of(plates)
    timed = pressed_plates_deck(tmp_path / "plates.vtu", 1.0, "[solver]\nend_time = 1.0").replace(
        'name = "between"', 'name = "time"')
    assert "contact[0].name: 'time' is one of history.csv's own columns" in problems_of(timed)
    probed = timed.replace('name = "time"', 'name = "between"') + (
        '\n[[output.probe]]\nname = "kinetic_energy"\nquantity = "displacement"\nset = "upper"\ncomponent = "z"\n')
    assert "output.probe[0].name: 'kinetic_energy' is one of history.csv's own columns" in problems_of(probed)


def _cantilever(tmp_path, name: str, old: str, new: str):
    text = (ROOT / "decks" / "verification" / name).read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new))
    return path


def test_runs_that_cannot_give_what_their_deck_asks_say_so(tmp_path):
    """Mass scaling by 1e29 (a step far past any stable one) is refused before the first
    step, exit 2, naming the largest step it takes; a relaxation that has not come to rest
    by its end time (the cantilever's, 0.5 ms after its load holds, asked for 1e-9 of
    its forces) ends 'not converged' with exit code 3 and its residual, not 'completed'
    with 0."""
    heavy = _cantilever(tmp_path, "test02_cantilever_uniform_load_3_mass_scaled.toml", "step = 1.2e-5", "step = 1.2e+4")
    result = runner.invoke(app, ["run", str(heavy), "--out", str(tmp_path / "heavy"), "--quiet"])
    message = " ".join(result.output.split())
    assert result.exit_code == 2 and "every mass would be multiplied by" in message and "ask for a step of at most" \
        in message, result.output
    assert json.loads((tmp_path / "heavy" / "summary.json").read_text())["status"] == "refused"
    restless = _cantilever(tmp_path, "test02_cantilever_uniform_load_3_relaxed.toml",
                           "end_time = 0.12\nrelaxation = { residual = 1e-4 }",
                           "end_time = 0.0605\nrelaxation = { residual = 1e-9 }")
    result = runner.invoke(app, ["run", str(restless), "--out", str(tmp_path / "restless"), "--quiet"])
    assert result.exit_code == EXIT_UNSTABLE and "did not come to rest by solver.end_time" in " ".join(
        result.output.split()), result.output
    summary = json.loads((tmp_path / "restless" / "summary.json").read_text())
    assert summary["status"] == "not converged" and "above solver.relaxation.residual = 1e-09" in summary["message"]


def test_contact_pressure_at_a_cable_s_own_node_is_zero_without_a_warning(monkeypatch):
    """A cable's own node (on no shell) has no area: its contact pressure reads 0, where
    0 / 0 printed a RuntimeWarning on every run of a scene with chordae (warnings are
    errors here); the others are force over area."""
    from types import SimpleNamespace

    from shellsim.output import fields

    class Forces:
        def __init__(self, model, names):
            pass

        def at_nodes(self, t, shape):
            return np.array([[0.0, 0.0, 3.0], [0.0, 4.0, 0.0], [0.0, 0.0, 0.0]])

    monkeypatch.setattr(fields, "ToolForces", Forces)
    sim = SimpleNamespace(model=None, state=SimpleNamespace(t=0.0, fields=SimpleNamespace(shape=None)))
    mesh = SimpleNamespace(node_areas=np.array([1.5, 2.0, 0.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(fields.contact_pressure(sim, mesh), [2.0, 2.0, 0.0])


def test_render_while_a_run_writes_its_series_is_a_message(tmp_path):
    """A run's results.h5 held open for writing (as a running run holds it; HDF5 locks the
    file) while ``shellsim render`` reads the folder: exit code 2 and a message saying a
    run may still be writing it, not h5py's traceback."""
    import h5py

    deck = tmp_path / "plate.toml"
    deck.write_text(PLATE)
    folder = tmp_path / "run"
    assert runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"]).exit_code == 0
    with h5py.File(folder / "results.h5", "a"):
        done = subprocess.run([sys.executable, "-m", "shellsim", "render", str(folder)], capture_output=True, text=True,
                              timeout=300, env=os.environ | {"COLUMNS": "300"})
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert "a run may still be writing it" in " ".join(done.stderr.split())


def test_divisions_too_many_for_the_memory_are_refused_before_meshing(tmp_path, monkeypatch):
    """The aortic valve builder at 2000 x 2000 x 200 divisions (gmsh died of a
    segmentation fault meshing it) on a machine with 24 GB free: refused at once by
    ``check``, exit code 2, naming the elements the divisions give (3 x 2000 x 2200) and
    the memory they need."""
    from shellsim import memory

    monkeypatch.setattr(memory, "available_bytes", lambda: 24e9)
    deck = tmp_path / "valve.toml"
    text = (ROOT / "decks" / "valves" / "aortic_valve_closing.toml").read_text()
    assert "divisions = { around = 12, belly = 6, coaptation = 2 }" in text
    deck.write_text(text.replace("divisions = { around = 12, belly = 6, coaptation = 2 }",
                                 "divisions = { around = 2000, belly = 2000, coaptation = 200 }"))
    result = runner.invoke(app, ["check", str(deck)])
    message = " ".join(result.output.split())
    assert result.exit_code == 2 and "[mesh] divisions give 13,200,000 elements: a run needs about 264 GB of memory and 24 GB is " \
        "available" in message


def test_a_static_summary_states_the_load_reached_and_the_largest_on_the_way():
    """A path that went up to load time 0.3 and back to 0.2 (past a limit point, where an
    arc-length run's clock can end short of its load): the summary's static record says
    both, and each curve's largest load factor."""
    from types import SimpleNamespace

    from shellsim.output.summary import static_record
    from shellsim.solver.static import NewtonStep

    steps = [NewtonStep(t=t, load_time=load, iterations=3, tangents=1, residual=1e-8, cutbacks=0)
             for t, load in ((0.1, 0.1), (0.3, 0.3), (0.4, 0.2))]
    factors = SimpleNamespace(columns=["load_factor_ramp"])
    run = SimpleNamespace(newton=steps, stability=None, measure={"load_factors": factors}.get,
                          history={"load_factor_ramp": [0.0, 0.1, 0.3, 0.2]},
                          tangent_seconds=[0.5, 0.25, 0.25, 0.5])  # a try cut back formed one more
    record = static_record(run)
    assert (record["load_time_reached"], record["largest_load_time"]) == (0.2, 0.3)
    assert record["largest_load_factors"] == {"load_factor_ramp": 0.3}
    assert (record["tangents"], record["tangents_formed"], record["tangent_seconds"]) == (3, 4, 1.5)


def test_a_stop_while_the_meshing_child_is_forked_is_not_lost(ctrl_c_delivered):
    """Ctrl-C arriving inside the fork's own hooks (as one did in the logging module's,
    where it was printed as ignored and lost, and the meshing ran on): the child is
    killed and the interrupt raised once the fork is done, not half a minute later."""
    import time

    from shellsim.geometry.child import in_child

    armed: list[bool] = []

    def interrupt_in_the_hook() -> None:
        if armed:
            armed.clear()
            os.kill(os.getpid(), signal.SIGINT)
            sum(range(10_000))  # Python code in the hook, where the interrupt would be raised

    os.register_at_fork(after_in_parent=interrupt_in_the_hook)
    armed.append(True)
    with pytest.raises(KeyboardInterrupt):
        in_child(time.sleep, 30.0)
