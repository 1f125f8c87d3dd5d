"""A run's folder is never corrupted: a run holds it, so a second run into it is refused
before it writes anything; a new run first clears what an earlier run left there, so
nothing of the earlier run is taken for the new run's; a disk that fills stops the run
cleanly, with its summary and its frames so far."""

from __future__ import annotations

import json
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.output.folder import LOCK_NAME

from .conftest import CLAMPED_PLATE, ROOT, deck_text

runner = CliRunner()
#: A clamped plate under a pressure, a few frames long.
PLATE = deck_text(*CLAMPED_PLATE).replace("end_time = 1.0", "end_time = 0.05")


@contextmanager
def held_by_another_process(folder: Path):
    """``folder`` held, as a running run holds it, by a second Python process until the
    block ends."""
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys; from pathlib import Path; from shellsim.output.folder import claimed\n"
                               f"with claimed(Path({str(folder)!r})):\n    print('held', flush=True)\n"
                               "    sys.stdin.read()"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        yield
    finally:
        holder.communicate("")


def test_a_second_run_into_a_folder_in_use_is_refused_and_touches_nothing(tmp_path):
    """While another process holds the folder (as a first run does), ``shellsim run`` into
    it exits with a message naming the holder, and every file there keeps its bytes; once
    the folder is free the same command runs."""
    deck = tmp_path / "plate.toml"
    deck.write_text(PLATE)
    folder = tmp_path / "run"
    folder.mkdir()
    earlier = {"deck.toml": b"# the first run's deck\n", "history.csv": b"time,dt\n0,1e-3\n",
               "results.xdmf": b"<Xdmf/>"}
    for name, data in earlier.items():
        (folder / name).write_bytes(data)
    with held_by_another_process(folder):
        result = runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"])
        message = " ".join(result.output.split())
        assert result.exit_code != 0 and "is in use by another run (pid" in message
        assert {path.name: path.read_bytes() for path in folder.iterdir() if path.name in earlier} == earlier
        assert not (folder / "summary.json").exists()
    result = runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"])
    assert result.exit_code == 0, result.output
    assert (folder / LOCK_NAME).exists()


def test_a_new_run_clears_what_an_earlier_run_left(tmp_path):
    """An earlier run's summary, checkpoint, VTU frames, cable series and plots are gone
    once a new run (writing XDMF only, no cables, no checkpoints) has started; the summary
    there is the new run's."""
    deck = tmp_path / "plate.toml"
    deck.write_text(PLATE)
    folder = tmp_path / "run"
    (folder / "frames").mkdir(parents=True)
    (folder / "frames" / "results_0007.vtu").write_text("<VTKFile/>")
    for name in ("results.pvd", "cables.xdmf", "cables.h5", "checkpoint.npz"):
        (folder / name).write_text("earlier")
    (folder / "summary.json").write_text(json.dumps({"status": "completed", "title": "an earlier scene"}))
    (folder / "notes.txt").write_text("the user's own")
    (folder / "plots").mkdir()
    (folder / "plots" / "tip.png").write_bytes(b"an earlier run's plot")
    result = runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"])
    assert result.exit_code == 0, result.output
    left = {path.name for path in folder.iterdir()}
    assert not left & {"frames", "results.pvd", "cables.xdmf", "cables.h5", "checkpoint.npz", "plots"}
    assert json.loads((folder / "summary.json").read_text())["title"] == "test scene"
    assert (folder / "notes.txt").read_text() == "the user's own"


@pytest.fixture
def small_disk(tmp_path):
    """A 3 MB file system (a tmpfs; mounting one needs root, so the test is skipped
    without)."""
    mount = tmp_path / "small"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=3M", "tmpfs", str(mount)], capture_output=True).returncode:
        pytest.skip("mounting a small tmpfs needs root")
    yield mount
    subprocess.run(["umount", "-l", str(mount)], check=True)


#: What a run stopped by a full disk says: the system's error, or its own check before a
#: frame (HDF5 meeting a full disk mid-write could crash the process later).
DISK_FULL = ("No space left on device", "the disk is full or nearly")


def test_a_disk_that_fills_mid_run_stops_it_cleanly(small_disk):
    """Test 2's cantilever writing a frame every 0.5 ms into 3 MB: the run stops with exit
    code 2 and an error saying the disk is full, its summary says 'output failed', no
    partial file is left, and every frame written before stays readable, with a checkpoint
    that --resume goes on from to the end once there is room."""
    import meshio

    deck = small_disk.parent / "cantilever.toml"
    deck.write_text((ROOT / "decks" / "verification" / "test02_cantilever_uniform_load_3.toml").read_text()
                    .replace("[output]\ninterval = 0.001", "[output]\ninterval = 0.0005\ncheckpoint_interval = 0.01"))
    folder = small_disk / "run"
    result = runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"])
    assert result.exit_code == 2 and any(said in " ".join(result.output.split()) for said in DISK_FULL), result.output
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["status"] == "output failed" and any(said in summary["message"] for said in DISK_FULL)
    assert not list(folder.glob("*.partial*"))
    with meshio.xdmf.TimeSeriesReader(folder / "results.xdmf") as reader:  # its .h5 closed after
        reader.read_points_cells()
        assert 10 < reader.num_steps == summary["frames"] < 241
        reader.read_data(reader.num_steps - 1)
    assert (folder / "checkpoint.npz").exists()
    subprocess.run(["mount", "-o", "remount,size=60M", str(small_disk)], check=True)
    result = runner.invoke(app, ["run", "--resume", str(folder), "--quiet"])
    assert result.exit_code == 0, result.output
    assert json.loads((folder / "summary.json").read_text())["status"] == "completed"


@pytest.mark.parametrize("room", ["16k", "64k"])
def test_a_disk_full_from_the_start_stops_with_a_message(small_disk, tmp_path, room):
    """The plate run onto a disk of 16 or 64 kB (less than its first frame and the room
    kept free beside it): exit code 2 and a message, never a traceback or a crash (at 64
    kB HDF5 met the full disk mid-write and the process died of a segmentation fault),
    and a summary saying 'output failed' wherever there was room for one."""
    subprocess.run(["mount", "-o", f"remount,size={room}", str(small_disk)], check=True)
    deck = tmp_path / "plate.toml"
    deck.write_text(PLATE)
    folder = small_disk / "run"
    done = subprocess.run([sys.executable, "-m", "shellsim", "run", str(deck), "--out", str(folder), "--quiet"],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    said = " ".join(done.stderr.split())
    assert any(text in said for text in DISK_FULL), said
    if (folder / "summary.json").exists():
        assert json.loads((folder / "summary.json").read_text())["status"] == "output failed"
