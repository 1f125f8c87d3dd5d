"""The search of shell contact (:mod:`shellsim.loads.shell_contact`), compiled: which face
a node may touch (each face's box and a bucket grid of the boxes) and the nearest point
of a 9-node face's quadratic mid-surface to a point (Newton on the natural coordinates).

Broad phase: each face's box is the box of its nine nodes grown by the reach of the
contact (the thickness offsets); the grid's cells are as wide as the widest box, so a
box covers at most 2 x 2 x 2 cells and a node only reads the faces listed in its own
cell. Cells are hashed into a table of twice as many buckets as faces and the lists are
made by a counting sort, so the grid costs O(faces) a call and allocates nothing.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Natural coordinates of the nine nodes (thesis order, :mod:`shellsim.element.shape`);
#: tuples, which compiled code takes as constants (a global array would keep a parallel
#: caller out of the cache).
_NODE_R = (1.0, -1.0, -1.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0)
_NODE_S = (1.0, 1.0, -1.0, -1.0, 1.0, 0.0, -1.0, 0.0, 0.0)
#: Newton iterations of the nearest point, the step (natural units) it stops at, and the
#: halvings of a step that would move away.
_ITERATIONS, _CONVERGED, _HALVINGS = 30, 1e-12, 40


@njit(cache=True, inline="always")
def _lagrange(x, node):
    """The 1D quadratic Lagrange polynomial on {-1, 0, 1} that is 1 at ``node``: its
    value, first and second derivatives at x."""
    if node == 0.0:
        return 1.0 - x * x, -2.0 * x, -2.0
    return 0.5 * x * (x + node), x + 0.5 * node, 1.0


@njit(cache=True)
def face_functions(r, s, N, dN):
    """The nine shape functions at (r, s) into N (9,), and their derivatives d/dr, d/ds,
    d2/dr2, d2/ds2, d2/drds into dN (5, 9)."""
    for a in range(9):
        lr, dr, ddr = _lagrange(r, _NODE_R[a])
        ls, ds, dds = _lagrange(s, _NODE_S[a])
        N[a] = lr * ls
        dN[0, a] = dr * ls
        dN[1, a] = lr * ds
        dN[2, a] = ddr * ls
        dN[3, a] = lr * dds
        dN[4, a] = dr * ds


@njit(cache=True)
def projection_scratch():
    """The scratch of :func:`nearest_point`: N (9,), dN (5, 9) and the surface's
    derivatives (5, 3)."""
    return np.empty(9), np.empty((5, 9)), np.empty((5, 3))


@njit(cache=True)
def _surface(x, nodes, r, s, point, scratch):
    """The face's point (3,) at (r, s), with the shape functions and the point's
    derivatives into the scratch (N, dN, derivatives) (:func:`projection_scratch`)."""
    N, dN, derivatives = scratch
    face_functions(r, s, N, dN)
    for i in range(3):
        # the sums held in registers, node by node in order as before (summed in the arrays,
        # a face's evaluation took 155 ns against 103: the same bits, one and a half times as long)
        p, pr, ps, prr, pss, prs = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        for a in range(9):
            value = x[nodes[a], i]
            p += N[a] * value
            pr += dN[0, a] * value
            ps += dN[1, a] * value
            prr += dN[2, a] * value
            pss += dN[3, a] * value
            prs += dN[4, a] * value
        point[i] = p
        derivatives[0, i], derivatives[1, i], derivatives[2, i] = pr, ps, prr
        derivatives[3, i], derivatives[4, i] = pss, prs


@njit(cache=True)
def nearest_point(x, nodes, y, rs, point, normal, scratch):
    """The point of the face (the biquadratic surface through x[nodes], nodes (9,)) nearest
    to y (3,): its natural coordinates into rs (2,), in [-1, 1]^2, the point into
    ``point`` (3,) and the unit vector from it to y into ``normal`` (3,) (the face's
    normal where y is on the face); the shape functions there are left in scratch[0]
    (:func:`projection_scratch`). Projected Newton on 1/2 |y - p(r, s)|^2 from the face's
    centre, each step halved until the distance does not grow; a coordinate on its bound
    is held there while the gradient pushes it out. Returns the distance |y - p|."""
    r = 0.0
    s = 0.0
    derivatives = scratch[2]
    _surface(x, nodes, r, s, point, scratch)
    squared = (y[0] - point[0]) ** 2 + (y[1] - point[1]) ** 2 + (y[2] - point[2]) ** 2
    for _ in range(_ITERATIONS):
        e0, e1, e2 = y[0] - point[0], y[1] - point[1], y[2] - point[2]
        pr, ps, prr, pss, prs = derivatives
        gr = -(e0 * pr[0] + e1 * pr[1] + e2 * pr[2])
        gs = -(e0 * ps[0] + e1 * ps[1] + e2 * ps[2])
        metric_r = pr[0] * pr[0] + pr[1] * pr[1] + pr[2] * pr[2]
        metric_s = ps[0] * ps[0] + ps[1] * ps[1] + ps[2] * ps[2]
        hrr = metric_r - (e0 * prr[0] + e1 * prr[1] + e2 * prr[2])
        hss = metric_s - (e0 * pss[0] + e1 * pss[1] + e2 * pss[2])
        hrs = pr[0] * ps[0] + pr[1] * ps[1] + pr[2] * ps[2] - (e0 * prs[0] + e1 * prs[1] + e2 * prs[2])
        r_held = (r >= 1.0 and gr < 0.0) or (r <= -1.0 and gr > 0.0)
        s_held = (s >= 1.0 and gs < 0.0) or (s <= -1.0 and gs > 0.0)
        det = hrr * hss - hrs * hrs
        if r_held or s_held or det <= 0.0 or hrr <= 0.0:
            # on a bound, or where the surface curves away faster than the point is far
            # (no minimum of the quadratic model): Newton along each free coordinate alone,
            # Gauss-Newton where even that has none
            dr = 0.0 if r_held else -gr / (hrr if hrr > 0.0 else metric_r)
            ds = 0.0 if s_held else -gs / (hss if hss > 0.0 else metric_s)
        else:
            dr = -(hss * gr - hrs * gs) / det
            ds = -(hrr * gs - hrs * gr) / det
        if abs(min(1.0, max(-1.0, r + dr)) - r) + abs(min(1.0, max(-1.0, s + ds)) - s) < _CONVERGED:
            # converged: the point, its derivatives and shape functions are those at (r, s)
            # (evaluating the step's end first made 3.1 evaluations of a face a projection
            # on two stacked plates, against 1.9, for a distance that moved by 3e-16 of itself)
            break
        step = 1.0
        for _ in range(_HALVINGS):  # halved until the distance does not grow
            r_new = min(1.0, max(-1.0, r + step * dr))
            s_new = min(1.0, max(-1.0, s + step * ds))
            _surface(x, nodes, r_new, s_new, point, scratch)
            trial = (y[0] - point[0]) ** 2 + (y[1] - point[1]) ** 2 + (y[2] - point[2]) ** 2
            if trial <= squared:
                break
            step *= 0.5
        moved = abs(r_new - r) + abs(s_new - s)
        r, s, squared = r_new, s_new, trial
        if moved < _CONVERGED:
            break
    rs[0], rs[1] = r, s
    for i in range(3):
        normal[i] = y[i] - point[i]
    distance = np.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
    size = distance
    if distance == 0.0:  # on the face: its normal
        pr, ps = derivatives[0], derivatives[1]
        normal[0] = pr[1] * ps[2] - pr[2] * ps[1]
        normal[1] = pr[2] * ps[0] - pr[0] * ps[2]
        normal[2] = pr[0] * ps[1] - pr[1] * ps[0]
        size = np.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
    for i in range(3):
        normal[i] /= size
    return distance


@njit(cache=True, inline="always")
def _bucket(i, j, k, buckets):
    """The hash bucket of grid cell (i, j, k) among ``buckets``."""
    key = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791)
    return key % buckets if key >= 0 else (-key) % buckets


#: The three nodes of each line of constant s (r = -1, 0, 1) and of constant r (s = -1,
#: 0, 1) of the face, whose second differences bound how far it bulges past its nodes.
_LINES = ((1, 4, 0), (5, 8, 7), (2, 6, 3), (2, 5, 1), (6, 8, 4), (3, 7, 0))


@njit(cache=True)
def face_boxes(x, faces, boxes):
    """boxes (F, 6): the lower and upper corners of each face (F, 9) (its nodes' numbers
    in x (n, 3)), filled in place. A box holds its face: its nodes' box grown by as far as
    a biquadratic face bulges past them (along each line of nodes, a quadratic overshoots
    them by at most an eighth of its second difference; across the lines, by 1.25 times
    that of the lines' values)."""
    for f in range(faces.shape[0]):
        for i in range(3):
            low, high = np.inf, -np.inf
            for a in range(9):
                value = x[faces[f, a], i]
                low = min(low, value)
                high = max(high, value)
            along, across = 0.0, 0.0
            for line in range(6):
                ends, middle = _LINES[line], _LINES[line][1]
                second = abs(x[faces[f, ends[0]], i] + x[faces[f, ends[2]], i] - 2.0 * x[faces[f, middle], i])
                if line < 3:
                    along = max(along, second)
                else:
                    across = max(across, second)
            bulge = 0.125 * along + 0.15625 * across
            boxes[f, i] = low - bulge
            boxes[f, 3 + i] = high + bulge


@njit(cache=True)
def fill_grid(reach, grid):
    """The bucket grid of F boxes: grid = (boxes (F, 6) lower and upper corners, start
    (B + 1,) each bucket's first entry, entries (8 F,) box rows by bucket), start and
    entries filled in place. The cells are as wide as the widest box grown by reach (F,)
    on every side, so a grown box covers at most 2 x 2 x 2 cells and is listed in each.
    Returns the cell width and the grid's origin corner (3,)."""
    boxes, start, entries = grid
    n_faces = boxes.shape[0]
    origin = np.full(3, np.inf)
    width = 0.0
    for f in range(n_faces):
        for i in range(3):
            width = max(width, boxes[f, 3 + i] - boxes[f, i] + 2.0 * reach[f])
            origin[i] = min(origin[i], boxes[f, i] - reach[f])
    width = max(width, 1e-300)
    buckets = start.shape[0] - 1
    start[:] = 0
    lo = np.empty(3, dtype=np.int64)
    hi = np.empty(3, dtype=np.int64)
    for placing in (False, True):  # count each bucket's faces, then place them
        if placing:  # start[b]: the end of bucket b's entries, then their start as they fill
            for b in range(1, buckets):
                start[b] += start[b - 1]
            start[buckets] = start[buckets - 1]
        for f in range(n_faces):
            for i in range(3):
                lo[i] = int(np.floor((boxes[f, i] - reach[f] - origin[i]) / width))
                hi[i] = int(np.floor((boxes[f, 3 + i] + reach[f] - origin[i]) / width))
            for ci in range(lo[0], hi[0] + 1):
                for cj in range(lo[1], hi[1] + 1):
                    for ck in range(lo[2], hi[2] + 1):
                        b = _bucket(ci, cj, ck, buckets)
                        if placing:
                            start[b] -= 1
                            entries[start[b]] = f
                        else:
                            start[b] += 1
    return width, origin


@njit(cache=True, inline="always")
def cell_faces(y, width, origin, start):
    """The range (first, stop) of the entries of the bucket of the cell holding y (3,)."""
    b = _bucket(int(np.floor((y[0] - origin[0]) / width)), int(np.floor((y[1] - origin[1]) / width)),
                int(np.floor((y[2] - origin[2]) / width)), start.shape[0] - 1)
    return start[b], start[b + 1]


@njit(cache=True, inline="always")
def near_box(y, boxes, f, reach):
    """Whether y (3,) lies within ``reach`` of face row f's box (a lower bound of its
    distance from the face)."""
    squared = 0.0
    for i in range(3):
        below = boxes[f, i] - y[i]
        above = y[i] - boxes[f, 3 + i]
        if below > 0.0:
            squared += below * below
        elif above > 0.0:
            squared += above * above
    return squared <= reach * reach
