"""The fixed-shape view the element kernels take of their work arrays: the same memory and
values, the strides a C-contiguous array of those trailing lengths has, the leading axes
untouched, and an error (not a wrong address) when the lengths or strides differ."""

import numpy as np
import pytest
from numba import njit

from shellsim.element.work_arrays import fixed_lanes, group_arrays
from shellsim.fixed_shape import fixed_trailing
from shellsim.lanes import LANES


@njit(error_model="numpy")
def _view_and_write(a):
    view = fixed_trailing(a, (3, LANES))
    view[1, 2, 5] = -1.0
    return view.shape, view.strides, view.sum()


def test_view_shares_memory_and_keeps_leading_strides():
    base = np.arange(6 * 3 * LANES, dtype=float).reshape(6, 3, LANES)
    every_other = base[::2]  # leading stride twice the C one: it must be kept
    expected_sum = every_other.sum() - every_other[1, 2, 5] - 1.0
    shape, strides, total = _view_and_write(every_other)
    assert shape == every_other.shape
    assert strides == every_other.strides == (2 * 3 * LANES * 8, LANES * 8, 8)
    assert total == expected_sum
    assert base[2, 2, 5] == -1.0  # written through to the array viewed


def test_other_trailing_lengths_raise():
    with pytest.raises(ValueError, match=r"trailing axes are not \(3, 16\)"):
        _view_and_write(np.zeros((2, 3, LANES // 2)))
    with pytest.raises(ValueError, match="trailing axes"):
        _view_and_write(np.zeros((2, 4, LANES)))
    with pytest.raises(ValueError, match="contiguous"):  # the right lengths, spread out
        _view_and_write(np.zeros((2, 3, 2 * LANES))[:, :, ::2])


@njit(error_model="numpy")
def _fixed_shapes(group, points, scratch):
    group, points, scratch = fixed_lanes(group, points, scratch)
    return group.xe.shape, points.Q.shape, points.EPS.shape, scratch.M.shape, scratch.Mb.shape


def test_fixed_lanes_views_every_bundle_at_its_own_shape():
    npts, nt, nq, nb = 25, 2, 9, 3
    group, points, scratch = group_arrays(npts, nt, nq, nb)
    assert _fixed_shapes(group, points, scratch) == (group.xe.shape, points.Q.shape, points.EPS.shape,
                                                     scratch.M.shape, scratch.Mb.shape)
