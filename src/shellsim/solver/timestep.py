"""Critical time step from the largest natural frequency (thesis 3.16).

lambda_max of M^-1/2 K_L M^-1/2 on the free DOFs by Lanczos (ARPACK through scipy), with
the stiffness applied matrix-free (:func:`shellsim.element.assembly.stiffness_product`)
and warm-started from the previous estimate's eigenvector. The Ritz value approaches
lambda_max from below, so its residual norm is added: lambda_max <= theta + |r|.
Then dt_critical = 2 / omega_max (Eq 3.43 divides it by the safety factor).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, LinearOperator, eigsh
from threadpoolctl import threadpool_limits

from ..errors import NumericalError

# BLAS serves only the Lanczos vector operations here, too small to share out; OpenBLAS'
# threads (numpy's and scipy's, both loaded by now) kept spinning after each call and
# took the second core from the element loop (Scordelis-Lo 16 x 16 on two threads: 7.6
# us per element-step with them, 4.9 without).
threadpool_limits(limits=1, user_api="blas")


#: Lanczos basis size. Warm-started from the last estimate's eigenvector, the estimate
#: converges within its first basis, so ARPACK's default of 20 vectors spends three times
#: the stiffness products (measured: 7 against 21 per estimate, the same bound to 3e-5).
LANCZOS_VECTORS = 6
#: Relative tolerance of the Ritz value, and the coarse one taken when it has not been met
#: within PRODUCTS stiffness products, so that an estimate's cost stays bounded at any
#: mesh size. Cold estimates measured: 37 products on a 10,000-element plate, 43 on a
#: 931-element tube, up to 196 for the shipped decks (Scordelis-Lo), 565 on a uniform
#: 32 x 32 plate (a cluster at the top of the spectrum; now 300 + 22); warm ones 7.
TOLERANCE, COARSE_TOLERANCE, PRODUCTS = 1e-4, 1e-2, 300


class _OverBudget(Exception):
    """The Lanczos iteration used its PRODUCTS."""


def largest_eigenvalue(sim, start: np.ndarray | None = None,
                       on_product: Callable[[int], None] | None = None) -> tuple[float, np.ndarray]:
    """Upper estimate of lambda_max = omega_max^2 at the simulation's current state, and the
    eigenvector (for the next warm start). ``sim``: a :class:`Simulation`; ``on_product``
    is told the count of stiffness products so far (progress on a large mesh).

    Raises NumericalError when the masses or the stiffness are degenerate."""
    m, s = sim.model, sim.state
    n = m.n_nodes
    _check_masses(s.mt, s.mr)
    inv_sqrt_t = 1.0 / np.sqrt(s.mt)
    inv_sqrt_r = 1.0 / np.sqrt(s.mr)
    fu, fr = np.empty((n, 3)), np.empty((n, 2))
    projector, rot_free = m.constraints.projector, m.constraints.rot_free
    space = sim.workspace

    budget = PRODUCTS  # products left to the first Lanczos run; None: not counted
    products = 0

    def apply(z: np.ndarray) -> np.ndarray:
        nonlocal budget, products
        products += 1
        if on_product is not None:
            on_product(products)
        if budget is not None:
            budget -= 1
            if budget < 0:
                raise _OverBudget
        z = np.asarray(z).ravel()
        vu = np.einsum("nij,nj->ni", projector, z[: 3 * n].reshape(n, 3) * inv_sqrt_t[:, None])
        vr = z[3 * n:].reshape(n, 2) * inv_sqrt_r[:, None] * rot_free
        sim.compiled.stiffness(m, s.fields.shape, s.stress, vu, vr, fu, fr, space.parts)
        out_u = np.einsum("nij,nj->ni", projector, fu) * inv_sqrt_t[:, None]
        out_r = fr * rot_free * inv_sqrt_r[:, None]
        return np.concatenate([out_u.ravel(), out_r.ravel()])

    size = 5 * n
    operator = LinearOperator((size, size), matvec=apply, dtype=float)
    v0 = start if start is not None else np.random.default_rng(0).standard_normal(size)
    ncv = min(LANCZOS_VECTORS, size)
    try:
        try:
            values, vectors = eigsh(operator, k=1, which="LA", v0=v0, ncv=ncv, tol=TOLERANCE, maxiter=10 * PRODUCTS)
        except (_OverBudget, ArpackNoConvergence):
            # a cluster at the top of the spectrum (a uniform mesh) is slow to resolve; the
            # coarse tolerance ends within about 25 products and errs on the safe side (a
            # larger bound, a smaller step)
            budget = None
            values, vectors = eigsh(operator, k=1, which="LA", v0=v0, ncv=ncv, tol=COARSE_TOLERANCE,
                                    maxiter=10 * PRODUCTS)
    except (ArpackError, ArpackNoConvergence) as error:
        raise NumericalError(_degenerate(s, f"the Lanczos iteration failed ({error})")) from None
    budget = None
    theta, vector = float(values[0]), vectors[:, 0]
    residual = np.linalg.norm(apply(vector) - theta * vector)
    if not (np.isfinite(theta + residual) and theta > 0):
        raise NumericalError(_degenerate(s, f"its largest eigenvalue came out as {theta + residual:.3g}"))
    return theta + residual, vector


def _check_masses(mt: np.ndarray, mr: np.ndarray) -> None:
    """Lumped masses (n,) must be positive numbers for M^-1/2 K M^-1/2 to mean anything."""
    bad = np.flatnonzero(~((0.0 < mt) & (mt < np.inf) & (0.0 < mr) & (mr < np.inf)))  # NaN fails too
    if bad.size:
        raise NumericalError(
            f"the lumped masses of {bad.size} nodes (first, counting from 1: {(bad[:5] + 1).tolist()}) are not "
            "positive finite numbers, so no critical time step exists: an element around them has "
            "folded over or has no volume, or the density or thickness is out of scale")


def _degenerate(state, what: str) -> str:
    """Why the critical step could not be found, for a message."""
    return (f"the critical time step could not be estimated at t = {state.t:.6g}: {what}. The model's "
            "stiffness and mass are degenerate: check the magnitudes of material.E, material.density, "
            "section.thickness and the geometry against each other (their units), and the mesh")


def critical_time_step(sim, start: np.ndarray | None = None,
                       on_product: Callable[[int], None] | None = None) -> tuple[float, np.ndarray]:
    """(dt_critical = 2 / omega_max, eigenvector) at the current state."""
    lam, vector = largest_eigenvalue(sim, start, on_product)
    return 2.0 / np.sqrt(lam), vector
