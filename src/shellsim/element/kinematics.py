"""Point kinematics of an element group: geometry, strains, and the stress's way back to
nodal forces (thesis 3.3-3.6), every array with the group's lanes last (G, see
:mod:`shellsim.lanes`).

Kinematics (thesis Eq 3.3): y(r, s, t) = sum_a N_a (x_a + t h_a/2 d_a), with mid-surface
nodes x_a, unit directors d_a and fibre lengths h_a. A director moves by
delta d_a = -theta1 e1f_a - theta2 e2f_a (thesis Eq 2.62), so each node has 5 DOF.

Strain-displacement, done once and consistently instead of copying Eqs 3.18-3.19 (whose
rotation columns swap e1f and e2f between the two equations): at a point, a virtual
field changes the displacement gradient by

    delta L = sum_a delta u_a (x) gN_a + delta d_a (x) gM_a,
    gN_a = J^-T (dN_a/dr, dN_a/ds, 0),  gM_a = h_a/2 J^-T (t dN_a/dr, t dN_a/ds, N_a),

J = dy/d(r, s, t) the current Jacobian (columns). The lamina strains of Eq 3.20 are the
components of sym(q delta L q^T), q the lamina frame; the thesis' B~_L^l is exactly this
map. So B^T sigma needs no B: with sigma_g = q^T sigma^l q (global Cauchy stress),
f_a = sigma_g gN_a dv (translations) and g_a = sigma_g gM_a dv (conjugate to the
director), whose rotational components are -e1f.g_a and -e2f.g_a.

The helpers are inlined into their callers (numba IR inlining): called once per point
and layer, a call's argument passing would cost as much as the arithmetic.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..tensor3 import det3
from ..lanes import LANES



@njit(cache=True, error_model="numpy", inline="always")
def fibre_point(x, d, h, t):
    """The point at thickness coordinate t in [-1, 1] on the fibre of a node at x with
    director d and fibre length h: x + t h/2 d (thesis Eq 3.3 at one node). Scalars or
    broadcasting arrays, in compiled code or from Python."""
    return x + t * 0.5 * h * d


@njit(cache=True, error_model="numpy", inline="always")
def lamina_frame(jac, q):
    """Hughes' lamina basis from the tangents g_r = jac[:, 0], g_s = jac[:, 1] (3, 3, G).

    e3 is the lamina normal; e1, e2 lie in the lamina, symmetric about the bisector of
    e_r and e_s (thesis Eq 2.57 and Figure 2.11). Writes q (3, 3, G) with rows e1, e2, e3
    (the global -> lamina rotation [q]).
    """
    c = np.sqrt(0.5)
    for lane in range(LANES):
        nr = np.sqrt(jac[0, 0, lane] ** 2 + jac[1, 0, lane] ** 2 + jac[2, 0, lane] ** 2)
        ns = np.sqrt(jac[0, 1, lane] ** 2 + jac[1, 1, lane] ** 2 + jac[2, 1, lane] ** 2)
        rx, ry, rz = jac[0, 0, lane] / nr, jac[1, 0, lane] / nr, jac[2, 0, lane] / nr
        sx, sy, sz = jac[0, 1, lane] / ns, jac[1, 1, lane] / ns, jac[2, 1, lane] / ns
        nx, ny, nz = ry * sz - rz * sy, rz * sx - rx * sz, rx * sy - ry * sx
        n = np.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / n, ny / n, nz / n
        ax, ay, az = rx + sx, ry + sy, rz + sz
        a = np.sqrt(ax * ax + ay * ay + az * az)
        ax, ay, az = ax / a, ay / a, az / a
        bx, by, bz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax
        b = np.sqrt(bx * bx + by * by + bz * bz)
        bx, by, bz = bx / b, by / b, bz / b
        q[0, 0, lane], q[0, 1, lane], q[0, 2, lane] = c * (ax - bx), c * (ay - by), c * (az - bz)
        q[1, 0, lane], q[1, 1, lane], q[1, 2, lane] = c * (ax + bx), c * (ay + by), c * (az + bz)
        q[2, 0, lane], q[2, 1, lane], q[2, 2, lane] = nx, ny, nz


@njit(cache=True, error_model="numpy", inline="always")
def point_geometry(element, functions, t, out):
    """Current Jacobian, its determinant and inverse, and the lamina frame at one point.

    element = (xe, de, he): positions and directors (9, 3, G), fibre lengths (9, G);
    functions = (N, dNr, dNs) (9,) at the point; t the thickness coordinate. Writes
    out = (jac, jinv, q) (3, 3, G) and det (G,).
    """
    xe, de, he = element
    N, dNr, dNs = functions
    jac, jinv, q, det = out
    for i in range(3):
        for lane in range(LANES):
            # summed in registers (see tensor3.product), node by node
            r, s, n = 0.0, 0.0, 0.0
            for a in range(9):
                half = 0.5 * he[a, lane]
                pos = xe[a, i, lane] + t * half * de[a, i, lane]
                r += dNr[a] * pos
                s += dNs[a] * pos
                n += N[a] * half * de[a, i, lane]
            jac[i, 0, lane], jac[i, 1, lane], jac[i, 2, lane] = r, s, n
    det3(jac, det)
    for lane in range(LANES):
        d = det[lane]
        jinv[0, 0, lane] = (jac[1, 1, lane] * jac[2, 2, lane] - jac[1, 2, lane] * jac[2, 1, lane]) / d
        jinv[0, 1, lane] = (jac[0, 2, lane] * jac[2, 1, lane] - jac[0, 1, lane] * jac[2, 2, lane]) / d
        jinv[0, 2, lane] = (jac[0, 1, lane] * jac[1, 2, lane] - jac[0, 2, lane] * jac[1, 1, lane]) / d
        jinv[1, 0, lane] = (jac[1, 2, lane] * jac[2, 0, lane] - jac[1, 0, lane] * jac[2, 2, lane]) / d
        jinv[1, 1, lane] = (jac[0, 0, lane] * jac[2, 2, lane] - jac[0, 2, lane] * jac[2, 0, lane]) / d
        jinv[1, 2, lane] = (jac[0, 2, lane] * jac[1, 0, lane] - jac[0, 0, lane] * jac[1, 2, lane]) / d
        jinv[2, 0, lane] = (jac[1, 0, lane] * jac[2, 1, lane] - jac[1, 1, lane] * jac[2, 0, lane]) / d
        jinv[2, 1, lane] = (jac[0, 1, lane] * jac[2, 0, lane] - jac[0, 0, lane] * jac[2, 1, lane]) / d
        jinv[2, 2, lane] = (jac[0, 0, lane] * jac[1, 1, lane] - jac[0, 1, lane] * jac[1, 0, lane]) / d
    lamina_frame(jac, q)


@njit(cache=True, error_model="numpy", inline="always")
def gradient_vectors(jinv, he, N, dNr, dNs, t, gN, gM):
    """gN, gM (9, 3, G) at one point from its inverse Jacobian jinv (3, 3, G) (module
    docstring); he (9, G), N, dNr, dNs (9,), t as :func:`point_geometry`."""
    for a in range(9):
        for j in range(3):
            for lane in range(LANES):
                g = jinv[0, j, lane] * dNr[a] + jinv[1, j, lane] * dNs[a]
                gN[a, j, lane] = g
                gM[a, j, lane] = 0.5 * he[a, lane] * (t * g + jinv[2, j, lane] * N[a])



@njit(cache=True, error_model="numpy", inline="always")
def almansi(F, eg, B, det):
    """Almansi strain eg = 1/2 (I - (F F^T)^-1) of deformation gradients F (3, 3, G);
    B (3, 3, G), det (G,) scratch. A degenerate F gives non-finite values (no
    exception), which the time loop detects."""
    for i in range(3):
        for j in range(i, 3):
            for lane in range(LANES):
                B[i, j, lane] = F[i, 0, lane] * F[j, 0, lane] + F[i, 1, lane] * F[j, 1, lane] + F[i, 2, lane] * F[j, 2, lane]
                B[j, i, lane] = B[i, j, lane]
    det3(B, det)
    for lane in range(LANES):
        d = det[lane]
        eg[0, 0, lane] = 0.5 - 0.5 * (B[1, 1, lane] * B[2, 2, lane] - B[1, 2, lane] * B[2, 1, lane]) / d
        eg[1, 1, lane] = 0.5 - 0.5 * (B[0, 0, lane] * B[2, 2, lane] - B[0, 2, lane] * B[2, 0, lane]) / d
        eg[2, 2, lane] = 0.5 - 0.5 * (B[0, 0, lane] * B[1, 1, lane] - B[0, 1, lane] * B[1, 0, lane]) / d
        eg[0, 1, lane] = eg[1, 0, lane] = -0.5 * (B[0, 2, lane] * B[2, 1, lane] - B[0, 1, lane] * B[2, 2, lane]) / d
        eg[0, 2, lane] = eg[2, 0, lane] = -0.5 * (B[0, 1, lane] * B[1, 2, lane] - B[0, 2, lane] * B[1, 1, lane]) / d
        eg[1, 2, lane] = eg[2, 1, lane] = -0.5 * (B[0, 2, lane] * B[1, 0, lane] - B[0, 0, lane] * B[1, 2, lane]) / d


@njit(cache=True, error_model="numpy", inline="always")
def field_gradient(ue, ve, gN, gM, L):
    """L (3, 3, G) = sum_a ue[a] (x) gN[a] + ve[a] (x) gM[a]; ue, ve, gN, gM (9, 3, G)."""
    for i in range(3):
        for j in range(3):
            for lane in range(LANES):
                acc = 0.0  # in a register, as tensor3.product sums
                for a in range(9):
                    acc += ue[a, i, lane] * gN[a, j, lane] + ve[a, i, lane] * gM[a, j, lane]
                L[i, j, lane] = acc


@njit(cache=True, error_model="numpy", inline="always")
def symmetric_part(L, out):
    """out = (L + L^T) / 2, both (3, 3, G)."""
    for i in range(3):
        for j in range(3):
            for lane in range(LANES):
                out[i, j, lane] = 0.5 * (L[i, j, lane] + L[j, i, lane])




@njit(cache=True, error_model="numpy", inline="always")
def lamina_strain(eg, q, e5, v):
    """Lamina strain vectors e5 (5, G) = (e11, e22, 2e12, 2e13, 2e23) of q eg q^T, eg
    (3, 3, G) symmetric; v (3, 3, G) scratch."""
    # rows of eg q^T, i.e. (eg q_a) for lamina axes a = 0, 1, 2
    for a in range(3):
        for i in range(3):
            for lane in range(LANES):
                v[a, i, lane] = (eg[i, 0, lane] * q[a, 0, lane] + eg[i, 1, lane] * q[a, 1, lane]
                                 + eg[i, 2, lane] * q[a, 2, lane])
    for lane in range(LANES):
        e5[0, lane] = q[0, 0, lane] * v[0, 0, lane] + q[0, 1, lane] * v[0, 1, lane] + q[0, 2, lane] * v[0, 2, lane]
        e5[1, lane] = q[1, 0, lane] * v[1, 0, lane] + q[1, 1, lane] * v[1, 1, lane] + q[1, 2, lane] * v[1, 2, lane]
        e5[2, lane] = 2.0 * (q[0, 0, lane] * v[1, 0, lane] + q[0, 1, lane] * v[1, 1, lane] + q[0, 2, lane] * v[1, 2, lane])
        e5[3, lane] = 2.0 * (q[0, 0, lane] * v[2, 0, lane] + q[0, 1, lane] * v[2, 1, lane] + q[0, 2, lane] * v[2, 2, lane])
        e5[4, lane] = 2.0 * (q[1, 0, lane] * v[2, 0, lane] + q[1, 1, lane] * v[2, 1, lane] + q[1, 2, lane] * v[2, 2, lane])


@njit(cache=True, error_model="numpy", inline="always")
def global_stress(s5, q, sg):
    """Global stresses sg (3, 3, G) = q^T sigma^l q from lamina stresses s5 (5, G)
    = (s11, s22, s12, s13, s23), s33 = 0."""
    for i in range(3):
        for lane in range(LANES):
            # row i of q^T sigma^l: sum_k q[k, i] sigma^l[k, :]
            t0 = q[0, i, lane] * s5[0, lane] + q[1, i, lane] * s5[2, lane] + q[2, i, lane] * s5[3, lane]
            t1 = q[0, i, lane] * s5[2, lane] + q[1, i, lane] * s5[1, lane] + q[2, i, lane] * s5[4, lane]
            t2 = q[0, i, lane] * s5[3, lane] + q[1, i, lane] * s5[4, lane]
            for j in range(3):
                sg[i, j, lane] = t0 * q[0, j, lane] + t1 * q[1, j, lane] + t2 * q[2, j, lane]


@njit(cache=True, error_model="numpy", inline="always")
def add_forces(sg, gN, gM, dv, fe, ge):
    """fe[a] += sg gN[a] dv, ge[a] += sg gM[a] dv for the 9 nodes: sg (3, 3, G), gN, gM,
    fe, ge (9, 3, G), dv (G,) point volumes."""
    for a in range(9):
        for i in range(3):
            for lane in range(LANES):
                fe[a, i, lane] += (sg[i, 0, lane] * gN[a, 0, lane] + sg[i, 1, lane] * gN[a, 1, lane]
                                   + sg[i, 2, lane] * gN[a, 2, lane]) * dv[lane]
                ge[a, i, lane] += (sg[i, 0, lane] * gM[a, 0, lane] + sg[i, 1, lane] * gM[a, 1, lane]
                                   + sg[i, 2, lane] * gM[a, 2, lane]) * dv[lane]
