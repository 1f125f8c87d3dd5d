"""A thin inextensible ring (radius R, bending stiffness EI per unit length) squeezed
between two rigid flat plates, as an elastica: the plates' force per unit length P
against their approach, through the phase where the ring touches each plate at one point
and the phase where it lies flat along them.

By symmetry a quarter is enough: from the side point B (tangent along the plates'
normal, no shear) to the top point A (tangent along the plate). With the arc length s
from B, the tangent's angle theta(s) from the plate (theta(0) = pi/2) and
u(s) = int_0^s cos(theta) (the horizontal distance from B), the moment balance of the
arc from B is

    EI (theta' - 1/R) = EI c + (P/2) u(s)

(the plate's half-load carried through B; c the change of curvature at B). In the point
phase, c is found so that theta = pi at A (s = pi R / 2); the plates' approach is
2 (R - y_A). The point phase ends when the curvature at A reaches zero; after it the ring
lies flat over a length a at each end of the quarter (curvature zero there, the load
taken where it leaves the plate), and (c, a) are found so that theta = pi and
theta' = 0 at s = pi R / 2 - a. This is the shooting method on the elastica's equations
(Frisch-Fay, *Flexible Bars*, Butterworths, 1962); as the load goes to zero it gives
the thin ring's linear answer, a change of the loaded diameter (pi/4 - 2/pi) P R^3 / EI
(Timoshenko, *Strength of Materials* I, curved bars; Roark's Formulas, Table 9.2
case 1).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq


def _arc(load: float, change: float, length: float):
    """(theta, theta', y) at the end of the arc of ``length`` from B for the dimensionless
    half-load p = P R^2 / (2 EI) and change of curvature c R at B (R = 1)."""
    def slope(_s, state):
        theta, u, y = state
        return (1.0 + change + load * u, np.cos(theta), np.sin(theta))

    end = solve_ivp(slope, (0.0, length), (np.pi / 2, 0.0, 0.0), method="DOP853", rtol=1e-10, atol=1e-12).y[:, -1]
    return end[0], 1.0 + change + load * end[1], end[2]


def _ending_level(load: float, length: float) -> float:
    """The change of curvature at B that brings the arc of ``length`` to the plate's
    direction (theta = pi) under half-load p."""
    return brentq(lambda c: _arc(load, c, length)[0] - np.pi, -1.0, 50.0, xtol=1e-14)


def point_phase(load: float) -> tuple[float, float]:
    """(approach / R, curvature at A times R) of the point phase under the dimensionless
    half-load p = P R^2 / (2 EI)."""
    quarter = np.pi / 2
    _, curvature, height = _arc(load, _ending_level(load, quarter), quarter)
    return 2.0 * (1.0 - height), curvature


def _flat_phase(load: float) -> float:
    """The approach / R of the flat phase under half-load p: the flat length a where the
    arc that ends along the plate ends with zero curvature."""
    def curvature(flat):
        length = np.pi / 2 - flat
        return _arc(load, _ending_level(load, length), length)[1]

    flat = brentq(curvature, 0.0, np.pi / 2 - 0.05, xtol=1e-14)
    length = np.pi / 2 - flat
    return 2.0 * (1.0 - _arc(load, _ending_level(load, length), length)[2])


def _flat_start_load() -> float:
    """The half-load p at which the curvature at A reaches zero."""
    return brentq(lambda p: point_phase(p)[1], 0.1, 50.0, xtol=1e-13)


def load_path(points: int = 40, largest_approach: float = 1.1) -> tuple[np.ndarray, np.ndarray]:
    """(approach / R, P R^2 / EI) (m,) along the squeeze from rest up to at least
    ``largest_approach`` x R (the plates' approach of both sides: 1.0 is half the
    diameter), the flat phase included; ``points`` loads in the point phase, spaced
    evenly, and loads growing by 1/points in the flat."""
    flat_start = _flat_start_load()
    approaches, loads = [0.0], [0.0]
    for p in np.linspace(0.0, flat_start, points + 1)[1:]:
        approaches.append(point_phase(p)[0])
        loads.append(2.0 * p)
    p = flat_start
    while approaches[-1] < largest_approach:
        p *= 1.0 + 1.0 / points
        approaches.append(_flat_phase(p))
        loads.append(2.0 * p)
    return np.asarray(approaches), np.asarray(loads)


def load_at(approach, radius: float, bending_stiffness: float, path=None):
    """The plates' force per unit length P [force/length] at the plates' ``approach``
    (scalar or (m,), [length], both sides together) of a ring of ``radius`` and
    ``bending_stiffness`` EI per unit length, interpolated (cubic, monotone) on
    :func:`load_path` (or the ``path`` it returned)."""
    relative, loads = path if path is not None else load_path(largest_approach=np.max(approach) / radius + 0.05)
    return PchipInterpolator(relative, loads)(np.asarray(approach) / radius) * bending_stiffness / radius**2


def flat_phase_start() -> float:
    """The approach / R at which the ring begins to lie flat along the plates."""
    return point_phase(_flat_start_load())[0]
