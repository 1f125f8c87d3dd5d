"""Semi-analytic references: closed-end inflation of an incompressible anisotropic tube,
and the inflation of a neo-Hookean sphere (:func:`sphere_inflation_path`).

Exact 3D solution (benchmarks.md, Tests 9 and 10) for a law without shear strains in
cylindrical axes (t circumferential, z axial, r radial): the Guccione law of thesis Eq 4.2
(:class:`Guccione`) or Holzapfel-Gasser-Ogden with two families at +-beta from the
circumferential direction (:class:`HolzapfelGasserOgden`; the families' shears cancel).

Deformation r(R) with r^2 = r_i^2 + (R^2 - R_i^2) / lambda_z, theta = Theta,
z = lambda_z Z; stretches lambda_t = r / R, lambda_z, lambda_r = 1 / (lambda_t lambda_z).
Cauchy stress differences D_t = s_tt - s_rr = lambda_t^2 S_tt - lambda_r^2 S_rr and
D_z = s_zz - s_rr, S the energy's second Piola stress. Radial equilibrium with
s_rr(r_i) = -P, s_rr(r_o) = 0 and the closed end's axial balance (wall force = pi r_i^2 P)
give, with r dr = R dR / lambda_z,

    P = int_{R_i}^{R_o} D_t R / (lambda_z r^2) dR,
    0 = int_{R_i}^{R_o} (2 D_z - D_t) R / lambda_z dR,

solved for (r_i, lambda_z) at each pressure, continuing from (R_i, 1) at P = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad
from scipy.optimize import root


@dataclass(frozen=True)
class Guccione:
    """W = C1/2 (exp Q - 1), Q = C2 E_tt^2 + C3 (E_zz^2 + E_rr^2) (no shear strains here);
    C = (C1, C2, C3, C4), C1 in stress units, C4 (the shear weight) does no work here."""

    C: tuple[float, float, float, float]

    @property
    def scale(self) -> float:
        return self.C[0]

    def stresses(self, E_t, E_z, E_r):
        """(S_tt, S_zz, S_rr) at the principal Green-Lagrange strains."""
        C1, C2, C3, _ = self.C
        factor = C1 * np.exp(C2 * E_t**2 + C3 * (E_z**2 + E_r**2))
        return factor * C2 * E_t, factor * C3 * E_z, factor * C3 * E_r


@dataclass(frozen=True)
class HolzapfelGasserOgden:
    """W = mu/2 (I1 - 3) + sum over the families at +-beta_deg from the circumferential
    direction of chi(I4) k1/(2 k2) (exp(k2 Ebar^2) - 1), Ebar = kappa (I1 - 3) + (1 - 3
    kappa) (I4 - 1), chi the step I4 > 1 (a family carrying nothing while I4 <= 1; Gasser,
    Ogden & Holzapfel 2006) or, with ``switch_sharpness`` k, 1 / (1 + exp(-k (I4 - 1)))."""

    mu: float
    k1: float
    k2: float
    kappa: float
    beta_deg: float
    switch_sharpness: float = 0.0

    @property
    def scale(self) -> float:
        return self.mu

    def stresses(self, E_t, E_z, E_r):
        """(S_tt, S_zz, S_rr) = mu I + sum_f [2 chi psi (kappa I + (1 - 3 kappa) a_f a_f)
        + 2 chi' Phi a_f a_f] at the principal strains; both families stretch alike, psi =
        k1 Ebar exp(k2 Ebar^2), Phi = k1/(2 k2) (exp(k2 Ebar^2) - 1), chi' = dchi/dI4."""
        c, s = np.cos(np.radians(self.beta_deg)), np.sin(np.radians(self.beta_deg))
        fibre = c * c * E_t + s * s * E_z  # a.E a = (I4 - 1) / 2
        ebar = 2.0 * self.kappa * (E_t + E_z + E_r) + 2.0 * (1.0 - 3.0 * self.kappa) * fibre
        k = self.switch_sharpness
        chi = np.where(fibre > 0.0, 1.0, 0.0) if k == 0.0 else 1.0 / (1.0 + np.exp(-2.0 * k * fibre))
        psi = chi * self.k1 * ebar * np.exp(self.k2 * ebar**2)
        own = k * chi * (1.0 - chi) * self.k1 / (2.0 * self.k2) * np.expm1(self.k2 * ebar**2)
        dispersed, aligned = 4.0 * psi * self.kappa, 4.0 * (psi * (1.0 - 3.0 * self.kappa) + own)
        return (self.mu + dispersed + aligned * c * c, self.mu + dispersed + aligned * s * s,
                self.mu + dispersed)


def _stress_differences(R, r_i, lam_z, R_i, law):
    """(D_t, D_z, r) at material radius R."""
    r = np.sqrt(r_i**2 + (R**2 - R_i**2) / lam_z)
    lam_t = r / R
    lam_r = 1.0 / (lam_t * lam_z)
    S_t, S_z, S_r = law.stresses(0.5 * (lam_t**2 - 1), 0.5 * (lam_z**2 - 1), 0.5 * (lam_r**2 - 1))
    return lam_t**2 * S_t - lam_r**2 * S_r, lam_z**2 * S_z - lam_r**2 * S_r, r


def _radial_gradient(R, r_i, lam_z, R_i, law):
    """d s_rr / dR = D_t R / (lambda_z r^2) at material radius R: the integrand of the
    radial balance."""
    D_t, _, r = _stress_differences(R, r_i, lam_z, R_i, law)
    return D_t * R / (lam_z * r**2)


def _residuals(unknowns, pressure, R_i, R_o, law):
    """Both balances in units of the law's stress scale, for the unknowns (r_i / R_i,
    lambda_z)."""
    r_i, lam_z = unknowns[0] * R_i, unknowns[1]

    def axial(R):
        D_t, D_z, _ = _stress_differences(R, r_i, lam_z, R_i, law)
        return (2 * D_z - D_t) * R / lam_z

    hoop = quad(_radial_gradient, R_i, R_o, args=(r_i, lam_z, R_i, law), epsrel=1e-12)[0]
    return [(hoop - pressure) / law.scale,
            quad(axial, R_i, R_o, epsrel=1e-12)[0] / (R_o**2 * law.scale)]


def tube_inflation(pressures, inner_radius: float, wall_thickness: float, law,
                   axial_stretch: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Inner radius r_i and axial stretch lambda_z of the closed-end tube at each pressure,
    or, given ``axial_stretch``, of the tube whose ends are held at that stretch (an
    artery tethered in situ: the radial balance alone).

    pressures (m,) [stress units], increasing from 0 or above; inner_radius R_i and
    wall_thickness H of the unloaded tube [length]; ``law`` a :class:`Guccione` or
    :class:`HolzapfelGasserOgden`. Returns
    (r_i (m,) [length], lambda_z (m,)). Pressures are reached by continuation in steps
    of at most 1/50 of the largest, each solve starting from the previous solution.
    """
    pressures = np.asarray(pressures, dtype=float)
    R_i, R_o = inner_radius, inner_radius + wall_thickness
    top = max(float(pressures.max(initial=0.0)), 1e-300)
    if axial_stretch is None:
        residuals, guess = _residuals, np.array([1.0, 1.0])
    else:  # the radial balance for r_i / R_i; the guess: the wall stretched without pressure
        def residuals(unknowns, *args):
            return _residuals([unknowns[0], axial_stretch], *args)[:1]
        guess = np.array([1.0 / np.sqrt(axial_stretch)])
    done = 0.0
    out_r, out_z = np.empty(len(pressures)), np.empty(len(pressures))
    for index in np.argsort(pressures, kind="stable"):
        target = pressures[index]
        steps = max(1, int(np.ceil((target - done) / (top / 50))))
        for pressure in np.linspace(done, target, steps + 1)[1:]:
            solution = root(residuals, guess, args=(pressure, R_i, R_o, law), method="hybr", tol=1e-13)
            # 'no good progress' at round-off level is convergence: judge by the residual
            if np.abs(solution.fun).max() > 1e-10:
                raise RuntimeError(f"tube_inflation: no solution at P = {pressure:g}: {solution.message}")
            guess = solution.x
        done = target
        out_r[index], out_z[index] = guess[0] * R_i, guess[1] if axial_stretch is None else axial_stretch
    return out_r, out_z


def through_wall_stresses(pressure: float, R, inner_radius: float, wall_thickness: float, law):
    """Cauchy stresses (s_rr, s_tt, s_zz) (each like R) at material radii R through the
    wall at one pressure: s_rr(R) = -int_R^{R_o} D_t R' / (lambda_z r^2) dR'."""
    R_i, R_o = inner_radius, inner_radius + wall_thickness
    (r_i,), (lam_z,) = tube_inflation([pressure], R_i, wall_thickness, law)
    R = np.atleast_1d(np.asarray(R, dtype=float))
    s_rr = np.array([-quad(_radial_gradient, Ri, R_o, args=(r_i, lam_z, R_i, law), epsrel=1e-12)[0] for Ri in R])
    D_t, D_z, _ = _stress_differences(R, r_i, lam_z, R_i, law)
    return s_rr, s_rr + D_t, s_rr + D_z


def sphere_inflation_path(inner_radii, inner_radius: float, wall_thickness: float, C1: float) -> np.ndarray:
    """Pressure (m,) [stress units] of an incompressible neo-Hookean sphere,
    W = C1 (I1 - 3), at each inner radius r_i (m,) [length]: the exact 3D inflation of a
    balloon, whose pressure rises to a maximum and falls beyond it.

    The deformation r^3 = r_i^3 + R^3 - R_i^3 stretches the wall equally in both tangent
    directions, lambda = r / R, and by 1 / lambda^2 radially; the hoop-radial stress
    difference is 2 C1 (lambda^2 - lambda^-4), and radial equilibrium with s_rr = -P
    inside and 0 outside gives P = int 2 (s_tt - s_rr) dr / r, with dr / r = R^2 dR / r^3.
    """
    R_i, R_o = inner_radius, inner_radius + wall_thickness

    def pressure(r_i: float) -> float:
        def integrand(R):
            r = np.cbrt(r_i**3 + R**3 - R_i**3)
            lam = r / R
            return 4.0 * C1 * (lam**2 - lam**-4) * R**2 / r**3

        return quad(integrand, R_i, R_o, epsrel=1e-12)[0]

    return np.array([pressure(r_i) for r_i in np.asarray(inner_radii, dtype=float)])
