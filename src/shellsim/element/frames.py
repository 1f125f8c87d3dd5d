"""Lamina and fibre coordinate systems and the director update (thesis 2.5.1.2, 3.2, 3.3).

All functions are compiled with numba and work on one node (the lamina frame of the
integration points is :func:`shellsim.element.kinematics.lamina_frame`).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, inline="always")
def cross(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """The components of a x b, a and b (3,) (rows of nodal arrays too: nothing is
    allocated)."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def normalize(a: np.ndarray) -> None:
    """Scale a (3,) to unit length in place."""
    n = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    a[0] /= n
    a[1] /= n
    a[2] /= n


@njit(cache=True, error_model="numpy")
def initial_fibre_frame(d: np.ndarray, e1: np.ndarray) -> None:
    """Hughes' fibre basis for a director d (3,): writes e1f into e1 (3,); e2f = d x e1f.

    Steps 1-7 of thesis 2.5.1.2.3: the global axis least aligned with the director is
    crossed with it, so a director near e3 gets e1f, e2f near e1, e2.
    """
    b1, b2, b3 = abs(d[0]), abs(d[1]), abs(d[2])
    j = 0
    if b1 > b3:
        b3 = b1
        j = 1
    if b2 > b3:
        j = 2
    axis = np.zeros(3)
    axis[j] = 1.0
    e2 = np.empty(3)
    e2[0], e2[1], e2[2] = cross(d, axis)
    normalize(e2)
    e1[0], e1[1], e1[2] = cross(e2, d)


@njit(cache=True, error_model="numpy")
def update_fibre_frame(d: np.ndarray, e1: np.ndarray) -> None:
    """The thesis' new fibre-frame update (3.3.2): e2f = d x e1f(previous), e1f = e2f x d.

    Crossing with the previous step's e1f instead of a fixed global axis keeps the frame's
    sense through any rotation (bending past 90 degrees no longer flips it). e1 (3,) is
    updated in place. Scalars only: it runs at every node of every step.
    """
    e2x, e2y, e2z = cross(d, e1)
    n = np.sqrt(e2x * e2x + e2y * e2y + e2z * e2z)
    e1[0], e1[1], e1[2] = cross((e2x / n, e2y / n, e2z / n), d)


@njit(cache=True, error_model="numpy")
def rotate_director(d: np.ndarray, e1: np.ndarray, dtheta1: float, dtheta2: float) -> None:
    """Director update by trial increment and normalisation (thesis 3.2, Eq 2.62):
    d <- (d - dtheta1 e1f - dtheta2 e2f) / |...|, e2f = d x e1f, then the fibre frame
    follows. In place."""
    e2x, e2y, e2z = cross(d, e1)
    d[0] -= dtheta1 * e1[0] + dtheta2 * e2x
    d[1] -= dtheta1 * e1[1] + dtheta2 * e2y
    d[2] -= dtheta1 * e1[2] + dtheta2 * e2z
    normalize(d)
    update_fibre_frame(d, e1)


@njit(cache=True, error_model="numpy")
def rotate_directors(d, e1, nodes, dtheta):
    """:func:`rotate_director` at each of ``nodes`` (k,) by the increments dtheta (k, 2);
    d, e1 (n, 3) in place."""
    for k in range(nodes.shape[0]):
        rotate_director(d[nodes[k]], e1[nodes[k]], dtheta[k, 0], dtheta[k, 1])


@njit(cache=True, parallel=True, error_model="numpy")
def to_rotational(g, d, e1, out):
    """Rotational DOF forces (n, 2) from director-conjugate forces g (n, 3):
    (-e1f.g, -e2f.g), e2f = d x e1f; node by node over the threads."""
    for n in prange(g.shape[0]):
        rotational_at(n, g, d, e1, out)


@njit(cache=True, error_model="numpy", inline="always")
def rotational_at(n, g, d, e1, out):
    """:func:`to_rotational` at node n."""
    e2x, e2y, e2z = cross(d[n], e1[n])
    out[n, 0] = -(e1[n, 0] * g[n, 0] + e1[n, 1] * g[n, 1] + e1[n, 2] * g[n, 2])
    out[n, 1] = -(e2x * g[n, 0] + e2y * g[n, 1] + e2z * g[n, 2])


@njit(cache=True, error_model="numpy")
def director_increments(w, d, e1, out):
    """Director increments (n, 3) of rotational DOF values w (n, 2): -w1 e1f - w2 e2f."""
    for n in range(w.shape[0]):
        e2x, e2y, e2z = cross(d[n], e1[n])
        out[n, 0] = -w[n, 0] * e1[n, 0] - w[n, 1] * e2x
        out[n, 1] = -w[n, 0] * e1[n, 1] - w[n, 1] * e2y
        out[n, 2] = -w[n, 0] * e1[n, 2] - w[n, 1] * e2z
