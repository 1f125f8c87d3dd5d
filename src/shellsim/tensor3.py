"""3 x 3 algebra over an element group's lanes: every array (3, 3, G) holds one matrix per
lane, G = :data:`shellsim.lanes.LANES` the last axis, so each line is a packed
loop over the lanes. The helpers are inlined into their callers (a call's argument
passing would cost as much as the arithmetic); none allocates, and an ``out`` must be
none of the inputs."""

from __future__ import annotations

from numba import njit

from .lanes import LANES


@njit(cache=True, error_model="numpy", inline="always")
def det3(A, out):
    """out (G,) = det A, A (3, 3, G)."""
    for lane in range(LANES):
        out[lane] = (A[0, 0, lane] * (A[1, 1, lane] * A[2, 2, lane] - A[1, 2, lane] * A[2, 1, lane])
                     - A[0, 1, lane] * (A[1, 0, lane] * A[2, 2, lane] - A[1, 2, lane] * A[2, 0, lane])
                     + A[0, 2, lane] * (A[1, 0, lane] * A[2, 1, lane] - A[1, 1, lane] * A[2, 0, lane]))


@njit(cache=True, error_model="numpy", inline="always")
def product(A, B, out):
    """out = A B, all (3, 3, G); out must be neither input."""
    # summed in a register, not in out: a sum held in memory is stored and loaded again
    # at every term, as out might be an input for all the compiled code can tell
    for i in range(3):
        for j in range(3):
            for lane in range(LANES):
                acc = 0.0
                for m in range(3):
                    acc += A[i, m, lane] * B[m, j, lane]
                out[i, j, lane] = acc


@njit(cache=True, error_model="numpy", inline="always")
def congruence(a, m, b, out):
    """out = a m b^T, all (3, 3, G)."""
    for i in range(3):
        for lane in range(LANES):
            r0 = a[i, 0, lane] * m[0, 0, lane] + a[i, 1, lane] * m[1, 0, lane] + a[i, 2, lane] * m[2, 0, lane]
            r1 = a[i, 0, lane] * m[0, 1, lane] + a[i, 1, lane] * m[1, 1, lane] + a[i, 2, lane] * m[2, 1, lane]
            r2 = a[i, 0, lane] * m[0, 2, lane] + a[i, 1, lane] * m[1, 2, lane] + a[i, 2, lane] * m[2, 2, lane]
            for j in range(3):
                out[i, j, lane] = r0 * b[j, 0, lane] + r1 * b[j, 1, lane] + r2 * b[j, 2, lane]


@njit(cache=True, error_model="numpy", inline="always")
def to_lamina(q, A, out):
    """out = q A q^T, all (3, 3, G): a global tensor's lamina components."""
    congruence(q, A, q, out)


@njit(cache=True, error_model="numpy", inline="always")
def to_global(q, A, out):
    """out = q^T A q, all (3, 3, G): a lamina tensor in global axes."""
    for i in range(3):
        for lane in range(LANES):
            r0 = q[0, i, lane] * A[0, 0, lane] + q[1, i, lane] * A[1, 0, lane] + q[2, i, lane] * A[2, 0, lane]
            r1 = q[0, i, lane] * A[0, 1, lane] + q[1, i, lane] * A[1, 1, lane] + q[2, i, lane] * A[2, 1, lane]
            r2 = q[0, i, lane] * A[0, 2, lane] + q[1, i, lane] * A[1, 2, lane] + q[2, i, lane] * A[2, 2, lane]
            for j in range(3):
                out[i, j, lane] = r0 * q[0, j, lane] + r1 * q[1, j, lane] + r2 * q[2, j, lane]
