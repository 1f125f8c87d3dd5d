"""Closed-form references for a simply supported square plate under a uniform step pressure
(benchmarks.md, Test 1): Navier double sine series of the Reissner-Mindlin plate.

Hard simple support on all four edges, side a, thickness h. Mode (m, n), both odd, has
wavenumber k^2 = (pi/a)^2 (m^2 + n^2) and load coefficient q_mn = 16 q / (pi^2 m n); its
static deflection is q_mn / (D k^4) (bending) + q_mn / (kappa G h k^2) (shear), and the
centre deflection sums them with the signs sin(m pi/2) sin(n pi/2). The first frequency is
the flexural root of the Mindlin mode (1, 1) with rotary inertia rho h^3 / 12:

    (kappa G h k^2 - rho h w^2) (D k^2 + kappa G h - rho h^3/12 w^2) = (kappa G h k)^2.

As h / a falls, both tend to the Kirchhoff values (w_st = 0.0040624 q a^4 / D,
w11 = 2 (pi/a)^2 sqrt(D / (rho h))), whose undamped step response peaks at exactly twice
the static deflection at t = pi / w11.
"""

from __future__ import annotations

import numpy as np


def plate_step_reference(side: float, thickness: float, E: float, nu: float, density: float, pressure: float,
                         shear_factor: float = 5.0 / 6.0, terms: int = 400) -> tuple[float, float]:
    """(static centre deflection [length], first angular frequency [rad/time]) of the
    Mindlin plate; the step response's amplitude is the static deflection and its first
    peak falls at pi / frequency. ``terms``: odd m, n up to this bound."""
    a, h = side, thickness
    D = E * h**3 / (12.0 * (1.0 - nu**2))
    shear = shear_factor * E / (2.0 * (1.0 + nu)) * h
    m = np.arange(1, terms + 1, 2, dtype=float)
    M, N = np.meshgrid(m, m, indexing="ij")
    k2 = (np.pi / a) ** 2 * (M**2 + N**2)
    q_mn = 16.0 * pressure / (np.pi**2 * M * N)
    sign = np.sin(M * np.pi / 2) * np.sin(N * np.pi / 2)
    deflection = float(np.sum(sign * (q_mn / (D * k2**2) + q_mn / (shear * k2))))

    k2 = 2.0 * (np.pi / a) ** 2  # mode (1, 1): the smaller root of p2 w^4 + p1 w^2 + p0
    mass, inertia = density * h, density * h**3 / 12.0
    p2 = mass * inertia
    p1 = -(mass * (D * k2 + shear) + inertia * shear * k2)
    p0 = shear * k2 * D * k2
    # written as 2 p0 / (-p1 + root): the textbook form cancels when the plate is thin
    w2 = 2.0 * p0 / (-p1 + np.sqrt(p1**2 - 4.0 * p2 * p0))
    return deflection, float(np.sqrt(w2))
