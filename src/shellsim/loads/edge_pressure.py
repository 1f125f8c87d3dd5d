"""Pressure on the shell's edge faces, compiled, and the edge quadrature it shares with
the dead edge loads."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..element.frames import cross

#: 3-point Gauss rule along an element edge and the 1D quadratic shape functions at its
#: points, for (corner, mid-side, corner) node triples.
EDGE_XI = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
EDGE_W = np.array([5.0, 8.0, 5.0]) / 9.0
EDGE_N = np.stack([EDGE_XI * (EDGE_XI - 1) / 2, 1 - EDGE_XI**2, EDGE_XI * (EDGE_XI + 1) / 2], axis=1)
EDGE_DN = np.stack([EDGE_XI - 0.5, -2 * EDGE_XI, EDGE_XI + 0.5], axis=1)


@njit(cache=True)
def edge_pressure_forces(shape, loads, scale, f):
    """Pressure ``scale`` (E,) [force/length^2] on the edge faces of ``loads``
    (:class:`shellsim.bundles.EdgePressureLoads`): a force per unit edge length of p times
    the fibre length, normal to the edge within the shell, pushing in. Adds to f (n, 3);
    shape: the current :class:`~shellsim.bundles.Shape`."""
    x, d, h = shape.x, shape.d, shape.h
    tan = np.empty(3)
    nrm = np.empty(3)
    out = np.empty(3)
    for m in range(loads.edges.shape[0]):
        for p in range(3):
            tan[:] = 0.0
            nrm[:] = 0.0
            thick = 0.0
            for k in range(3):
                node = loads.edges[m, k]
                thick += EDGE_N[p, k] * h[node]
                for i in range(3):
                    tan[i] += EDGE_DN[p, k] * x[node, i]
                    nrm[i] += EDGE_N[p, k] * d[node, i]
            nrm /= np.sqrt(nrm @ nrm)
            out[0], out[1], out[2] = cross(tan, nrm)
            for k in range(3):
                node = loads.edges[m, k]
                w = -loads.outward[m] * scale[m] * thick * EDGE_N[p, k] * EDGE_W[p]
                for i in range(3):
                    f[node, i] += w * out[i]
