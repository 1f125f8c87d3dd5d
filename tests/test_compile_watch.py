"""What numba compiles is told as it happens: the outermost compilations only (the kernels
they call compile inside them), each with its name and duration."""

from __future__ import annotations

import pytest
from numba import njit
from typer.testing import CliRunner

from shellsim.compile_watch import watching_compiles

from .conftest import CLAMPED_PLATE, deck_text


def test_each_outermost_compilation_is_told_once_with_its_name_and_duration():
    @njit
    def inner(x):
        return 2.0 * x

    @njit
    def outer(x):
        return inner(x) + 1.0

    started, ended = [], []
    with watching_compiles(started.append, lambda name, seconds: ended.append((name, seconds))):
        assert outer(1.0) == 3.0
        assert outer(2.0) == 5.0  # compiled already: nothing told
    name = "tests.test_compile_watch.test_each_outermost_compilation_is_told_once_with_its_name_and_duration.<locals>.outer"
    assert started == [name]
    assert [n for n, _ in ended] == [name] and ended[0][1] > 0.0
    outer(3)  # a new signature, outside the block: nobody told
    assert len(started) == 1


def test_the_run_progress_tells_the_compiling_once_and_each_long_kernel():
    """Off a terminal, lines: the first compilation says the kernels compile once and
    about how long; kernels over 5 s are named with their time. On a terminal the bar names
    the kernel compiling and goes back to the step's figures after."""
    import io

    from rich.console import Console

    from shellsim.output.progress import ProgressDisplay

    text = io.StringIO()
    lines = ProgressDisplay(Console(file=text, width=200, force_terminal=False), end_time=1.0)
    lines.compiling("solver.explicit.forces")
    lines.compiled("solver.explicit.forces", 128.4)
    lines.compiling("element.groups.group_count")
    lines.compiled("element.groups.group_count", 0.3)
    out = text.getvalue().splitlines()
    assert len(out) == 2
    assert out[0].startswith("compiling the kernels (once for this version of shellsim")
    assert out[1] == "compiled solver.explicit.forces in 128 s"

    bar = ProgressDisplay(Console(file=io.StringIO(), width=120, force_terminal=True), end_time=1.0)
    try:
        before = bar.bar.tasks[0].fields["status"]
        bar.compiling("solver.explicit.advance")
        fields = bar.bar.tasks[0].fields
        assert fields["status"] == "compiling solver.explicit.advance" and fields["compiling_since"] is not None
        bar.compiled("solver.explicit.advance", 11.0)
        fields = bar.bar.tasks[0].fields
        assert fields["status"] == before and fields["compiling_since"] is None
    finally:
        bar.close()


def test_the_time_left_follows_the_step_and_a_newton_path_gets_a_range():
    """Explicit: the steps still to go at the current step, each at the recent wall time
    per step; the step halving doubles the time left at once. Newton steps: the
    simulated time still to go at the middle half of the recent rates."""
    from shellsim.output.progress import Pace, left_text

    pace = Pace()
    assert pace.left(1.0, 1e-3) is None and left_text(None) == "-"
    for k in range(5):  # 100 steps of 1e-3 a wall second
        pace.add(0.1 * k, 100 * k, now=float(k))
    soonest, latest = pace.left(1.0, 1e-3)
    assert soonest == latest == pytest.approx(600 * 0.01)  # 600 steps at 10 ms
    assert pace.left(1.0, 0.5e-3)[0] == pytest.approx(1200 * 0.01)
    assert left_text((12.0, 12.0)) == "about 0:12 left"

    newton = Pace()
    for wall, t in [(0.0, 0.0), (1.0, 0.1), (3.0, 0.2), (4.0, 0.3), (8.0, 0.4)]:  # 10, 20, 10, 40 s per unit
        newton.add(t, 0, now=wall)
    soonest, latest = newton.left(1.0, None)
    assert soonest == pytest.approx(0.6 * 10.0) and latest == pytest.approx(0.6 * 25.0)
    assert left_text((soonest, latest)) == "0:06-0:15 left"
    assert left_text((3725.0, 3725.0)) == "about 1:02:05 left"


def test_a_static_solve_shows_its_own_columns(tmp_path):
    """A static run's progress lines name its load steps, iterations and tangents, never
    an explicit step's rate or balance; the closing lines say where to look."""
    from shellsim.cli import app

    deck = tmp_path / "static.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', CLAMPED_PLATE[1]).replace(
        "[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0\n[output]\ninterval = 0.25').replace(
        "thickness = 0.01", "thickness = 0.1"))
    result = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("t = ")]
    assert len(lines) >= 4 and all("load step" in line and "iterations" in line and "steps/s" not in line
                                   and "balance" not in line for line in lines)
    unwrapped = "".join(result.output.split())  # a narrow console folds the long path anywhere
    assert "paraview" in unwrapped and "results.xdmf" in unwrapped
