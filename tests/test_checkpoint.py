"""Restart: an explicit run stopped part way (as Ctrl-C stops it) and resumed from its last
checkpoint ends with the same history.csv, byte for byte, and the same frames, number for
number, as the run that never stopped; and what cannot be resumed says why."""

from __future__ import annotations

import json
import os
import pickle
import shutil
from pathlib import Path

import meshio
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.deck import load_deck
from shellsim.deck.resolved import RESOLVED_NAME, read_resolved
from shellsim.errors import OutputError
from shellsim.execute import built_run, run_scene
from shellsim.output.checkpoint import CHECKPOINT_NAME, read_checkpoint, restore
from shellsim.solver.run import Listener

from .conftest import ROOT, deck_text, pressed_plates_deck, problems_of

VERIFICATION = ROOT / "decks" / "verification"


class StopAt(Listener):
    """Stops the run, as Ctrl-C does, at its first frame at or after ``t``."""

    def __init__(self, t: float):
        self.t = t

    def on_frame(self, run) -> None:
        if run.sim.state.t >= self.t:
            raise KeyboardInterrupt


def _frames(folder: Path) -> list:
    reader = meshio.xdmf.TimeSeriesReader(folder / "results.xdmf")
    reader.read_points_cells()
    return [reader.read_data(k) for k in range(reader.num_steps)]


def _same_frames(a: Path, b: Path) -> None:
    first, second = _frames(a), _frames(b)
    assert len(first) == len(second)
    for (ta, points_a, cells_a), (tb, points_b, cells_b) in zip(first, second):
        assert ta == tb and points_a.keys() == points_b.keys() and cells_a.keys() == cells_b.keys()
        for name in points_a:
            np.testing.assert_array_equal(points_a[name], points_b[name])
        for name in cells_a:
            np.testing.assert_array_equal(cells_a[name][0], cells_b[name][0])


def _cantilever(tmp_path: Path, name: str, extra: str = "") -> Path:
    """Test 2's cantilever (or its relaxed variant) with checkpoints every 0.01 s and both
    series."""
    text = (VERIFICATION / name).read_text().replace(
        "[output]\n", f'[output]\ncheckpoint_interval = 0.01\nformats = ["xdmf", "vtu"]\n{extra}', 1)
    path = tmp_path / name
    path.write_text(text)
    return path


def _pressed_plates(tmp_path: Path) -> Path:
    """Two plates pressed together and pushed along y against friction, explicitly."""
    text = pressed_plates_deck(tmp_path / "plates.vtu", 1.0, "[solver]\nend_time = 0.4\ndamping = 50.0", '["x"]',
                               "friction = 0.3\n[[load]]\ntype = \"body_force\"\nset = \"upper\"\n"
                               "value = [0.0, 20.0, 0.0]\n[output]\ninterval = 0.02\ncheckpoint_interval = 0.1\n")
    path = tmp_path / "plates.toml"
    path.write_text(text)
    return path


SCENES = {
    "cantilever": (lambda tmp: _cantilever(tmp, "test02_cantilever_uniform_load_3.toml"), 0.0455),
    "relaxed": (lambda tmp: _cantilever(tmp, "test02_cantilever_uniform_load_3_relaxed.toml"), 0.0455),
    "contact_with_friction": (_pressed_plates, 0.25),
}


@pytest.mark.parametrize("scene", SCENES)
def test_a_stopped_run_resumed_ends_as_the_run_that_never_stopped(scene, tmp_path):
    make, stop_at = SCENES[scene]
    deck_path = make(tmp_path)
    deck = load_deck(deck_path)
    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    whole.mkdir(), stopped.mkdir()
    done, _ = run_scene(deck, deck_path, whole)
    assert done.status == "completed"
    interrupted, _ = run_scene(deck, deck_path, stopped, StopAt(stop_at))
    assert interrupted.status == "interrupted" and interrupted.sim.state.t < deck.solver.end_time
    checkpoint = read_checkpoint(stopped)
    assert 0.0 < checkpoint["t"] <= interrupted.sim.state.t
    resumed, summary = run_scene(read_resolved(stopped), stopped / RESOLVED_NAME, stopped, checkpoint=checkpoint)
    assert resumed.status == "completed" and summary["steps"] == done.sim.state.steps
    assert (stopped / "history.csv").read_bytes() == (whole / "history.csv").read_bytes()
    _same_frames(whole, stopped)
    if "vtu" in deck.output.formats:
        assert (stopped / "results.pvd").read_bytes() == (whole / "results.pvd").read_bytes()
        assert sorted(p.name for p in (stopped / "frames").iterdir()) == sorted(p.name for p in (whole / "frames").iterdir())


def test_resume_from_the_command_line_and_what_it_refuses(tmp_path):
    """``shellsim run --resume FOLDER`` goes on in the folder; a folder without a
    checkpoint, a deck given as well, or a static deck asking for checkpoints are refused
    with a message naming what to do."""
    runner = CliRunner()
    deck_path = _cantilever(tmp_path, "test02_cantilever_uniform_load_3.toml")
    folder = tmp_path / "run"
    folder.mkdir()
    run_scene(load_deck(deck_path), deck_path, folder, StopAt(0.03))
    result = runner.invoke(app, ["run", "--resume", str(folder), "--quiet"])
    assert result.exit_code == 0, result.output
    assert '"status": "completed"' in (folder / "summary.json").read_text()
    (folder / CHECKPOINT_NAME).unlink()
    result = runner.invoke(app, ["run", "--resume", str(folder), "--quiet"])
    assert result.exit_code != 0 and "holds no checkpoint to resume from" in " ".join(result.output.split())
    result = runner.invoke(app, ["run", str(deck_path), "--resume", str(folder)])
    assert result.exit_code != 0 and "not both" in " ".join(result.output.split())
    static = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0').replace(
        "[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0')
    assert "checkpoints are of the explicit time loop" in problems_of(static + "\n[output]\ncheckpoint_interval = 0.5\n")


@pytest.fixture(scope="module")
def stopped_cantilever(tmp_path_factory) -> Path:
    """The cantilever's folder, its run stopped at 0.03 s with a checkpoint written."""
    tmp_path = tmp_path_factory.mktemp("stopped")
    deck_path = _cantilever(tmp_path, "test02_cantilever_uniform_load_3.toml")
    folder = tmp_path / "run"
    folder.mkdir()
    run_scene(load_deck(deck_path), deck_path, folder, StopAt(0.03))
    return folder


class Planted:
    """A pickle that, if ever unpickled, leaves a file behind."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (Path.touch, (self.marker,))


def _resume(folder: Path):
    return CliRunner().invoke(app, ["run", "--resume", str(folder), "--quiet"])


def test_a_checkpoint_cannot_run_code(stopped_cantilever, tmp_path):
    """A pickle planted as an older checkpoint.pkl, and one inside the npz archive (an
    object array), are never unpickled: nothing they carry runs, and the resume is refused
    naming why."""
    folder = tmp_path / "shared"
    shutil.copytree(stopped_cantilever, folder)
    marker = tmp_path / "ran"
    (folder / CHECKPOINT_NAME).unlink()
    (folder / "checkpoint.pkl").write_bytes(pickle.dumps(Planted(marker)))
    result = _resume(folder)
    assert result.exit_code == 2 and "a pickle can run code" in " ".join(result.output.split())
    assert not marker.exists()
    np.savez(folder / CHECKPOINT_NAME, document=np.array([Planted(marker)], dtype=object))
    result = _resume(folder)
    assert result.exit_code == 2 and "is not a checkpoint shellsim reads" in " ".join(result.output.split())
    assert not marker.exists()


def _document(folder: Path) -> dict:
    with np.load(folder / CHECKPOINT_NAME) as archive:
        return json.loads(bytes(archive["document"]).decode())


def _rewrite(folder: Path, document: dict) -> None:
    with np.load(folder / CHECKPOINT_NAME) as archive:
        arrays = {name: archive[name] for name in archive.files if name != "document"}
    np.savez(folder / CHECKPOINT_NAME, **arrays, document=np.frombuffer(json.dumps(document).encode(), np.uint8))


def test_a_checkpoint_of_another_version_or_deck_is_refused_saying_why(stopped_cantilever, tmp_path):
    """Written by another version, or beside a deck.toml edited since (its load doubled):
    refused with the reason, the folder's files as they were; a FIFO at the checkpoint's
    name is refused at once, not waited on."""
    folder = tmp_path / "shared"
    shutil.copytree(stopped_cantilever, folder)
    document = _document(folder)
    document["$dict"]["version"] = "0.0.1"
    _rewrite(folder, document)
    history = (folder / "history.csv").read_bytes()
    result = _resume(folder)
    assert result.exit_code == 2 and "written by shellsim 0.0.1" in " ".join(result.output.split())
    shutil.copy(stopped_cantilever / CHECKPOINT_NAME, folder / CHECKPOINT_NAME)
    deck = (folder / RESOLVED_NAME).read_text()
    assert "value = -2.85" in deck
    (folder / RESOLVED_NAME).write_text(deck.replace("value = -2.85", "value = -5.7"))
    result = _resume(folder)
    assert result.exit_code == 2 and "of another scene" in " ".join(result.output.split())
    assert (folder / "history.csv").read_bytes() == history
    (folder / CHECKPOINT_NAME).unlink()
    os.mkfifo(folder / CHECKPOINT_NAME)
    result = _resume(folder)
    assert result.exit_code == 2 and "not a regular file" in " ".join(result.output.split())


#: JSON values a damaged or forged document may hold where the checkpoint had another.
JSON_VALUES = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
                           lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner,
                                                                                        max_size=3), max_leaves=8)


def _places(data, path=()):
    """Every place in a JSON document: the keys and indices leading to it."""
    yield path
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    for key, item in items:
        yield from _places(item, (*path, key))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_a_damaged_checkpoint_is_restored_or_refused_never_a_traceback(stopped_cantilever, built_cantilever,
                                                                       tmp_path, data):
    """Any one entry of the checkpoint's document removed or replaced by any JSON value:
    read and restored into the run, or refused with an OutputError; nothing else."""
    document = _document(stopped_cantilever)
    places = [p for p in _places(document) if p]
    path = data.draw(st.sampled_from(places))
    parent = document
    for key in path[:-1]:
        parent = parent[key]
    if data.draw(st.booleans()) and isinstance(parent, dict):
        del parent[path[-1]]
    else:
        parent[path[-1]] = data.draw(JSON_VALUES)
    folder = tmp_path / "damaged"
    folder.mkdir(exist_ok=True)
    shutil.copy(stopped_cantilever / CHECKPOINT_NAME, folder / CHECKPOINT_NAME)
    _rewrite(folder, document)
    try:
        restore(built_cantilever, read_checkpoint(folder))
    except OutputError:
        pass


@pytest.fixture(scope="module")
def built_cantilever(stopped_cantilever):
    """A run built from the stopped cantilever's resolved deck, not started."""
    return built_run(read_resolved(stopped_cantilever), stopped_cantilever)
