"""Hyperelastic laws under zero normal stress: stresses and tangents against finite
differences of the strain energy, the determinant condition, and the closed-form
homogeneous responses of incompressible Mooney-Rivlin (benchmarks.md 8B). Every law is
evaluated on a full element group, one random strain per lane."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.bundles import Material
from shellsim.element.lanes import LANES
from shellsim.materials import zero_normal_stress as zns
from shellsim.materials.laws import LAWS, energy, law_of

PARAMETERS = {
    "mooney_rivlin": np.array([0.2e6, 0.05e6]),
    "neo_hookean": np.array([0.3e6, 0.0]),
    "guccione": np.array([25e3, 20.0, 10.0, 10.0]),
    "linear_elastic": np.array([577.0, 385.0, 5.0 / 6.0]),
}


def material(model: str) -> Material:
    """The kernels' bundle for the law serving ``model`` with :data:`PARAMETERS`."""
    code, law = law_of(model)
    return Material(law=code, params=PARAMETERS[model], incompressible=law.INCOMPRESSIBLE,
                    C=np.zeros((5, 5)), axes0=np.zeros((1, 1, 1, 3, 3)), technique=1, normal_ratio=0.0,
                    incremental=False, thickness_update=False)


def random_strains(rng, size):
    """(3, 3, G) Green-Lagrange strains of random deformation gradients I + O(size), one
    per lane; E33 = 0."""
    F = np.eye(3) + rng.uniform(-size, size, (LANES, 3, 3))
    E = 0.5 * (np.einsum("gki,gkj->gij", F, F) - np.eye(3))
    E[:, 2, 2] = 0.0
    return np.ascontiguousarray(E.transpose(1, 2, 0))


def lane_values():
    """(S, Cinv, pressure, volume, work) buffers for one group."""
    return np.empty((3, 3, LANES)), np.empty((3, 3, LANES)), np.empty(LANES), np.empty(LANES), np.empty((3, 3, 3, LANES))


def solved_stress(mat, E):
    """(S~, E with E33 solved, Cinv, pressure) of strains E (3, 3, G)."""
    E = E.copy()
    S, Cinv, pressure, volume, work = lane_values()
    zns.stress(mat, E, S, Cinv, pressure, volume, work)
    return S, E, Cinv, pressure


def reduced_energy(mat, E):
    """W~ (G,) of the eight in-plane and shear components, E33 from zero normal stress."""
    E = E.copy()
    stretch, W = np.empty(LANES), np.empty(LANES)
    zns.normal_strain(mat, E, stretch, np.empty((3, 3, 3, LANES)))
    energy(mat.law, mat.params, E, W)
    return W


@pytest.mark.parametrize("model", PARAMETERS)
def test_stress_is_the_derivative_of_the_reduced_energy(model):
    mat = material(model)
    rng = np.random.default_rng(1)
    for size in (0.02, 0.3):
        E = random_strains(rng, size)
        S = solved_stress(mat, E)[0]
        h = 1e-6
        for i in range(3):
            for j in range(i, 3):
                if (i, j) == (2, 2):
                    continue
                step = np.zeros((3, 3, 1))
                step[i, j] = step[j, i] = h
                dW = reduced_energy(mat, E + step) - reduced_energy(mat, E - step)
                expected = dW / (2 * h) / (1 if i == j else 2)
                np.testing.assert_allclose(S[i, j], expected, rtol=1e-5, atol=1e-7 * np.abs(S).max())
        assert np.all(S[2, 2] == 0.0)


@pytest.mark.parametrize("model", PARAMETERS)
def test_tangent_is_the_derivative_of_the_stress(model):
    mat = material(model)
    rng = np.random.default_rng(2)
    for size in (0.02, 0.3):
        E = random_strains(rng, size)
        direction = random_strains(rng, 0.5)
        S, E_solved, Cinv, pressure = solved_stress(mat, E)
        dS = np.empty((3, 3, LANES))
        zns.tangent(mat, E_solved, Cinv, pressure, direction.copy(), dS, np.empty((3, 3, 3, LANES)))
        h = 1e-6
        Sp, Sm = solved_stress(mat, E + h * direction)[0], solved_stress(mat, E - h * direction)[0]
        np.testing.assert_allclose(dS, (Sp - Sm) / (2 * h), rtol=1e-5, atol=1e-6 * np.abs(dS).max())


def test_normal_strain_gives_unit_determinant():
    E = random_strains(np.random.default_rng(3), 0.4)
    stretch = np.empty(LANES)
    zns.solve_normal_strain(E, stretch)
    C = 2 * E.transpose(2, 0, 1) + np.eye(3)
    np.testing.assert_allclose(np.linalg.det(C), 1.0, atol=1e-13)
    np.testing.assert_allclose(stretch, np.sqrt(1 + 2 * E[2, 2]), rtol=1e-15)


def test_st_venant_kirchhoff_normal_strain_frees_the_normal_stress():
    """The compressible law: E33 = -lambda (E11 + E22) / (lambda + 2 mu), J = sqrt(det C)."""
    mat = material("linear_elastic")
    lam, mu = PARAMETERS["linear_elastic"][:2]
    E = random_strains(np.random.default_rng(4), 0.3)
    S, Cinv, pressure, volume, work = lane_values()
    solved = E.copy()
    zns.stress(mat, solved, S, Cinv, pressure, volume, work)
    np.testing.assert_allclose(solved[2, 2], -lam * (E[0, 0] + E[1, 1]) / (lam + 2 * mu), rtol=1e-14)
    np.testing.assert_allclose(volume, np.sqrt(np.linalg.det(2 * solved.transpose(2, 0, 1) + np.eye(3))), rtol=1e-14)
    assert np.all(pressure == 0.0)


@pytest.mark.parametrize("stretch", [1.01, 1.5, 2.0, 3.26])
def test_mooney_rivlin_homogeneous_stretches_match_the_closed_form(stretch):
    """Uniaxial and equibiaxial nominal stress and thickness stretch (benchmarks.md 8B),
    in every lane."""
    C1, C2 = PARAMETERS["mooney_rivlin"]
    mat = material("mooney_rivlin")
    lam = stretch

    def solved(diagonal):
        E = np.zeros((3, 3, LANES))
        E[[0, 1, 2], [0, 1, 2]] = np.asarray(diagonal)[:, None]
        return solved_stress(mat, E)[:2]

    S, E = solved([(lam**2 - 1) / 2, (1 / lam - 1) / 2, 0.0])
    np.testing.assert_allclose(S[0, 0] * lam, 2 * (lam - lam**-2) * (C1 + C2 / lam), rtol=1e-12)
    np.testing.assert_allclose(S[1, 1], 0.0, atol=1e-9 * C1)  # the lateral edge is free
    np.testing.assert_allclose(np.sqrt(1 + 2 * E[2, 2]), lam**-0.5, rtol=1e-12)
    S, E = solved([(lam**2 - 1) / 2, (lam**2 - 1) / 2, 0.0])
    np.testing.assert_allclose(S[0, 0] * lam, 2 * (lam - lam**-5) * (C1 + C2 * lam**2), rtol=1e-12)
    np.testing.assert_allclose(np.sqrt(1 + 2 * E[2, 2]), lam**-2, rtol=1e-12)


def test_every_deck_model_of_a_law_is_a_deck_material():
    """The registry and the deck agree: the deck accepts each law's models."""
    from shellsim.deck.material import MATERIALS

    from shellsim.deck.types import tag_of

    for law in LAWS:
        for model in law.MODELS:
            assert MATERIALS[tag_of(model)[1]] is model
