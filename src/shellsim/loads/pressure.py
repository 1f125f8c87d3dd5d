"""Follower pressure on element faces (thesis 3.12.1), compiled."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..element.frames import cross
from ..element.kinematics import fibre_point


@njit(cache=True)
def pressure_forces(rule, conn, shape, faces, scale, f, g):
    """Adds the forces of pressures ``scale`` (P,) [force/length^2] on ``faces``
    (:class:`shellsim.bundles.PressureLoads`) to f and g (n, 3).

    face -1 bottom (t = -1), 0 mid-surface, +1 top. Positive pushes into the shell, i.e.
    along +n on the bottom face and the mid-surface and along -n on the top face,
    n = g_r x g_s / |.| (the directors' side). Forces act where the face is, so the
    director-conjugate part g carries their lever arm. rule: the element's
    :class:`~shellsim.bundles.Rule`; conn (ne, 9); shape: the current
    :class:`~shellsim.bundles.Shape`.
    """
    x, d, h = shape.x, shape.d, shape.h
    N, dNr, dNs, wq = rule.N, rule.dNr, rule.dNs, rule.wq
    yr = np.empty(3)
    ys = np.empty(3)
    area = np.empty(3)
    for m in range(faces.elements.shape[0]):
        e = faces.elements[m]
        t = float(faces.face[m])
        sign = -1.0 if faces.face[m] > 0 else 1.0
        for p in range(wq.shape[0]):
            yr[:] = 0.0
            ys[:] = 0.0
            for a in range(9):
                node = conn[e, a]
                for i in range(3):
                    pos = fibre_point(x[node, i], d[node, i], h[node], t)
                    yr[i] += dNr[p, a] * pos
                    ys[i] += dNs[p, a] * pos
            area[0], area[1], area[2] = cross(yr, ys)
            for a in range(9):
                node = conn[e, a]
                w = sign * scale[m] * N[p, a] * wq[p]
                for i in range(3):
                    f[node, i] += w * area[i]
                    g[node, i] += w * area[i] * t * 0.5 * h[node]
