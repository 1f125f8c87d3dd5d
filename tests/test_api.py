"""The Python interface: a scene from a dict or a file, run into a folder, its results read
back as arrays that agree with what the run wrote; errors as the command line gives them."""

from __future__ import annotations

import subprocess
import sys
import tomllib

import numpy as np
import pytest

import shellsim
from shellsim.errors import DeckError, OutputError

from .conftest import CLAMPED_PLATE, ROOT, deck_text

PLATE = deck_text(CLAMPED_PLATE[0], CLAMPED_PLATE[1] + """
[solver]
method = "static"
end_time = 1.0

[output]
interval = 0.5

[[output.probe]]
name = "tip"
quantity = "displacement"
set = "x1y0"
component = "z"
""").replace("[solver]\nend_time = 1.0\n", "", 1).replace("thickness = 0.01", "thickness = 0.05")


def test_a_scene_from_a_dict_runs_and_its_results_read_back(tmp_path):
    """A dict of tables, as TOML gives them, runs as its file would: the history's probe,
    the frames at their times, the last frame's displacement at the tip equal to the
    probe's last reading, and the summary's status."""
    results = shellsim.run(tomllib.loads(PLATE), tmp_path / "out")
    assert results.status == "completed" and results.summary["method"] == "static"
    assert results.times == pytest.approx([0.0, 0.5, 1.0])
    point_data, cell_data = results.frame(-1)
    tip = np.argmin(np.linalg.norm(results.points - [2.0, 0.0, 0.0], axis=1))
    assert point_data["displacement"][tip, 2] == pytest.approx(results.history["tip"][-1], rel=1e-6)
    assert abs(results.history["tip"][-1]) > 1e-3  # the plate bends under the pressure
    assert cell_data["cauchy_stress"].shape == (len(results.cells), 6)
    again = shellsim.Results(tmp_path / "out")
    np.testing.assert_array_equal(again.history["tip"], results.history["tip"])


def test_the_interface_says_what_is_wrong_as_the_command_line_does(tmp_path):
    data = tomllib.loads(PLATE)
    data["section"]["thickness"] = -1.0
    with pytest.raises(DeckError, match=r"section.thickness"):
        shellsim.load(data)
    with pytest.raises(DeckError, match="file not found"):
        shellsim.load(tmp_path / "missing.toml")
    with pytest.raises(OutputError, match="holds no finished run"):
        shellsim.Results(tmp_path)
    scene = shellsim.load(ROOT / "decks" / "verification" / "test09_aorta_static.toml")
    assert scene.solver.method == "static"


def test_importing_shellsim_loads_no_compiled_code():
    """``import shellsim`` is light: numba and the kernels come with the first use."""
    probe = "import sys, shellsim; print('numba' in sys.modules, 'shellsim.api' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["False", "False"]
