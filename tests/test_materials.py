"""Hyperelastic laws under zero normal stress: stresses and tangents against finite
differences of the strain energy, the determinant condition, and the closed-form
homogeneous responses of incompressible Mooney-Rivlin (benchmarks.md 8B)."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.materials import hyperelastic as hy

LAWS = {
    "mooney_rivlin": (hy.MOONEY_RIVLIN, np.array([0.2e6, 0.05e6, 0.0, 0.0])),
    "neo_hookean": (hy.MOONEY_RIVLIN, np.array([0.3e6, 0.0, 0.0, 0.0])),
    "guccione": (hy.GUCCIONE, np.array([25e3, 20.0, 10.0, 10.0])),
    "st_venant_kirchhoff": (hy.ST_VENANT_KIRCHHOFF, np.array([577.0, 385.0, 5.0 / 6.0, 0.0])),
}


def random_strain(rng, size):
    """Green-Lagrange strain of a random deformation gradient I + O(size); E33 = 0."""
    F = np.eye(3) + rng.uniform(-size, size, (3, 3))
    E = 0.5 * (F.T @ F - np.eye(3))
    E[2, 2] = 0.0
    return E


def reduced_energy(law, params, E):
    """W~ of the eight in-plane and shear components, E33 from zero normal stress."""
    E = E.copy()
    hy.normal_strain(law, params, E)
    return hy.strain_energy(law, params, E)


@pytest.mark.parametrize("name", LAWS)
def test_stress_is_the_derivative_of_the_reduced_energy(name):
    law, params = LAWS[name]
    rng = np.random.default_rng(1)
    for size in (0.02, 0.3):
        E = random_strain(rng, size)
        S, Cinv = np.empty((3, 3)), np.empty((3, 3))
        hy.stress(law, params, E.copy(), S, Cinv)
        h = 1e-6
        for i in range(3):
            for j in range(i, 3):
                if (i, j) == (2, 2):
                    continue
                step = np.zeros((3, 3))
                step[i, j] = step[j, i] = h
                dW = reduced_energy(law, params, E + step) - reduced_energy(law, params, E - step)
                expected = dW / (2 * h) / (1 if i == j else 2)
                assert S[i, j] == pytest.approx(expected, rel=1e-5, abs=1e-7 * np.abs(S).max())
        assert S[2, 2] == 0.0


@pytest.mark.parametrize("name", LAWS)
def test_tangent_is_the_derivative_of_the_stress(name):
    law, params = LAWS[name]
    rng = np.random.default_rng(2)
    for size in (0.02, 0.3):
        E = random_strain(rng, size)
        direction = random_strain(rng, 0.5)
        S, Cinv = np.empty((3, 3)), np.empty((3, 3))
        E_solved = E.copy()
        p = hy.stress(law, params, E_solved, S, Cinv)
        dS = np.empty((3, 3))
        hy.tangent(law, params, E_solved, Cinv, p, direction.copy(), dS)
        h = 1e-6
        Sp, Sm, work = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3))
        hy.stress(law, params, E + h * direction, Sp, work)
        hy.stress(law, params, E - h * direction, Sm, work)
        np.testing.assert_allclose(dS, (Sp - Sm) / (2 * h), rtol=1e-5, atol=1e-6 * np.abs(dS).max())


def test_normal_strain_gives_unit_determinant():
    rng = np.random.default_rng(3)
    for _ in range(20):
        E = random_strain(rng, 0.4)
        stretch = hy.solve_normal_strain(E, 1.0)
        assert np.linalg.det(2 * E + np.eye(3)) == pytest.approx(1.0, abs=1e-13)
        assert stretch == pytest.approx(np.sqrt(1 + 2 * E[2, 2]))


@pytest.mark.parametrize("stretch", [1.01, 1.5, 2.0, 3.26])
def test_mooney_rivlin_homogeneous_stretches_match_the_closed_form(stretch):
    """Uniaxial and equibiaxial nominal stress and thickness stretch (benchmarks.md 8B)."""
    C1, C2 = 0.2e6, 0.05e6
    law, params = hy.MOONEY_RIVLIN, np.array([C1, C2, 0.0, 0.0])
    S, Cinv = np.empty((3, 3)), np.empty((3, 3))
    lam = stretch
    uniaxial = np.diag([(lam**2 - 1) / 2, (1 / lam - 1) / 2, 0.0])
    hy.stress(law, params, uniaxial, S, Cinv)
    assert S[0, 0] * lam == pytest.approx(2 * (lam - lam**-2) * (C1 + C2 / lam), rel=1e-12)
    assert S[1, 1] == pytest.approx(0.0, abs=1e-9 * C1)  # the lateral edge is free
    assert np.sqrt(1 + 2 * uniaxial[2, 2]) == pytest.approx(lam**-0.5, rel=1e-12)
    equibiaxial = np.diag([(lam**2 - 1) / 2, (lam**2 - 1) / 2, 0.0])
    hy.stress(law, params, equibiaxial, S, Cinv)
    assert S[0, 0] * lam == pytest.approx(2 * (lam - lam**-5) * (C1 + C2 * lam**2), rel=1e-12)
    assert np.sqrt(1 + 2 * equibiaxial[2, 2]) == pytest.approx(lam**-2, rel=1e-12)
