"""The closed-form references against benchmarks.md: tube inflation (the tables of the
Tests 9 and 10 stand-ins, and the exact resultants any solution must meet) and the
Mindlin plate of Test 1 (1A, NAFEMS 21T, and its Kirchhoff limit)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from shellsim.verify.analytic import Guccione, through_wall_stresses, tube_inflation
from shellsim.verify.plate import plate_step_reference

AORTA = dict(inner_radius=10.0e-3, wall_thickness=1.5e-3, law=Guccione((25e3, 20.0, 10.0, 10.0)))
CAROTID = dict(inner_radius=1.2e-3, wall_thickness=0.5e-3, law=Guccione((20e3, 8.0, 4.0, 4.0)))


@pytest.mark.parametrize("tube, pressures, r_i, lam_z", [
    (AORTA, [2e3, 8e3, 13.33e3, 18.66e3], [10.204888, 10.759377, 11.091432, 11.316356],
     [1.006830, 1.035529, 1.059130, 1.077306]),
    (CAROTID, [2e3, 13.33e3, 26.66e3], [1.238930, 1.430612, 1.531909], [1.008723, 1.095435, 1.163966]),
])
def test_tube_inflation_matches_the_published_tables(tube, pressures, r_i, lam_z):
    radius, stretch = tube_inflation(np.array(pressures), **tube)
    np.testing.assert_allclose(radius * 1e3, r_i, atol=2e-6)
    np.testing.assert_allclose(stretch, lam_z, atol=2e-6)


def test_through_wall_stresses_meet_the_exact_resultants():
    """int s_tt dr = P r_i and int 2 pi r s_zz dr = pi r_i^2 P (benchmarks.md)."""
    P, tube = 13.33e3, AORTA
    R_i, H = tube["inner_radius"], tube["wall_thickness"]
    (r_i,), (lam_z,) = tube_inflation([P], **tube)
    s_rr, s_tt, s_zz = through_wall_stresses(P, [R_i, R_i + H], **tube)
    assert s_rr[0] == pytest.approx(-P, rel=1e-9) and abs(s_rr[1]) < 1e-9 * P
    assert s_tt[0] / 1e3 == pytest.approx(143.1916, abs=1e-3)  # benchmarks.md, R = 10.00 mm

    def radius(R):
        return np.sqrt(r_i**2 + (R**2 - R_i**2) / lam_z)

    def over_r(f):  # int f dr over the wall, with dr = R dR / (lam_z r)
        return quad(lambda R: f(R) * R / (lam_z * radius(R)), R_i, R_i + H, epsrel=1e-10)[0]

    hoop = over_r(lambda R: through_wall_stresses(P, R, **tube)[1][0])
    axial = over_r(lambda R: 2 * np.pi * radius(R) * through_wall_stresses(P, R, **tube)[2][0])
    assert hoop == pytest.approx(P * r_i, rel=1e-7)
    assert axial == pytest.approx(np.pi * r_i**2 * P, rel=1e-7)


@pytest.mark.parametrize("plate, deflection, frequency", [
    # benchmarks.md Test 1A: w_M = 1.28387e-4 m, Mindlin w11 = 6028.5 rad/s
    (dict(side=0.25, thickness=0.0125, E=70e9, nu=0.3, density=2700.0, pressure=100e3), 1.28387e-4, 6028.5),
    # NAFEMS 21T (benchmarks.md Test 1B): 2.333 mm static, 288.379 rad/s (our Mindlin 288.47)
    (dict(side=10.0, thickness=1.0, E=200e9, nu=0.3, density=8000.0, pressure=1e6), 2.3330e-3, 288.47),
])
def test_plate_reference_matches_benchmarks(plate, deflection, frequency):
    w, omega = plate_step_reference(**plate)
    assert w == pytest.approx(deflection, rel=5e-5)
    assert omega == pytest.approx(frequency, rel=5e-5)


def test_thin_plate_reference_tends_to_kirchhoff():
    """At a / h = 1e4 the Mindlin values meet Kirchhoff's: w = 0.0040624 q a^4 / D
    (Timoshenko & Woinowsky-Krieger) and w11 = 2 (pi/a)^2 sqrt(D / (rho h))."""
    a, h, E, nu, rho, q = 0.25, 2.5e-5, 70e9, 0.3, 2700.0, 1.6e-6
    D = E * h**3 / (12 * (1 - nu**2))
    w, omega = plate_step_reference(a, h, E, nu, rho, q)
    assert w == pytest.approx(0.0040624 * q * a**4 / D, rel=2e-5)
    assert omega == pytest.approx(2 * (np.pi / a) ** 2 * np.sqrt(D / (rho * h)), rel=1e-6)


@pytest.mark.parametrize("sharpness", [0.0, 100.0])
def test_the_tube_references_hgo_stress_is_the_law_of_the_kernels(sharpness):
    """The semi-analytic tube's HGO stresses (circumferential, axial, radial) equal the
    compiled law's S^w in material axes (1 circumferential, 2 axial, 3 radial) at
    principal strains, fibres stretched and shortened, sharply and smoothly switched: two
    separate writings agree."""
    from shellsim.lanes import LANES
    from shellsim.materials import hgo
    from shellsim.verify.analytic import HolzapfelGasserOgden

    law = HolzapfelGasserOgden(40e3, 100e3, 20.0, 0.226, 40.0, sharpness)
    params = np.array([40e3, 100e3, 20.0, 0.226, np.cos(np.radians(40.0)), np.sin(np.radians(40.0)), sharpness])
    for strains in ((0.1, 0.02, -0.1), (-0.05, 0.01, 0.04), (0.2, 0.1, -0.25), (0.01, -0.005, -0.005)):
        E = np.zeros((3, 3, LANES))
        for i, value in enumerate(strains):
            E[i, i] = value
        S = np.empty((3, 3, LANES))
        hgo.energy_stress(params, E, S)
        np.testing.assert_allclose([S[0, 0, 0], S[1, 1, 0], S[2, 2, 0]], law.stresses(*strains), rtol=1e-12)
