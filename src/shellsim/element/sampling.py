"""Reading the element's integration-point results: which point is nearest to a location,
and the stress and strain tensors at every point (for probes and output frames)."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..tensor3 import product, to_global
from .kinematics import global_stress, point_geometry
from ..lanes import LANES
from .groups import gather_element_values, gather_shape, group_count, lane_copy


def integration_points(x: np.ndarray, conn: np.ndarray, N_gauss: np.ndarray) -> np.ndarray:
    """(ne, nq, 3) the mid-surface places of the in-plane integration points of the
    elements ``conn`` (ne, 9), for nodes at x (n, 3); N_gauss (nq, 9)."""
    return np.einsum("qa,eai->eqi", N_gauss, x[conn])


def nearest_integration_point(x0: np.ndarray, conn: np.ndarray, N_gauss: np.ndarray,
                              location: np.ndarray) -> tuple[int, int]:
    """(element, in-plane point) of the mid-surface integration point nearest to
    ``location`` (3,) in the initial configuration; x0 (n, 3), conn (ne, 9), N_gauss (nq, 9)."""
    points = integration_points(x0, conn, N_gauss)
    flat = int(np.argmin(np.linalg.norm(points - location, axis=2)))
    return divmod(flat, len(N_gauss))


def thickness_mean(values: np.ndarray, wt: np.ndarray, axis: int) -> np.ndarray:
    """The weighted mean of point ``values`` over the thickness layers on ``axis``, with the
    thickness rule's weights ``wt`` (nt,); that axis is removed."""
    return np.tensordot(wt / wt.sum(), values, axes=([0], [axis]))


def pressure_band(sigma: np.ndarray) -> np.ndarray:
    """-trace(sigma) / 3 of each (..., 3, 3) stress: the thesis' pressure band."""
    return -np.trace(sigma, axis1=-2, axis2=-1) / 3.0


@njit(cache=True, error_model="numpy")
def point_tensors(nodes, conn, points, jac0_inv, stress, out):
    """Tensors at every integration point (element e, in-plane point q, layer k).

    Inputs: nodes = (x, d, h), the current mid-surface and directors (n, 3) and fibre
    lengths (n,); conn (ne, 9); points = (N, dNr, dNs, tz): shape functions at the
    in-plane points (nq, 9) and the layer coordinates (nt,); jac0_inv (ne, >= nq, nt, 3,
    3): inverse initial Jacobians; stress (ne, nq, nt, 5): lamina stresses (s11, s22, s12,
    s13, s23).

    Writes out = (lamina, cauchy, green), each (ne, nq, nt, 3, 3): ``lamina``, the stress in the lamina frame (s33 = 0);
    ``cauchy``, the same turned to global axes (q^T lamina q, q the current lamina frame);
    ``green``, the Green-Lagrange strain (F^T F - I) / 2 in global axes with
    F = dx/d(r, s, t) (dX/d(r, s, t))^-1.
    """
    N, dNr, dNs, tz = points
    lamina, cauchy, green = out
    members = np.empty(LANES, dtype=np.int64)
    xe, de, he = np.empty((9, 3, LANES)), np.empty((9, 3, LANES)), np.empty((9, LANES))
    jac0 = np.empty(jac0_inv.shape[1:] + (LANES,))
    jac, jinv, q, det = np.empty((3, 3, LANES)), np.empty((3, 3, LANES)), np.empty((3, 3, LANES)), np.empty(LANES)
    s5, sg, F, FtF = np.empty((5, LANES)), np.empty((3, 3, LANES)), np.empty((3, 3, LANES)), np.empty((3, 3, LANES))
    same = np.zeros((3, 3, LANES))
    for i in range(3):
        same[i, i, :] = 1.0  # the lamina frame is its own; also the identity
    for group in range(group_count(conn.shape[0])):
        count = gather_shape(group, conn, nodes, members, (xe, de, he))
        gather_element_values(jac0_inv, members, jac0)
        for p in range(N.shape[0]):
            for k in range(tz.shape[0]):
                point_geometry((xe, de, he), (N[p], dNr[p], dNs[p]), tz[k], (jac, jinv, q, det))
                for i in range(5):
                    for lane in range(LANES):
                        s5[i, lane] = stress[members[lane], p, k, i]
                global_stress(s5, same, sg)
                for lane in range(count):
                    lane_copy(sg, lane, lamina[members[lane], p, k])
                global_stress(s5, q, sg)
                for lane in range(count):
                    lane_copy(sg, lane, cauchy[members[lane], p, k])
                product(jac, jac0[p, k], F)
                to_global(F, same, FtF)  # F^T F
                for i in range(3):
                    for j in range(3):
                        for lane in range(count):
                            green[members[lane], p, k, i, j] = 0.5 * (FtF[i, j, lane] - same[i, j, lane])
