"""Lumped nodal masses of the shell (thesis 3.14), element group by group."""

from __future__ import annotations

import numpy as np
from numba import njit

from .kinematics import point_geometry
from ..lanes import LANES
from .groups import gather_shape, group_count, lane_copy


@njit(cache=True, error_model="numpy")
def lumped_masses(rule, body, shape, density, hughes, mt, mr):
    """Lumped nodal masses on the current ``shape`` (thesis 3.14); rule, body: the
    element's :class:`~shellsim.bundles.Rule` and the mesh's :class:`~shellsim.bundles.Body`;
    density (ne,) each element's [mass / length^3].

    hughes=True gives M1 (Hughes et al. 1981): translational masses proportional to
    int N_a^2 rho dV, scaled to the element mass; rotational ones are those times
    max(h_a^2/12, A/8). hughes=False gives M2: row sums of the consistent mass, separately
    for the translational block (int N_a rho dV) and the director block
    (sum_b int rho N_a N_b t^2 h_a h_b / 4 dV, with t^2 taken at its exact mean 1/3 over
    the thickness: the 2- and 3-point rules give that anyway, and the 1-point rule of a
    membrane-only scene would give no rotary inertia at all). Writes mt (n,) and mr (n,).
    """
    conn = body.conn
    N, dNr, dNs, wq, tz, wt = rule.N, rule.dNr, rule.dNs, rule.wq, rule.tz, rule.wt
    mt[:] = 0.0
    mr[:] = 0.0
    members = np.empty(LANES, dtype=np.int64)
    xe, de, he = np.empty((9, 3, LANES)), np.empty((9, 3, LANES)), np.empty((9, LANES))
    jac, jinv, q, det = np.empty((3, 3, LANES)), np.empty((3, 3, LANES)), np.empty((3, 3, LANES)), np.empty(LANES)
    raw, rot, volume = np.empty((9, LANES)), np.empty((9, LANES)), np.empty(LANES)
    raw1, rot1, he1 = np.empty(9), np.empty(9), np.empty(9)
    for group in range(group_count(conn.shape[0])):
        count = gather_shape(group, conn, (shape.x, shape.d, shape.h), members, (xe, de, he))
        raw[:] = 0.0
        rot[:] = 0.0
        volume[:] = 0.0
        for p in range(wq.shape[0]):
            for k in range(tz.shape[0]):
                point_geometry((xe, de, he), (N[p], dNr[p], dNs[p]), tz[k], (jac, jinv, q, det))
                for lane in range(LANES):
                    dv = det[lane] * wq[p] * wt[k]
                    volume[lane] += dv
                    if hughes:
                        for a in range(9):
                            raw[a, lane] += N[p, a] * N[p, a] * density[members[lane]] * dv
                    else:
                        hbar = 0.0
                        for b in range(9):
                            hbar += N[p, b] * he[b, lane]
                        for a in range(9):
                            raw[a, lane] += N[p, a] * density[members[lane]] * dv
                            rot[a, lane] += N[p, a] * density[members[lane]] * dv * he[a, lane] * hbar / 12.0
        for lane in range(count):
            lane_copy(raw, lane, raw1)
            lane_copy(rot, lane, rot1)
            lane_copy(he, lane, he1)
            if hughes:
                total = raw1.sum()
                area = volume[lane] / he1.mean()
                for a in range(9):
                    m = density[members[lane]] * volume[lane] * raw1[a] / total
                    rot1[a] = m * max(he1[a] * he1[a] / 12.0, area / 8.0)
                    raw1[a] = m
            e = members[lane]
            for a in range(9):
                mt[conn[e, a]] += raw1[a]
                mr[conn[e, a]] += rot1[a]
