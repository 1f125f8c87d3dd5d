"""Dead nodal forces and moments (edge, point, body and dead pressure loads, tabulated
by :func:`shellsim.model.build_model`), scaled by their curves, compiled."""

from __future__ import annotations

from numba import njit

from ..curve_tables import factor


@njit(cache=True)
def add_dead_forces(t, curves, forces, f):
    """f (n, 3) += sum_k curve_k(t) forces.vectors[k] (:class:`shellsim.bundles.NodalLoads`)."""
    for k in range(forces.curve.shape[0]):
        c = factor(curves, forces.curve[k], t)
        for node in range(f.shape[0]):
            for i in range(3):
                f[node, i] += c * forces.vectors[k, node, i]


@njit(cache=True)
def add_dead_moments(t, curves, moments, d, g):
    """g (n, 3) += the director-conjugate forces M x d of the moments M(t) of ``moments``
    (:class:`shellsim.bundles.NodalLoads`): a moment M turns the director d (n, 3) by M x d."""
    for k in range(moments.curve.shape[0]):
        c = factor(curves, moments.curve[k], t)
        for node in range(g.shape[0]):
            mx, my, mz = c * moments.vectors[k, node, 0], c * moments.vectors[k, node, 1], c * moments.vectors[k, node, 2]
            g[node, 0] += my * d[node, 2] - mz * d[node, 1]
            g[node, 1] += mz * d[node, 0] - mx * d[node, 2]
            g[node, 2] += mx * d[node, 1] - my * d[node, 0]
