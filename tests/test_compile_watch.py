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
