"""The hostile sweep: 16 numeric fields of a shipped deck, each given one of 11 bad or
extreme values (176 decks). ``shellsim check`` must end each with exit code 0 (a valid
scene) or 2 (a message), never a traceback, a crash or a hang.

Run as a script (``python tests/test_deck_sweep.py``) it checks every case in its own
process with a time limit and prints what each ended with, so a crash or a hang shows too.
"""

from __future__ import annotations

import copy
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BASE_DECK = ROOT / "decks" / "bench" / "plate_step.toml"

FIELDS = [
    "material.E", "material.nu", "material.density", "section.thickness", "geometry.length", "geometry.width",
    "mesh.divisions.length", "mesh.divisions.width", "solver.end_time", "solver.dt_safety_factor",
    "load.0.value", "output.interval", "boundary.0.director_plane_normal.1", "reference.0.expected",
    "reference.0.tolerance_percent", "output.probe.0.component",
]
VALUES = {
    "nan": math.nan, "inf": math.inf, "-inf": -math.inf, "negative": -1.0, "zero": 0.0, "1e300": 1e300,
    "1e-300": 1e-300, "string": "12", "boolean": True, "list": [1.0, 2.0], "table": {"a": 1.0},
}
CASES = [(f, v) for f in FIELDS for v in VALUES]
#: A case checked in its own process must end within this [s] (meshing and the estimate of a
#: 2 x 2 plate take under 5 s once the kernels are compiled).
TIME_LIMIT = 120


def sweep_deck(folder: Path, field: str, value_name: str) -> Path:
    """The base deck with ``field`` (a dotted path; numbers index arrays of tables) set to
    the value named ``value_name``, written into ``folder``."""
    import tomli_w

    deck = tomllib.loads(BASE_DECK.read_text())
    *parents, last = field.split(".")
    table = deck
    for key in parents:
        table = table[int(key)] if key.isdigit() else table[key]
    value = copy.deepcopy(VALUES[value_name])
    if last.isdigit():
        table[int(last)] = value
    else:
        table[last] = value
    path = folder / f"{field.replace('.', '_')}-{value_name}.toml"
    path.write_text(tomli_w.dumps(deck))
    return path


@pytest.mark.parametrize(("field", "value_name"), CASES, ids=[f"{f}={v}" for f, v in CASES])
def test_check_ends_with_a_valid_scene_or_a_message(tmp_path, field, value_name):
    from typer.testing import CliRunner

    from shellsim.cli import app

    result = CliRunner().invoke(app, ["check", str(sweep_deck(tmp_path, field, value_name))])
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.exit_code in (0, 2), result.output
    assert "Traceback" not in result.output
    if result.exit_code == 2:
        assert result.output.lstrip().startswith("error:") or "\nerror:" in result.output, result.output


def main(folder: Path) -> int:
    """Every case in its own ``shellsim check`` process; prints one line each and returns
    the number of cases that did not end with 0 or 2 within TIME_LIMIT."""
    bad = 0
    for field, value_name in CASES:
        deck = sweep_deck(folder, field, value_name)
        try:
            done = subprocess.run([sys.executable, "-m", "shellsim", "check", str(deck)], capture_output=True,
                                  text=True, timeout=TIME_LIMIT)
            code, said = done.returncode, (done.stdout + done.stderr)
        except subprocess.TimeoutExpired:
            code, said = "timeout", ""
        error = [line for line in said.splitlines() if line.startswith("error:") or line.startswith("  - ")]
        fine = code in (0, 2) and "Traceback" not in said
        bad += not fine
        print(f"{'ok ' if fine else 'BAD'} {field}={value_name}: exit {code}; {' '.join(error)[:160]}", flush=True)
    print(f"{len(CASES) - bad} of {len(CASES)} cases ended with exit code 0 or 2 and no traceback")
    return bad


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as scratch:
        sys.exit(1 if main(Path(scratch)) else 0)
