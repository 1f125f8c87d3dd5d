"""3 x 3 algebra for the compiled kernels: scalar loops, no allocation, one point at a
time (numba)."""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy")
def det3(A):
    """Determinant of A (3, 3)."""
    return (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
            - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
            + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))


@njit(cache=True, error_model="numpy")
def congruence(a, m, b, out):
    """out = a m b^T, all (3, 3); out must be none of the inputs. With a = b = q it turns
    a global tensor into the frame q (rows: its axes), with q.T back."""
    for i in range(3):
        r0 = a[i, 0] * m[0, 0] + a[i, 1] * m[1, 0] + a[i, 2] * m[2, 0]
        r1 = a[i, 0] * m[0, 1] + a[i, 1] * m[1, 1] + a[i, 2] * m[2, 1]
        r2 = a[i, 0] * m[0, 2] + a[i, 1] * m[1, 2] + a[i, 2] * m[2, 2]
        for j in range(3):
            out[i, j] = r0 * b[j, 0] + r1 * b[j, 1] + r2 * b[j, 2]
