"""The 9-node (biquadratic Lagrange) reference quadrilateral of the thesis, Table 2.1.

Node order (thesis numbering k = index + 1) and natural coordinates (r, s)::

      2 ---- 5 ---- 1        s
      |             |        ^
      6      9      8        |
      |             |        +--> r
      3 ---- 7 ---- 4

node 1 (+1,+1), 2 (-1,+1), 3 (-1,-1), 4 (+1,-1), 5 (0,+1), 6 (-1,0), 7 (0,-1), 8 (+1,0),
9 (0,0). The functions are the tensor products of the 1D quadratic Lagrange polynomials on
{-1, 0, +1}, identical to Bathe's variable-number-node functions of Table 2.1 with all nine
nodes present (a test checks that against the table as printed).

gmsh's 9-node quadrangle (type 10) and VTK's biquadratic quad use the same node sequence
with reference coordinates (u, v) = (-r, -s); see :mod:`shellsim.geometry.gmsh_extract`.
"""

from __future__ import annotations

import numpy as np

#: Natural coordinates (r, s) of the nine nodes, thesis order. Shape (9, 2).
NODE_RS = np.array(
    [[1, 1], [-1, 1], [-1, -1], [1, -1], [0, 1], [-1, 0], [0, -1], [1, 0], [0, 0]], dtype=float
)

#: Node indices as the nodes lie: rows from s = +1 down to s = -1, columns from r = -1 to
#: +1 (the grid lines neighbouring nodes share). Shape (3, 3).
GRID = np.array([[1, 4, 0], [5, 8, 7], [2, 6, 3]])

#: Node indices of the three nodes of each element edge, in the order
#: (corner, mid-side, corner), walking the boundary counter-clockwise in (r, s).
EDGES = np.array([[0, 4, 1], [1, 5, 2], [2, 6, 3], [3, 7, 0]])


def _lagrange_1d(x: np.ndarray, node: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadratic Lagrange polynomial on {-1, 0, 1} that is 1 at ``node``, and its derivative.

    Shapes: x (n, 1), node (1, 9) -> value (n, 9), derivative (n, 9).
    """
    value = np.where(node == 0, 1 - x**2, 0.5 * x * (x + node))
    slope = np.where(node == 0, -2 * x, x + 0.5 * node)
    return value, slope


def shape(rs: np.ndarray) -> np.ndarray:
    """Shape functions N_a at points ``rs``.

    Parameters
    ----------
    rs : (n, 2) float — natural coordinates (r, s).

    Returns
    -------
    (n, 9) float
    """
    rs = np.atleast_2d(np.asarray(rs, dtype=float))
    lr, _ = _lagrange_1d(rs[:, :1], NODE_RS[None, :, 0])
    ls, _ = _lagrange_1d(rs[:, 1:], NODE_RS[None, :, 1])
    return lr * ls


def shape_derivatives(rs: np.ndarray) -> np.ndarray:
    """Derivatives dN_a/dr and dN_a/ds at points ``rs``.

    Parameters
    ----------
    rs : (n, 2) float

    Returns
    -------
    (n, 9, 2) float — last axis (d/dr, d/ds).
    """
    rs = np.atleast_2d(np.asarray(rs, dtype=float))
    lr, dlr = _lagrange_1d(rs[:, :1], NODE_RS[None, :, 0])
    ls, dls = _lagrange_1d(rs[:, 1:], NODE_RS[None, :, 1])
    return np.stack([dlr * ls, lr * dls], axis=-1)


def gauss_rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [-1, 1]: shapes (n,), (n,)."""
    return np.polynomial.legendre.leggauss(n)


def gauss_rule_2d(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor-product Gauss rule on the reference square.

    Returns
    -------
    rs : (n*n, 2) float — points, r varying fastest.
    w : (n*n,) float — weights, summing to 4.
    """
    x, w = gauss_rule(n)
    r, s = np.meshgrid(x, x, indexing="xy")
    wr, ws = np.meshgrid(w, w, indexing="xy")
    return np.column_stack([r.ravel(), s.ravel()]), (wr * ws).ravel()


#: 3-point Gauss rule along an element edge and the 1D quadratic shape functions at its
#: points, for (corner, mid-side, corner) node triples.
EDGE_XI = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
EDGE_W = np.array([5.0, 8.0, 5.0]) / 9.0
EDGE_N = np.stack([EDGE_XI * (EDGE_XI - 1) / 2, 1 - EDGE_XI**2, EDGE_XI * (EDGE_XI + 1) / 2], axis=1)
EDGE_DN = np.stack([EDGE_XI - 0.5, -2 * EDGE_XI, EDGE_XI + 0.5], axis=1)
