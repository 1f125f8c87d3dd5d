"""Element groups: group g holds elements g * LANES ... g * LANES + LANES - 1
(:data:`shellsim.lanes.LANES`), gathered into lanes and put back. A group at the end of
the mesh fills its spare lanes with the last element again: computed like the others,
never written back. The element loops group the elements of each part (material) apart
(:func:`part_groups`): a group then holds elements of one part, its spare lanes its last
element again.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..array_copy import copy_into
from ..lanes import LANES


@njit(cache=True)
def group_count(n_elements):
    """Groups covering ``n_elements`` elements."""
    return -(-n_elements // LANES)


@njit(cache=True, error_model="numpy")
def group_members(group, ne, members):
    """Write the group's element numbers into members (G,) (spare lanes repeat element
    ne - 1) and return how many lanes hold elements of their own."""
    start = group * LANES
    for lane in range(LANES):
        members[lane] = min(start + lane, ne - 1)
    return min(LANES, ne - start)


def part_groups(part: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(start (G + 1,), order (ne,), group_part (G,)): groups of at most LANES elements of
    one part each, for each element's ``part`` (ne,); group g holds elements
    order[start[g]:start[g + 1]], in ascending order within each part. One part gives
    the groups of :func:`group_members`."""
    order = np.argsort(part, kind="stable").astype(np.int64)
    starts, parts = [], []
    for p in np.unique(part):
        first, stop = np.searchsorted(part[order], p), np.searchsorted(part[order], p, side="right")
        starts += range(first, stop, LANES)
        parts += [p] * len(range(first, stop, LANES))
    return np.array(starts + [len(part)], dtype=np.int64), order, np.array(parts, dtype=np.int64)


@njit(cache=True, error_model="numpy")
def part_group_members(group, start, order, members):
    """Write the members of group ``group`` of :func:`part_groups` into members (G,)
    (spare lanes repeat its last element) and return how many lanes hold elements of
    their own."""
    first, stop = start[group], start[group + 1]
    for lane in range(LANES):
        members[lane] = order[min(first + lane, stop - 1)]
    return stop - first


@njit(cache=True, error_model="numpy")
def gather_shape(group, conn, nodes, members, element):
    """A group's members (:func:`group_members`) and element = (xe, de, he): their
    positions and directors (9, 3, G) and fibre lengths (9, G) from nodes = (x, d, h),
    the nodal (n, 3), (n, 3) and (n,); returns how many lanes hold elements of their own."""
    count = group_members(group, conn.shape[0], members)
    gather_members_shape(conn, nodes, members, element)
    return count


@njit(cache=True, error_model="numpy", inline="always")
def gather_members_shape(conn, nodes, members, element):
    """element = (xe, de, he) of the elements ``members`` (G,), as :func:`gather_shape`."""
    x, d, h = nodes
    xe, de, he = element
    gather_nodal_vectors(conn, members, x, xe)
    gather_nodal_vectors(conn, members, d, de)
    gather_nodal_scalars(conn, members, h, he)


@njit(cache=True, error_model="numpy")
def gather_nodal_vectors(conn, members, values, out):
    """out (9, 3, G) = the members' nodal values (n, 3), node order of conn (ne, 9)."""
    for a in range(9):
        for i in range(3):
            for lane in range(LANES):
                out[a, i, lane] = values[conn[members[lane], a], i]


@njit(cache=True, error_model="numpy")
def gather_nodal_scalars(conn, members, values, out):
    """out (9, G) = the members' nodal values (n,)."""
    for a in range(9):
        for lane in range(LANES):
            out[a, lane] = values[conn[members[lane], a]]


@njit(cache=True, error_model="numpy")
def gather_element_values(values, members, out):
    """out (..., G) = values (ne, ...) of the members, for any trailing shape (both
    C-contiguous)."""
    rows = values.reshape((values.shape[0], values.size // values.shape[0]))
    lanes = out.reshape((rows.shape[1], LANES))
    for j in range(rows.shape[1]):
        for lane in range(LANES):
            lanes[j, lane] = rows[members[lane], j]


@njit(cache=True, error_model="numpy")
def scatter_element_values(lane_values, members, count, values):
    """values (ne, ...)[member] = lane_values (..., G) of the first ``count`` lanes: the
    inverse of :func:`gather_element_values`."""
    rows = values.reshape((values.shape[0], values.size // values.shape[0]))
    lanes = lane_values.reshape((rows.shape[1], LANES))
    for lane in range(count):
        e = members[lane]
        for j in range(rows.shape[1]):
            rows[e, j] = lanes[j, lane]


@njit(cache=True, error_model="numpy")
def lane_copy(lane_values, lane, out):
    """out (...) = lane ``lane`` of lane_values (..., G)."""
    flat = out.reshape(out.size)
    lanes = lane_values.reshape((out.size, LANES))
    for j in range(out.size):
        flat[j] = lanes[j, lane]


@njit(cache=True, error_model="numpy")
def lane_store(values, lane, lane_values):
    """Lane ``lane`` of lane_values (..., G) = values (...): the inverse of
    :func:`lane_copy`."""
    flat = values.reshape(values.size)
    lanes = lane_values.reshape((values.size, LANES))
    for j in range(values.size):
        lanes[j, lane] = flat[j]


@njit(cache=True)
def gather_nodes(shape, nodes, xe, de, he):
    """The mid-surface points, directors and fibre lengths of an edge's or a face's nodes
    (k,) into xe, de (k, 3) and he (k,)."""
    for a in range(nodes.shape[0]):
        copy_into(shape.x[nodes[a]], xe[a])
        copy_into(shape.d[nodes[a]], de[a])
        he[a] = shape.h[nodes[a]]
