"""Hyperelastic laws under zero normal stress: stresses and tangents against finite
differences of the strain energy, the determinant condition, and the closed-form
homogeneous responses of incompressible Mooney-Rivlin (benchmarks.md 8B),
Holzapfel-Gasser-Ogden and Lee-Sacks. Every law is evaluated on a full element group, one
random strain per lane."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.bundles import Material
from shellsim.element.steps import HYPERELASTIC
from shellsim.lanes import LANES
from shellsim.materials import zero_normal_stress as zns
from shellsim.materials.laws import LAWS, held_laws, law_of

PARAMETERS = {
    "mooney_rivlin": np.array([0.2e6, 0.05e6]),
    "neo_hookean": np.array([0.3e6, 0.0]),
    "guccione": np.array([25e3, 20.0, 10.0, 10.0]),
    "hgo": np.array([20e3, 50e3, 2.0, 0.1, np.cos(0.6), np.sin(0.6), 0.0]),
    "hgo_switched": np.array([20e3, 50e3, 2.0, 0.1, np.cos(0.6), np.sin(0.6), 100.0]),
    "lee_sacks": np.array([10e3, 2e3, 4.0, 20.0, 0.3, np.cos(0.6), np.sin(0.6)]),
    "linear_elastic": np.array([577.0, 385.0, 5.0 / 6.0]),
}
#: The deck models of the :data:`PARAMETERS` cases not named by their model: HGO with the
#: smooth fibre switch of svMultiPhysics (k = 100).
MODEL_OF = {"hgo_switched": "hgo"}


def material(case: str) -> Material:
    """The kernels' bundle for the law serving the model of ``case`` with its
    :data:`PARAMETERS`."""
    code, law = law_of(MODEL_OF.get(case, case))
    energy_stress, energy_tangent = held_laws([code])
    return Material(path=HYPERELASTIC, incremental=False, push_forward=False, thickness_update=False,
                    law=np.array([code]), energy_stress=energy_stress, energy_tangent=energy_tangent,
                    params=PARAMETERS[case][None], incompressible=np.array([law.INCOMPRESSIBLE]),
                    axes0=np.zeros((1, 1, 1, 3, 3)), C=np.zeros((1, 5, 5)), normal_ratio=np.zeros(1))


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
    zns.stress(mat, 0, E, S, Cinv, pressure, volume, work)
    return S, E, Cinv, pressure


def reduced_energy(mat, E):
    """W~ (G,) of the eight in-plane and shear components, E33 from zero normal stress."""
    E = E.copy()
    stretch, W = np.empty(LANES), np.empty(LANES)
    zns.normal_strain(mat, 0, E, stretch, np.empty((3, 3, 3, LANES)))
    LAWS[mat.law[0]].energy(mat.params[0], E, W)
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
        zns.tangent(mat, 0, E_solved, Cinv, pressure, direction.copy(), dS, np.empty((3, 3, 3, LANES)))
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
    zns.stress(mat, 0, solved, S, Cinv, pressure, volume, work)
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


def _hgo_cauchy(params: np.ndarray, l1: float, l2: float) -> tuple[float, float, float]:
    """Cauchy sigma_11, sigma_22, sigma_12 of incompressible HGO under F = diag(l1, l2,
    1/(l1 l2)) with sigma_33 = 0 (Gasser, Ogden & Holzapfel 2006, Eq 2.8 with the pressure
    of the free normal): sigma = -p I + 2 W1 B + sum_f 2 W4f (F a_f)(F a_f), W1 = mu/2 +
    sum_f chi kappa psi_f, W4f = chi (1 - 3 kappa) psi_f + chi' Phi_f, psi_f = k1 Ebar
    exp(k2 Ebar^2) = dPhi_f/dEbar, Phi_f = k1/(2 k2) (exp(k2 Ebar^2) - 1); chi(I4) the
    family's switch, the step I4 > 1 or 1 / (1 + exp(-k (I4 - 1))); the two families'
    shears cancel."""
    mu, k1, k2, kappa, c, s, k = params
    l3 = 1.0 / (l1 * l2)
    I1, I4 = l1**2 + l2**2 + l3**2, (l1 * c) ** 2 + (l2 * s) ** 2
    ebar = kappa * (I1 - 3) + (1 - 3 * kappa) * (I4 - 1)
    psi, phi = k1 * ebar * np.exp(k2 * ebar**2), k1 / (2 * k2) * np.expm1(k2 * ebar**2)
    chi = float(I4 > 1) if k == 0 else 1 / (1 + np.exp(-k * (I4 - 1)))
    dchi = k * chi * (1 - chi)
    W1 = mu / 2 + 2 * kappa * chi * psi  # summed over the two families
    W4 = 2 * ((1 - 3 * kappa) * chi * psi + dchi * phi)
    return 2 * W1 * (l1**2 - l3**2) + 2 * W4 * (l1 * c) ** 2, 2 * W1 * (l2**2 - l3**2) + 2 * W4 * (l2 * s) ** 2, 0.0


def _lee_sacks_cauchy(params: np.ndarray, l1: float, l2: float) -> tuple[float, float, float]:
    """Cauchy sigma_11, sigma_22, sigma_12 of incompressible Lee-Sacks under F = diag(l1,
    l2, 1/(l1 l2)) with sigma_33 = 0: sigma = -p I + 2 W1 B + 2 W4 (F a)(F a), W1 = c0/2 +
    c1 delta c2 (I1 - 3) exp(c2 (I1 - 3)^2), W4 = c1 (1 - delta) c3 (I4 - 1) exp(c3 (I4 -
    1)^2) when I4 > 1 (Lee et al. 2014, Eq 1); one family, so a shear holds F diagonal."""
    c0, c1, c2, c3, delta, c, s = params
    l3 = 1.0 / (l1 * l2)
    I1, I4 = l1**2 + l2**2 + l3**2, (l1 * c) ** 2 + (l2 * s) ** 2
    W1 = c0 / 2 + c1 * delta * c2 * (I1 - 3) * np.exp(c2 * (I1 - 3) ** 2)
    W4 = c1 * (1 - delta) * c3 * (I4 - 1) * np.exp(c3 * (I4 - 1) ** 2) if I4 > 1 else 0.0
    return (2 * W1 * (l1**2 - l3**2) + 2 * W4 * (l1 * c) ** 2, 2 * W1 * (l2**2 - l3**2) + 2 * W4 * (l2 * s) ** 2,
            2 * W4 * l1 * l2 * c * s)


#: (model, its parameters with the fibre angle given, the closed-form Cauchy stress)
#: of each law with a fibre family; the variants are HGO's aligned and dispersed
#: fibres (kappa = 0.226, the adventitia of Gasser et al. 2006), sharply or smoothly
#: switched (k = 100), and Lee-Sacks' stiffening shared mostly by the fibres or mostly by
#: the matrix.
FIBRE_LAWS = {
    "hgo_aligned": ("hgo", lambda c, s: [20e3, 50e3, 2.0, 0.0, c, s, 0.0], _hgo_cauchy),
    "hgo_dispersed": ("hgo", lambda c, s: [20e3, 50e3, 2.0, 0.226, c, s, 0.0], _hgo_cauchy),
    "hgo_dispersed_switched": ("hgo", lambda c, s: [20e3, 50e3, 2.0, 0.226, c, s, 100.0], _hgo_cauchy),
    "lee_sacks_fibres": ("lee_sacks", lambda c, s: [10e3, 2e3, 4.0, 20.0, 0.2, c, s], _lee_sacks_cauchy),
    "lee_sacks_matrix": ("lee_sacks", lambda c, s: [10e3, 2e3, 4.0, 20.0, 0.8, c, s], _lee_sacks_cauchy),
}


def _fibre_law(case: str, beta_deg: float):
    """(kernels' Material, closed-form Cauchy stress) of a :data:`FIBRE_LAWS` case."""
    model, params, cauchy = FIBRE_LAWS[case]
    beta = np.radians(beta_deg)
    return material(model)._replace(params=np.array([params(np.cos(beta), np.sin(beta))], dtype=float)), cauchy


def _stretched(mat: Material, l1: float, l2: float):
    """(S~, E) of the law at in-plane stretches l1, l2, in every lane."""
    E = np.zeros((3, 3, LANES))
    E[0, 0], E[1, 1] = (l1**2 - 1) / 2, (l2**2 - 1) / 2
    return solved_stress(mat, E)[:2]


@pytest.mark.parametrize("case", FIBRE_LAWS)
@pytest.mark.parametrize("beta_deg", [0.0, 45.0, 90.0])
@pytest.mark.parametrize("stretch", [1.01, 1.2, 1.5])
def test_fibre_laws_homogeneous_stretches_match_the_closed_form(case, beta_deg, stretch):
    """Equibiaxial stretch and uniaxial stretch along axis 1 (the lateral stress free,
    its stretch the root of sigma_22 = 0), fibres at 0, 45 and 90 degrees: the second
    Piola stress S = F^-1 sigma F^-T in every lane against the closed form to 1e-9, and the
    normal stretch 1/(l1 l2)."""
    from scipy.optimize import brentq

    mat, cauchy = _fibre_law(case, beta_deg)
    params = mat.params[0]  # the one part's
    lateral = brentq(lambda l2: cauchy(params, stretch, l2)[1], 0.3, 1.5, xtol=1e-15, rtol=1e-15)
    for l1, l2 in ((stretch, stretch), (stretch, lateral)):
        S, E = _stretched(mat, l1, l2)
        s11, s22, s12 = cauchy(params, l1, l2)
        scale = max(abs(s11), abs(s22), params[0])
        np.testing.assert_allclose(S[0, 0], s11 / l1**2, rtol=1e-9, atol=1e-12 * scale)
        np.testing.assert_allclose(S[1, 1], s22 / l2**2, rtol=1e-9, atol=1e-9 * scale)
        np.testing.assert_allclose(S[0, 1], s12 / (l1 * l2), rtol=1e-9, atol=1e-12 * scale)
        np.testing.assert_allclose(np.sqrt(1 + 2 * E[2, 2]), 1 / (l1 * l2), rtol=1e-12)


@pytest.mark.parametrize("case", ["hgo_aligned", "lee_sacks_fibres"])
def test_fibres_in_compression_carry_nothing(case):
    """Fibres along axis 1 shortened (uniaxial compression along them, no lateral stretch):
    the stress is the matrix's alone, 2 W1 (1 - l3^2 / l^2) along the fibre, with W1 at
    that state (mu/2 for HGO's aligned fibres)."""
    mat, _ = _fibre_law(case, 0.0)
    l1 = 0.9
    S, _ = _stretched(mat, l1, 1.0)
    if case.startswith("hgo"):
        np.testing.assert_allclose(S[0, 0], mat.params[0, 0] * (l1**2 - l1**-2) / l1**2, rtol=1e-12)
    else:
        c0, c1, c2, _, delta = mat.params[0, :5]
        i1 = l1**2 + 1 + l1**-2 - 3
        W1 = c0 / 2 + c1 * delta * c2 * i1 * np.exp(c2 * i1**2)
        np.testing.assert_allclose(S[0, 0], 2 * W1 * (l1**2 - l1**-2) / l1**2, rtol=1e-12)


def test_every_deck_model_of_a_law_is_a_deck_material():
    """The registry and the deck agree: the deck accepts each law's models."""
    from shellsim.deck.material import MATERIALS

    from shellsim.table_types import tag_of

    for law in LAWS:
        for model in law.MODELS:
            assert MATERIALS[tag_of(model)[1]] is model


@pytest.mark.parametrize("delta", [1.0, 0.5])
def test_an_isotropic_lee_sacks_law_is_not_refused_axes_it_does_not_need(delta):
    """Lee-Sacks at delta = 1 has no fibre term: fixed axes along the plate's normal, which
    cannot be laid in it, leave the elements' own directions (its stress takes none); at
    delta = 0.5 the fibres need them, and the axis is refused naming it."""
    from shellsim.deck import parse_deck
    from shellsim.errors import MeshError

    from .conftest import deck_text, prepared

    text = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0').replace(
        'model = "linear_elastic"\nE = 1000.0\nnu = 0.3',
        f'model = "lee_sacks"\nc0 = 10.0\nc1 = 2.0\nc2 = 4.0\nc3 = 20.0\ndelta = {delta}\n'
        'axes = { kind = "fixed", direction = [0.0, 0.0, 1.0] }')
    if delta == 1.0:
        assert prepared(parse_deck(text)).model.material.law[0] == law_of("lee_sacks")[0]
    else:
        with pytest.raises(MeshError, match="direction = \\(0, 0, 1\\) lies along the shell's normal"):
            prepared(parse_deck(text))
