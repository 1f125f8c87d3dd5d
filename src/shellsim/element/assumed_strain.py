"""Assumed membrane and transverse shear strains of an element group, and their adjoints
(the effective stresses they put at the tying points); the in-plane volumetric projection
of plane strain. Arrays carry the group's lanes last (G); ``points`` and ``scratch`` are
the group's :class:`shellsim.element.work_arrays.Points` and ``Scratch``.

Assumed membrane strain against membrane locking (a curved quadratic element cannot bend
without stretching by O(theta^2), which full integration samples): the covariant
membrane strains c_ab = g_a . eps . g_b, averaged through the thickness, are tied at
points where that spurious stretch vanishes, each component on its own set (rr: 2 x 3,
ss: 3 x 2, rs: 2 x 2, as in Huang and Hinton's and Bathe's MITC9 9-node shells; one
shared 2 x 2 set would leave three zero-energy membrane modes):

    c*_ab(p, t) = c_ab(p, t) - cbar_ab(p) + sum_m tie_ab(p, m) cbar_ab(m),

and the change goes back into the lamina strains through the contravariant basis. The
bending part (the deviation through the thickness) stays at the point. The transverse
shears are tied too (against shear locking of thin, distorted elements), layer by layer:
gamma_r on the rr points, gamma_s on the ss points. Constant strain on straight-edged
elements and rigid motion are reproduced exactly; the virtual work of sigma . delta eps*
puts effective stresses at the tying points too.

Points: rows 0..nq-1 of the rule are the 3 x 3 Gauss points, the rest the tying points;
tie (3, nq, m) and tie_points (3, m) give, for rr, ss and rs, the interpolation weights
at each Gauss point and the tying points they refer to.
"""

from __future__ import annotations

from numba import njit

from ..tensor3 import to_global, to_lamina
from ..lanes import LANES


@njit(cache=True, error_model="numpy", inline="always")
def _contravariant_tensor(c, jinv, out):
    """Global tensors out (3, 3, G) = sum_ab g^a (x) g^b c_ab (ordered pairs, c_rs counted
    twice), c (3, G), with the contravariant vectors g^a = jinv[a] (rows of the inverse
    Jacobians (3, 3, G))."""
    for i in range(3):
        for j in range(3):
            for lane in range(LANES):
                out[i, j, lane] = (c[0, lane] * jinv[0, i, lane] * jinv[0, j, lane]
                                   + c[1, lane] * jinv[1, i, lane] * jinv[1, j, lane]
                                   + c[2, lane] * (jinv[0, i, lane] * jinv[1, j, lane]
                                                   + jinv[1, i, lane] * jinv[0, j, lane]))


@njit(cache=True, error_model="numpy", inline="always")
def _solve2(a00, a01, a10, a11, b0, b1, out0, out1):
    """(out0, out1) = A^-1 (b0, b1) for A = [[a00, a01], [a10, a11]], all (G,)."""
    for lane in range(LANES):
        det = a00[lane] * a11[lane] - a01[lane] * a10[lane]
        out0[lane] = (a11[lane] * b0[lane] - a01[lane] * b1[lane]) / det
        out1[lane] = (a00[lane] * b1[lane] - a10[lane] * b0[lane]) / det


@njit(cache=True, error_model="numpy", inline="always")
def tie_membrane(rule, points, scratch, nq, nt):
    """Replace the membrane part of the lamina strains points.EPS at the Gauss points by
    its tied interpolation (the through-thickness means weighted by rule.share)."""
    tie, tie_points, share = rule.tie, rule.tie_points, rule.share
    EPS, Q, G, cbar = points.EPS, points.Q, points.G, points.cbar
    plane, glob, local, delta = scratch.plane, scratch.glob, scratch.local, scratch.delta
    # covariant membrane strains c_ab = g_a . eps . g_b (frame-free) and their
    # through-thickness means cbar at every point
    cbar[:] = 0.0
    plane[:] = 0.0
    for x in range(EPS.shape[0]):
        for k in range(nt):
            e5, g = EPS[x, k], G[x, k]
            for lane in range(LANES):
                plane[0, 0, lane] = e5[0, lane]
                plane[1, 1, lane] = e5[1, lane]
                plane[0, 1, lane] = plane[1, 0, lane] = 0.5 * e5[2, lane]
            to_global(Q[x, k], plane, glob)
            for c, (a, b) in enumerate(((0, 0), (1, 1), (0, 1))):
                for lane in range(LANES):
                    acc = 0.0
                    for i in range(3):
                        for j in range(3):
                            acc += g[a, i, lane] * glob[i, j, lane] * g[b, j, lane]
                    cbar[x, c, lane] += share[k] * acc
    for p in range(nq):
        for c in range(3):
            for lane in range(LANES):
                delta[c, lane] = -cbar[p, c, lane]
            for m in range(tie.shape[2]):
                if tie[c, p, m] != 0.0:
                    for lane in range(LANES):
                        delta[c, lane] += tie[c, p, m] * cbar[tie_points[c, m], c, lane]
        for k in range(nt):
            _contravariant_tensor(delta, points.jinv_all[p, k], glob)
            to_lamina(Q[p, k], glob, local)
            for lane in range(LANES):
                EPS[p, k, 0, lane] += local[0, 0, lane]
                EPS[p, k, 1, lane] += local[1, 1, lane]
                EPS[p, k, 2, lane] += 2.0 * local[0, 1, lane]


@njit(cache=True, error_model="numpy", inline="always")
def tie_shear(rule, points, scratch, nq, nt):
    """Replace the transverse shears of points.EPS at the Gauss points by their tied
    interpolation: the covariant shears gamma_a = g_a . gamma (gamma = (2e13, 2e23) in
    the lamina plane), gamma_r on the rr points and gamma_s on the ss points (MITC9).
    Keeps the tangents' lamina components points.A (npts, nt, 2, 2, G) for the adjoint."""
    tie, tie_points = rule.tie, rule.tie_points
    EPS, Q, G, A, cov_shear, delta = points.EPS, points.Q, points.G, points.A, points.cov_shear, scratch.delta
    for x in range(EPS.shape[0]):
        for k in range(nt):
            q, g, lam = Q[x, k], G[x, k], A[x, k]
            for a in range(2):
                for i in range(2):
                    for lane in range(LANES):
                        lam[a, i, lane] = q[i, 0, lane] * g[a, 0, lane] + q[i, 1, lane] * g[a, 1, lane] + q[i, 2, lane] * g[a, 2, lane]
            for c in range(2):
                for lane in range(LANES):
                    cov_shear[x, k, c, lane] = lam[c, 0, lane] * EPS[x, k, 3, lane] + lam[c, 1, lane] * EPS[x, k, 4, lane]
    for p in range(nq):
        for k in range(nt):
            for c in range(2):
                for lane in range(LANES):
                    delta[c, lane] = 0.0
                for m in range(tie.shape[2]):
                    if tie[c, p, m] != 0.0:
                        for lane in range(LANES):
                            delta[c, lane] += tie[c, p, m] * cov_shear[tie_points[c, m], k, c, lane]
            lam = A[p, k]
            _solve2(lam[0, 0], lam[0, 1], lam[1, 0], lam[1, 1], delta[0], delta[1], EPS[p, k, 3], EPS[p, k, 4])


@njit(cache=True, error_model="numpy", inline="always")
def membrane_tying_stresses(rule, points, scratch, nq, nt):
    """The adjoint of :func:`tie_membrane`: the volume-weighted in-plane stresses points.SW
    contracted with the contravariant basis, Bab(p) = sum_k dv g^a . sigma_m . g^b (twice
    for rs), act back through -cbar(p) at the Gauss points and through the tying at the
    tying points; writes their weights points.T (npts, 3, G), each to act as the global
    stress (w_k / W) sum_ab T_ab sym(g_a (x) g_b)."""
    tie, tie_points = rule.tie, rule.tie_points
    SW, Q, Bab, T, plane, glob = points.SW, points.Q, points.Bab, points.T, scratch.plane, scratch.glob
    Bab[:] = 0.0
    plane[:] = 0.0
    for p in range(nq):
        for k in range(nt):
            for lane in range(LANES):
                plane[0, 0, lane] = SW[p, k, 0, lane]
                plane[1, 1, lane] = SW[p, k, 1, lane]
                plane[0, 1, lane] = plane[1, 0, lane] = SW[p, k, 2, lane]
            to_global(Q[p, k], plane, glob)
            jinv = points.jinv_all[p, k]
            for c, (a, b, factor) in enumerate(((0, 0, 1.0), (1, 1, 1.0), (0, 1, 2.0))):
                for lane in range(LANES):
                    acc = 0.0
                    for i in range(3):
                        for j in range(3):
                            acc += jinv[a, i, lane] * glob[i, j, lane] * jinv[b, j, lane]
                    Bab[p, c, lane] += factor * acc
    T[:] = 0.0
    for p in range(nq):
        for c in range(3):
            for lane in range(LANES):
                T[p, c, lane] -= Bab[p, c, lane]
            for m in range(tie.shape[2]):
                if tie[c, p, m] != 0.0:
                    for lane in range(LANES):
                        T[tie_points[c, m], c, lane] += tie[c, p, m] * Bab[p, c, lane]


@njit(cache=True, error_model="numpy", inline="always")
def shear_tying_stresses(rule, points, stress, scratch, nq, nt):
    """The adjoint of :func:`tie_shear`: the shear stresses (in ``stress`` (nq, nt, 5, G))
    work through the tied covariant shears only; tau . A_p^-1 g* at the Gauss points puts
    A_m^T (sum_p tie(p, m) A_p^-T tau_p dv_p) at each tying point m. Writes points.TS
    (npts, nt, 2, G), the covariant factors of those effective shear stresses."""
    tie, tie_points = rule.tie, rule.tie_points
    A, DV, TS, delta, b0, b1 = points.A, points.DV, points.TS, scratch.delta, scratch.cov[0], scratch.cov[1]
    TS[:] = 0.0
    for p in range(nq):
        for k in range(nt):
            for lane in range(LANES):
                b0[lane] = stress[p, k, 3, lane] * DV[p, k, lane]
                b1[lane] = stress[p, k, 4, lane] * DV[p, k, lane]
            lam = A[p, k]
            _solve2(lam[0, 0], lam[1, 0], lam[0, 1], lam[1, 1], b0, b1, delta[0], delta[1])  # A^T
            for c in range(2):
                for m in range(tie.shape[2]):
                    if tie[c, p, m] != 0.0:
                        for lane in range(LANES):
                            TS[tie_points[c, m], k, c, lane] += tie[c, p, m] * delta[c, lane]


@njit(cache=True, error_model="numpy")
def project_volumetric(V, DV, basis, adjoint, count, scratch):
    """In-plane volumetric strain projected, layer by layer, on the fields of ``basis``
    (nq, nb): with (1, r, s) the 9-node quadrilateral becomes Q9/P3, free of volumetric
    locking in plane strain.

    Forward (adjoint=False): V = EPS (npts, nt, 5, G); e_v = e11 + e22 at the Gauss points
    is replaced by its L2 projection e_v* = phi^T Mb^-1 sum_p phi(p) DV(p) e_v(p), the
    change going half into e11 and half into e22 (the deviatoric strain is untouched).
    Adjoint (adjoint=True): V = SW (npts, nt, 3, G), the volume-weighted in-plane
    stresses; with S = (SW_11 + SW_22) / 2 their virtual work through e_v* adds
    DV(q) phi(q)^T Mb^-1 sum_p phi(p) S(p) - S(q) to both normal stresses at each point
    q. DV (npts, nt, G) point volumes; basis (nq, nb); the first ``count`` lanes;
    scratch.Mb (nb, nb) and scratch.rhs (nb,) as scratch."""
    nq, nb, nt = basis.shape[0], basis.shape[1], V.shape[1]
    Mb, rhs = scratch.Mb, scratch.rhs
    for k in range(nt):
        for lane in range(count):
            Mb[:] = 0.0
            for p in range(nq):
                for i in range(nb):
                    for j in range(nb):
                        Mb[i, j] += DV[p, k, lane] * basis[p, i] * basis[p, j]
            rhs[:] = 0.0
            for p in range(nq):
                weight = 0.5 if adjoint else DV[p, k, lane]
                for i in range(nb):
                    rhs[i] += basis[p, i] * weight * (V[p, k, 0, lane] + V[p, k, 1, lane])
            _solve_in_place(Mb, rhs)
            for q in range(nq):
                projected = 0.0
                for i in range(nb):
                    projected += basis[q, i] * rhs[i]
                change = (DV[q, k, lane] if adjoint else 0.5) * projected - 0.5 * (V[q, k, 0, lane] + V[q, k, 1, lane])
                V[q, k, 0, lane] += change
                V[q, k, 1, lane] += change


# in place of np.linalg.solve: LAPACK's binding compiles for seconds on a first run (with a
# shape check whose message formats both shapes), and allocates two arrays per call
@njit(cache=True, error_model="numpy")
def _solve_in_place(M, b):
    """b (n,) = M^-1 b, by Gaussian elimination with partial pivoting (LAPACK's dgesv);
    M (n, n) is overwritten by its factors."""
    n = b.shape[0]
    for j in range(n):
        pivot = j
        for i in range(j + 1, n):
            if abs(M[i, j]) > abs(M[pivot, j]):
                pivot = i
        if pivot != j:
            for k in range(n):
                M[j, k], M[pivot, k] = M[pivot, k], M[j, k]
            b[j], b[pivot] = b[pivot], b[j]
        for i in range(j + 1, n):
            factor = M[i, j] / M[j, j]
            for k in range(j + 1, n):
                M[i, k] -= factor * M[j, k]
            b[i] -= factor * b[j]
    for i in range(n - 1, -1, -1):
        for k in range(i + 1, n):
            b[i] -= M[i, k] * b[k]
        b[i] /= M[i, i]
