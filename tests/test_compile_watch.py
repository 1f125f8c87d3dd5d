"""What numba compiles is told as it happens: the outermost compilations only (the kernels
they call compile inside them), each with its name and duration."""

from __future__ import annotations

from numba import njit

from shellsim.compile_watch import watching_compiles


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
