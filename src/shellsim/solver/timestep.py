"""Critical time step from the largest natural frequency (thesis 3.16).

lambda_max of M^-1/2 K_L M^-1/2 on the free DOFs by Lanczos, with the stiffness applied
matrix-free (:class:`shellsim.element.assembly.StiffnessProduct`). The Ritz value approaches
lambda_max from below, so its residual norm is added: lambda_max <= theta + |r| (for the
eigenvalue the Ritz pair has found, which must be the top one).

The first estimate is ARPACK's (through scipy) from a random vector. Each later one is a
short Lanczos run with full reorthogonalisation from the last eigenvector mixed with as
much of a fresh random vector: from the eigenvector alone the run ends at once on the old
top mode when another has overtaken it (an element crumpling), and measured along the
leaflet flap's 2,190 estimates, 7% of them then fell short of lambda_max, by up to half;
the random half lets the new top mode grow (the worst shortfall a few percent, which the
safety factor covers). The recurrence gives the residual without a further product.
Then dt_critical = 2 / omega_max (Eq 3.43 divides it by the safety factor).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable

import numpy as np
from scipy.linalg import eigh_tridiagonal
from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, LinearOperator, eigsh
from threadpoolctl import threadpool_limits

from ..errors import NumericalError

# BLAS serves only the Lanczos vector operations here, too small to share out; OpenBLAS'
# threads (numpy's and scipy's, both loaded by now) kept spinning after each call and
# took the second core from the element loop (Scordelis-Lo 16 x 16 on two threads: 7.6
# us per element-step with them, 4.9 without).
threadpool_limits(limits=1, user_api="blas")


#: ARPACK's Lanczos basis size (its default of 20 vectors spends more stiffness products).
LANCZOS_VECTORS = 6
#: Relative tolerance of the Ritz value, and the coarse one taken when it has not been met
#: within PRODUCTS stiffness products, so that an estimate's cost stays bounded at any
#: mesh size. Cold estimates measured: 37 products on a 10,000-element plate, 43 on a
#: 931-element tube, up to 196 for the shipped decks (Scordelis-Lo), 565 on a uniform
#: 32 x 32 plate (a cluster at the top of the spectrum; now 300 + 22).
TOLERANCE, COARSE_TOLERANCE, PRODUCTS = 1e-4, 1e-2, 300
#: A later estimate's tolerance and most products (its basis is kept whole: most x 5n
#: numbers). Along the leaflet flap: 9 products per estimate on average at 1e-3 (12 at
#: 1e-4), against ARPACK's 12 from the eigenvector alone; the bound 0.1% high at most,
#: so the step at most 0.05% shorter. Past WARM_PRODUCTS the bound is taken at the coarse
#: tolerance, as a cold estimate past its PRODUCTS takes it; only past that does ARPACK
#: take over (on a synthetic tricuspid valve of 8,100 shells, whose rings of equal
#: elements make a cluster at the top, a warm estimate held to 1e-3 ran 309 products, 34
#: s, each time; at 40 products its residual was within 3e-3).
WARM_TOLERANCE, WARM_PRODUCTS = 1e-3, 40


#: The share of the safety factor's margin (ln safety) the critical step may change by
#: between two estimates (5.6% at the default 1.25). Along the leaflet flap (safety 2,
#: 11,000 steps): a half gave 249 estimates and three steps longer than the critical step
#: found next; a quarter 1,176 estimates, the step always below the next critical step
#: (by 0.4% at the closest, where it halved within 41 steps); an eighth 3,321. Every 5
#: steps, as the deck said before, made 2,190.
MARGIN_SHARE = 0.25


class EstimateSchedule:
    """When to estimate the critical step again: after as many steps as keep its change,
    at the fastest rate seen over the last ``most`` steps, within MARGIN_SHARE of the
    margin the safety factor leaves; at least 1, at most ``most`` (the deck's
    dt_update_every) and twice the interval before; FIRST steps to the first. Rises count
    as falls and a rate is remembered for ``most`` steps: a critical step that swings with
    the structure's motion (a flap rebounding) turns and falls again within a swing,
    faster than the interval just before its turn showed (on the leaflet flap, judged by
    the last interval alone, a 40-step interval saw the critical step halve and the run
    broke down). Without a margin (safety <= 1), every ``most`` steps."""

    FIRST = 5

    def __init__(self, safety: float, most: int):
        self.safety, self.most = safety, most
        self.interval = min(self.FIRST, most)
        self._seen: deque[tuple[int, float]] = deque()  # (step, ln dt_critical) of recent estimates

    def after_estimate(self, step: int, critical: float) -> int:
        """Steps to the next estimate, told this one's ``step`` count and ``critical`` step."""
        seen = self._seen
        seen.append((step, math.log(critical)))
        while len(seen) > 2 and seen[1][0] <= step - self.most:
            seen.popleft()  # the pair spanning the window's start stays
        if self.safety <= 1.0:
            self.interval = self.most
        if self.safety <= 1.0 or len(seen) < 2:
            return self.interval
        rate = max((abs(b - a) / max(m - k, 1) for (k, a), (m, b) in zip(seen, list(seen)[1:])), default=0.0)
        proposed = MARGIN_SHARE * math.log(self.safety) / rate if rate > 0.0 else math.inf
        self.interval = int(max(1, min(self.most, 2 * self.interval, proposed)))
        return self.interval


class _OverBudget(Exception):
    """The Lanczos iteration used its PRODUCTS."""


def largest_eigenvalue(sim, start: np.ndarray | None = None,
                       on_product: Callable[[int], None] | None = None,
                       fresh: np.random.Generator | None = None) -> tuple[float, np.ndarray]:
    """Upper estimate of lambda_max = omega_max^2 at the simulation's current state, and the
    eigenvector (for the next estimate's ``start``, (5n,)). ``sim``: a :class:`Simulation`;
    ``on_product`` is told the count of stiffness products so far (progress on a large
    mesh); ``fresh`` draws the random half of a later estimate's start vector.

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
        sim.compiled.stiffness(m.structure, s.fields.shape, s.stress, vu, vr, fu, fr, space.parts)
        out_u = np.einsum("nij,nj->ni", projector, fu) * inv_sqrt_t[:, None]
        out_r = fr * rot_free * inv_sqrt_r[:, None]
        product = np.concatenate([out_u.ravel(), out_r.ravel()])
        if not np.isfinite(product).all():  # the shape has degenerated (a crushed element): no step exists
            raise NumericalError(f"the run broke down at t = {s.t:.6g}: the stiffness at its shape is no longer "
                                 "a number, so no critical time step exists; the motion had become unstable")
        return product

    size = 5 * n
    if start is not None:
        start = mixed_start(start, fresh or np.random.default_rng(0))
        found = short_lanczos(apply, start, WARM_TOLERANCE, min(WARM_PRODUCTS, size), COARSE_TOLERANCE)
        if found is not None:
            return _checked(s, *found)
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
    return _checked(s, theta + np.linalg.norm(apply(vector) - theta * vector), vector)


def mixed_start(last: np.ndarray, fresh: np.random.Generator) -> np.ndarray:
    """A later estimate's start (size,): the last eigenvector ``last`` and a random vector
    from ``fresh``, each of unit length, so that a mode that has overtaken the last top one
    is in it to grow."""
    random = fresh.standard_normal(last.size)
    return last / np.linalg.norm(last) + random / np.linalg.norm(random)


def short_lanczos(apply: Callable[[np.ndarray], np.ndarray], start: np.ndarray, tolerance: float,
                  most: int, coarse: float = 0.0) -> tuple[float, np.ndarray] | None:
    """(theta + |r|, Ritz vector) of the top Ritz pair of the symmetric operator ``apply``
    once |r| <= tolerance * theta, within ``most`` products from ``start`` (size,); failing
    that, the last pair where |r| <= coarse * theta; None if neither. Each new basis
    vector is orthogonalised against all before it, twice."""
    basis = np.empty((most, start.size))
    basis[0] = start / np.linalg.norm(start)
    alpha, beta = np.empty(most), np.empty(most)
    for k in range(most):
        w = apply(basis[k])
        alpha[k] = basis[k] @ w
        for _ in range(2):
            w -= basis[:k + 1].T @ (basis[:k + 1] @ w)
        beta[k] = np.linalg.norm(w)
        values, vectors = eigh_tridiagonal(alpha[:k + 1], beta[:k])
        theta, ritz = values[-1], vectors[:, -1]
        residual = beta[k] * abs(ritz[-1])
        if residual <= tolerance * abs(theta) or k + 1 == start.size \
                or (k + 1 == most and residual <= coarse * abs(theta)):
            return float(theta + residual), ritz @ basis[:k + 1]
        if k + 1 < most:
            basis[k + 1] = w / beta[k]
    return None


def _checked(state, bound: float, vector: np.ndarray) -> tuple[float, np.ndarray]:
    """(bound, vector), or NumericalError when the bound is no positive number."""
    if not (np.isfinite(bound) and bound > 0):
        raise NumericalError(_degenerate(state, f"its largest eigenvalue came out as {bound:.3g}"))
    return bound, vector


def massless_nodes(mt: np.ndarray, mr: np.ndarray) -> np.ndarray:
    """The nodes whose lumped masses mt, mr (n,) are not positive finite numbers (NaN included)."""
    return np.flatnonzero(~((0.0 < mt) & (mt < np.inf) & (0.0 < mr) & (mr < np.inf)))


def _check_masses(mt: np.ndarray, mr: np.ndarray) -> None:
    """Lumped masses (n,) must be positive numbers for M^-1/2 K M^-1/2 to mean anything."""
    bad = massless_nodes(mt, mr)
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
                       on_product: Callable[[int], None] | None = None,
                       fresh: np.random.Generator | None = None) -> tuple[float, np.ndarray]:
    """(dt_critical = 2 / omega_max, eigenvector) at the current state; see :func:`largest_eigenvalue`."""
    lam, vector = largest_eigenvalue(sim, start, on_product, fresh)
    return 2.0 / np.sqrt(lam), vector
