"""Reading the element's integration-point results at a place: which point is nearest to
a location, and its Cauchy stress in global axes."""

from __future__ import annotations

import numpy as np

from .frames import lamina_frame


def nearest_integration_point(x0: np.ndarray, conn: np.ndarray, N_gauss: np.ndarray,
                              location: np.ndarray) -> tuple[int, int]:
    """(element, in-plane point) of the mid-surface integration point nearest to
    ``location`` (3,) in the initial configuration; x0 (n, 3), conn (ne, 9), N_gauss (nq, 9)."""
    points = np.einsum("qa,eai->eqi", N_gauss, x0[conn])
    flat = int(np.argmin(np.linalg.norm(points - location, axis=2)))
    return divmod(flat, len(N_gauss))


def global_stress(x: np.ndarray, d: np.ndarray, h: np.ndarray, nodes: np.ndarray, N: np.ndarray,
                  dNr: np.ndarray, dNs: np.ndarray, tz: np.ndarray, wt: np.ndarray,
                  stress: np.ndarray) -> np.ndarray:
    """Thickness mean of the Cauchy stress (3, 3), global axes, at one in-plane point.

    x, d (n, 3), h (n,): current configuration; nodes (9,): the element's nodes; N, dNr,
    dNs (9,): shape functions at the point; tz, wt (nt,): thickness rule; stress (nt, 5):
    the point's lamina stresses (s11, s22, s12, s13, s23), turned by each layer's lamina
    frame q into q^T sigma q.
    """
    xe, fe = x[nodes], 0.5 * h[nodes, None] * d[nodes]
    jac, q = np.empty((3, 3)), np.empty((3, 3))
    out = np.zeros((3, 3))
    for k, t in enumerate(tz):
        pos = xe + t * fe
        jac[:, 0], jac[:, 1], jac[:, 2] = dNr @ pos, dNs @ pos, N @ fe
        lamina_frame(jac, q)
        s11, s22, s12, s13, s23 = stress[k]
        local = np.array([[s11, s12, s13], [s12, s22, s23], [s13, s23, 0.0]])
        out += wt[k] * (q.T @ local @ q)
    return out / wt.sum()
