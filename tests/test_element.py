"""The shell element's kernels against invariants: stiffness consistent with the internal
force, rigid motions free of strain, membrane and bending patch tests on a distorted
mesh, lumped masses that add up."""

from __future__ import annotations

import numpy as np
import pytest
from numba import typeof

from shellsim.bundles import Shape
from shellsim.deck import parse_deck
from shellsim.element.assembly import StiffnessProduct, _all_elements, assembly, internal_forces
from shellsim.element.static_loop import ElementLoop
from shellsim.element.steps import steps_of
from shellsim.element.masses import lumped_masses
from shellsim.element.response import response_by_address
from shellsim.compiled_call import TypedCall
from shellsim.element.frames import rotate_director
from shellsim.element.sampling import point_tensors
from shellsim.geometry import build_mesh
from shellsim.mesh import Mesh, averaged_directors
from shellsim.model import build_model
from shellsim.solver.simulation import Simulation

from .conftest import deck_text

RNG = np.random.default_rng(11)
E, NU, T = 1000.0, 0.3, 0.05


#: A Mooney-Rivlin material under Technique 1, to replace the linear one of the base deck.
MOONEY_RIVLIN = ('model = "mooney_rivlin"\nC1 = 200.0\nC2 = 50.0', "technique = 1")


def make_model(geometry: str, mesh_options: str = "", extra: str = "", material: tuple[str, str] | None = None):
    text = deck_text(geometry, f"[mesh]\n{mesh_options}\n{extra}").replace("thickness = 0.01", f"thickness = {T}")
    if material is not None:
        law, section = material
        text = text.replace('model = "linear_elastic"\nE = 1000.0\nnu = 0.3', law).replace("[section]", f"[section]\n{section}")
    deck = parse_deck(text)
    return deck, build_model(deck, build_mesh(deck))


def square_patch(skew: float = 0.0, interior: tuple[float, float] = (0.5, 0.5), material: tuple[str, str] | None = None):
    """A 2 x 2 patch of the unit square, sheared by x += skew y (elements stay
    parallelograms) and with the shared interior corner moved to ``interior`` (elements
    become general quadrilaterals); edges stay straight (mid-side nodes at mid-points,
    centres at the corner mean)."""
    deck, model = make_model('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', "divisions = { length = 2, width = 2 }",
                             material=material)
    x = model.x0.copy()
    centre = int(np.argmin(np.linalg.norm(x - [0.5, 0.5, 0.0], axis=1)))
    x[centre, :2] = interior
    conn = model.conn
    for a, (i, j) in zip(range(4, 8), [(0, 1), (1, 2), (2, 3), (3, 0)]):
        x[conn[:, a]] = 0.5 * (x[conn[:, i]] + x[conn[:, j]])
    x[conn[:, 8]] = x[conn[:, :4]].mean(axis=1)
    x[:, 0] += skew * x[:, 1]
    d = averaged_directors(x, conn)
    mesh = Mesh(x=x, conn=conn, director=d, thickness=np.full(len(x), T), sets=build_mesh(deck).sets)
    return build_model(deck, mesh)


def interior_nodes(model) -> np.ndarray:
    """Nodes off the patch boundary (the four corners of the patch are (0,0), (1,0),
    (1+skew,1), (skew,1): boundary nodes have y in {0, 1} or lie on the slanted sides)."""
    corners = model.x0[model.conn[:, :4]].reshape(-1, 3)
    y = model.x0[:, 1]
    skew = corners[:, 0][np.isclose(corners[:, 1], 1.0)].min()
    left = model.x0[:, 0] - skew * y
    return np.flatnonzero((y > 1e-9) & (y < 1 - 1e-9) & (left > 1e-9) & (left < 1 - 1e-9))


def internal(model, x, d, e1, h=None, step=None, stress=None):
    """(f, fr, stress) at positions x, directors d, fibre frames e1. h: fibre lengths (a
    copy of the initial ones by default), updated in place when the material asks; step:
    the last step's translations (incremental formulation), with ``stress`` carried."""
    n = model.n_nodes
    f, fr = np.zeros((n, 3)), np.zeros((n, 2))
    if stress is None:
        stress = np.zeros((model.n_elements, len(model.rule.wq), len(model.rule.tz), 5))
    shape = Shape(x=x, d=d, e1=e1, h=model.h0.copy() if h is None else h)
    material = model.material._replace(incremental=step is not None)
    TypedCall(internal_forces)(response_by_address(model.rule, material), (model.rule, model.body, material), shape,
                               x * 0 if step is None else step, x * 0, stress, f, fr, assembly(n, model.n_elements))
    return f, fr, stress


def stiffness(model, vu, vr, x=None, stress=None):
    """K v at positions x (the initial ones by default) under the current stress (none by
    default)."""
    n = model.n_nodes
    f, fr = np.zeros((n, 3)), np.zeros((n, 2))
    if stress is None:
        stress = np.zeros((model.n_elements, len(model.rule.wq), len(model.rule.tz), 5))
    shape = Shape(x=model.x0 if x is None else x, d=model.d0, e1=model.e1f0, h=model.h0)
    product = StiffnessProduct(response_by_address(model.rule, model.material))
    product(model.structure, shape, stress, vu, vr, f, fr, assembly(n, model.n_elements))
    return f, fr


def test_the_stiffness_product_runs_on_the_time_loops_compiled_element_loop():
    """The critical step's K v product calls the time loop's parallel element loop from
    Python with the argument types the time loop gives it, so that it runs the loop's one
    compiled version (an argument typed differently would compile that loop again). The
    types are compared, not the compiled versions: with a warm cache the time loop is
    loaded whole and the loop is never loaded on its own."""
    _, model = make_model('builder = "tube"\ninner_radius = 1.0\nlength = 1.0', "divisions = { around = 4, axial = 3 }",
                          material=MOONEY_RIVLIN)
    sim = Simulation(model)
    assert sim.critical_time_step() > 0.0
    fields, space = sim.state.fields, sim.workspace
    time_loop = (sim.response, steps_of(model.material, np.bool_(False)), model.rule, model.body, model.material,
                 fields.shape, space.dx, space.dd, fields.stress, fields.f_int, fields.fr_int, space.parts)
    product = sim.compiled.stiffness._elements  # noqa: SLF001 (the product's one call of the loop)
    assert product.entry_point is _all_elements.overloads[tuple(typeof(a) for a in time_loop)].entry_point


def test_the_element_loop_from_python_gives_the_time_loops_forces_to_the_bit():
    """The compiled time loop's parallel loop and the loop Python calls (groups over
    threads) share the group run and the nodal sums: the same bits, the fibre-length update
    included (a Mooney-Rivlin tube of 12 elements: one full group and one partial). Over
    one thread and two: tests/test_threads.py."""
    _, model = make_model('builder = "tube"\ninner_radius = 1.0\nlength = 1.0', "divisions = { around = 4, axial = 3 }",
                          material=MOONEY_RIVLIN)
    x, d, e1 = moved(model, 0.05, RNG.standard_normal((model.n_nodes, 3)), RNG.standard_normal((model.n_nodes, 2)))
    n = model.n_nodes
    f, fr, stress = internal(model, x, d, e1, h=model.h0.copy())
    h, f_loop, fr_loop = model.h0.copy(), np.zeros((n, 3)), np.zeros((n, 2))
    stress_loop = np.zeros_like(stress)
    ElementLoop(response_by_address(model.rule, model.material)).forces(
        model.structure, Shape(x=x, d=d, e1=e1, h=h), x * 0, x * 0, stress_loop, f_loop, fr_loop, assembly(n, model.n_elements))
    assert np.abs(f).max() > 0.0 and not np.array_equal(h, model.h0)
    for ours, theirs in ((f_loop, f), (fr_loop, fr), (stress_loop, stress)):
        np.testing.assert_array_equal(ours, theirs)


def initial_shape(model) -> Shape:
    return Shape(x=model.x0, d=model.d0, e1=model.e1f0, h=model.h0)


def moved(model, eps, vu, vr):
    """Configuration after translations eps vu and rotations eps vr from the initial one."""
    x = model.x0 + eps * vu
    d, e1 = model.d0.copy(), model.e1f0.copy()
    for node in range(model.n_nodes):
        rotate_director(d[node], e1[node], eps * vr[node, 0], eps * vr[node, 1])
    return x, d, e1


@pytest.fixture(scope="module", params=[False, True], ids=["shell", "plane_strain"])
def curved(request):
    """One distorted curved element: a cylindrical panel with its centre node moved; as a
    shell, and in plane strain (where the volumetric strain is projected)."""
    section = f"thickness = {T}" + ("\nplane_strain = true" if request.param else "")
    text = deck_text('builder = "cylindrical_panel"\nradius = 2.0\nlength = 1.0\nangle_deg = 40.0',
                     "[mesh]\ndivisions = { around = 1, along = 1 }").replace("thickness = 0.01", section)
    deck = parse_deck(text)
    mesh = build_mesh(deck)
    x = mesh.x.copy()
    x[mesh.conn[0, 8]] += [0.03, 0.02, -0.01]
    distorted = Mesh(x=x, conn=mesh.conn, director=averaged_directors(x, mesh.conn),
                     thickness=mesh.thickness, sets=mesh.sets)
    return build_model(deck, distorted)


def test_stiffness_is_the_derivative_of_the_internal_force(curved):
    model = curved
    vu = RNG.standard_normal((model.n_nodes, 3))
    vr = RNG.standard_normal((model.n_nodes, 2))
    ku, kr = stiffness(model, vu, vr)
    h = 1e-6
    fp, frp, _ = internal(model, *moved(model, h, vu, vr))
    fm, frm, _ = internal(model, *moved(model, -h, vu, vr))
    scale = max(np.abs(ku).max(), np.abs(kr).max())
    np.testing.assert_allclose((fp - fm) / (2 * h), ku, atol=1e-6 * scale)
    np.testing.assert_allclose((frp - frm) / (2 * h), kr, atol=1e-6 * scale)


def test_stiffness_is_symmetric(curved):
    model = curved
    a = RNG.standard_normal((model.n_nodes, 3)), RNG.standard_normal((model.n_nodes, 2))
    b = RNG.standard_normal((model.n_nodes, 3)), RNG.standard_normal((model.n_nodes, 2))
    ka, kb = stiffness(model, *a), stiffness(model, *b)
    assert np.sum(b[0] * ka[0]) + np.sum(b[1] * ka[1]) == pytest.approx(np.sum(a[0] * kb[0]) + np.sum(a[1] * kb[1]), rel=1e-10)


def test_small_displacements_give_internal_force_k_u(curved):
    model = curved
    vu = RNG.standard_normal((model.n_nodes, 3))
    vr = RNG.standard_normal((model.n_nodes, 2))
    eps = 1e-7
    f, fr, _ = internal(model, *moved(model, eps, vu, vr))
    ku, kr = stiffness(model, vu, vr)
    np.testing.assert_allclose(f, eps * ku, atol=1e-5 * eps * np.abs(ku).max())
    np.testing.assert_allclose(fr, eps * kr, atol=1e-5 * eps * np.abs(ku).max())


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


@pytest.mark.parametrize("angle", np.linspace(0.0, 2 * np.pi, 9))
def test_rigid_motion_creates_no_strain_and_no_force(curved, angle):
    model = curved
    R = rotation(RNG.standard_normal(3), angle)
    x = model.x0 @ R.T + RNG.standard_normal(3)
    f, fr, stress = internal(model, x, model.d0 @ R.T, model.e1f0 @ R.T)
    assert np.abs(stress).max() < 1e-9 * E
    assert np.abs(f).max() < 1e-9 * E * T and np.abs(fr).max() < 1e-9 * E * T


STRAIN = np.array([[2e-7, 0.5e-7, 0.0], [0.5e-7, -1e-7, 0.0], [0.0, 0.0, 0.0]])


def membrane_patch(model):
    """Internal forces and stresses of the patch stretched uniformly by STRAIN; the
    interior residual relative to the largest nodal force."""
    x = model.x0 + model.x0 @ STRAIN.T
    f, fr, stress = internal(model, x, model.d0, model.e1f0)
    inner = interior_nodes(model)
    assert len(inner) == 9
    return stress, np.abs(f[inner]).max() / np.abs(f).max()


def uniform_plane_stress(model, stress):
    """The stress is the plane-stress law applied to STRAIN at every point (compared by the
    invariants of the in-plane stress: the lamina axes need not be x, y)."""
    expected = model.material.C[0] @ np.array([STRAIN[0, 0], STRAIN[1, 1], 2 * STRAIN[0, 1], 0.0, 0.0])
    s11, s22, s12 = stress[..., 0], stress[..., 1], stress[..., 2]
    np.testing.assert_allclose(s11 + s22, expected[0] + expected[1], rtol=1e-5)
    np.testing.assert_allclose(s11 * s22 - s12**2, expected[0] * expected[1] - expected[2] ** 2, rtol=1e-5)


def test_membrane_patch_test_on_a_skewed_mesh():
    model = square_patch(skew=0.3)
    stress, residual = membrane_patch(model)
    uniform_plane_stress(model, stress)
    assert residual < 1e-6


@pytest.mark.parametrize("turn", [0.0, 0.5 * np.pi, 2.0])
def test_point_tensors_are_the_plane_stress_law_and_the_exact_strain_in_global_axes(turn):
    """The tensors written to probes and frames (lamina stress turned by the lamina frame;
    Green-Lagrange strain from the geometry) on the stretched skewed patch, and on the same
    state turned rigidly about z by ``turn``: R sigma R^T with sigma the plane-stress law of
    STRAIN in x, y at every point; E = (F^T F - I) / 2 with F = R (I + STRAIN), unchanged by
    the rotation."""
    model = square_patch(skew=0.3)
    R = rotation(np.array([0.0, 0.0, 1.0]), turn)
    x, d = (model.x0 + model.x0 @ STRAIN.T) @ R.T, model.d0 @ R.T
    _, _, stress = internal(model, x, d, model.e1f0 @ R.T)
    law = model.material.C[0] @ np.array([STRAIN[0, 0], STRAIN[1, 1], 2 * STRAIN[0, 1], 0.0, 0.0])
    sigma = np.array([[law[0], law[2], 0.0], [law[2], law[1], 0.0], [0.0, 0.0, 0.0]])
    out = [np.empty((model.n_elements, 9, len(model.rule.tz), 3, 3)) for _ in range(3)]
    point_tensors((x, d, model.h0), model.conn, (model.rule.N[:9], model.rule.dNr[:9], model.rule.dNs[:9], model.rule.tz),
                  model.body.jac0_inv, stress, tuple(out))
    lamina, cauchy, green = out
    np.testing.assert_allclose(cauchy, np.broadcast_to(R @ sigma @ R.T, cauchy.shape), atol=1e-6 * np.abs(law).max())
    F = np.eye(3) + STRAIN
    np.testing.assert_allclose(green, np.broadcast_to(0.5 * (F.T @ F - np.eye(3)), green.shape), atol=1e-13)
    np.testing.assert_allclose(np.einsum("epkii->epk", lamina), np.einsum("epkii->epk", cauchy), atol=1e-9 * np.abs(law).max())


def test_rigid_rotation_gives_zero_green_lagrange_strain_everywhere(curved):
    """A large rigid rotation of the distorted curved element (directors carried along)
    produces no Green-Lagrange strain at any integration point."""
    model = curved
    R = rotation(np.array([0.3, -0.5, 0.8]), 2.4)
    out = [np.empty((model.n_elements, 9, len(model.rule.tz), 3, 3)) for _ in range(3)]
    point_tensors((model.x0 @ R.T + [1.0, -2.0, 3.0], model.d0 @ R.T, model.h0), model.conn,
                  (model.rule.N[:9], model.rule.dNr[:9], model.rule.dNs[:9], model.rule.tz), model.body.jac0_inv,
                  np.zeros((model.n_elements, 9, len(model.rule.tz), 5)), tuple(out))
    assert np.abs(out[2]).max() < 1e-12


def test_membrane_patch_test_on_general_quadrilaterals_converges():
    """Assumed (tied) membrane strains are exact on parallelograms; on general
    quadrilaterals the uniform state is reproduced point by point but the interior
    equilibrium carries an error that vanishes as the distortion shrinks (MITC-type
    elements pass the patch test in this weak sense)."""
    errors = []
    for offset in (0.08, 0.02):
        model = square_patch(interior=(0.5 + offset, 0.5 - 1.1 * offset))
        stress, residual = membrane_patch(model)
        uniform_plane_stress(model, stress)
        errors.append(residual)
    assert errors[0] < 1e-3
    assert errors[1] < errors[0] / 16  # at least second order in the distortion


def test_bending_patch_test_on_a_skewed_mesh():
    """Constant curvature, w = (kx x^2 + ky y^2 + 2 kxy x y)/2 with the directors tilted by
    grad w (no transverse shear): K v vanishes at every interior node.

    Done on the linearised operator K (a state this small would drown in the round-off
    of total strains), on a skewed patch of parallelograms: a 9-node Lagrangian element
    holds every quadratic of x, y only on an affine map, and constant curvature needs a
    quadratic deflection."""
    model = square_patch(skew=0.3)
    kx, ky, kxy = 2.0, -1.0, 0.7
    X, Y = model.x0[:, 0], model.x0[:, 1]
    vu = np.zeros_like(model.x0)
    vu[:, 2] = 0.5 * (kx * X**2 + ky * Y**2 + 2 * kxy * X * Y)
    tilt = np.column_stack([-(kx * X + kxy * Y), -(ky * Y + kxy * X), np.zeros_like(X)])
    e2 = np.cross(model.d0, model.e1f0)
    vr = np.column_stack([-np.einsum("ni,ni->n", tilt, model.e1f0), -np.einsum("ni,ni->n", tilt, e2)])
    f, fr = stiffness(model, vu, vr)
    inner = interior_nodes(model)
    assert len(inner) == 9
    scale = max(np.abs(f).max(), np.abs(fr).max())
    assert np.abs(f[inner]).max() < 1e-9 * scale and np.abs(fr[inner]).max() < 1e-9 * scale


@pytest.mark.parametrize("mass", ["M1", "M2"])
def test_lumped_masses_add_up_and_are_positive(curved, mass):
    model = curved
    n = model.n_nodes
    mt, mr = np.zeros(n), np.zeros(n)
    lumped_masses(model.rule, model.body, initial_shape(model), np.full(model.n_elements, 7.0), mass == "M1", mt, mr)
    volume = np.sum(1.0 / np.abs(np.linalg.det(model.body.jac0_inv[:, :9])) * model.rule.wq[None, :, None] * model.rule.wt[None, None, :])
    assert mt.sum() == pytest.approx(7.0 * volume, rel=1e-12)
    assert np.all(mt > 0) and np.all(mr > 0)


def test_m2_masses_of_a_rectangle_are_the_tensor_product_of_simpson_weights():
    _, model = make_model('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', "divisions = { length = 1, width = 1 }")
    n = model.n_nodes
    mt, mr = np.zeros(n), np.zeros(n)
    lumped_masses(model.rule, model.body, initial_shape(model), np.ones(model.n_elements), False, mt, mr)
    total = 2.0 * 1.0 * T
    np.testing.assert_allclose(mt[model.conn[0]], total * np.array([1, 1, 1, 1, 4, 4, 4, 4, 16]) / 36, rtol=1e-12)
    np.testing.assert_allclose(mr / mt, T**2 / 12, rtol=1e-12)  # director inertia of the fibre


@pytest.mark.parametrize("geometry, divisions", [
    ('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', "divisions = { length = 1, width = 1 }"),
    ('builder = "rectangle"\nlength = 2.0\nwidth = 2.0', "divisions = { length = 2, width = 2 }"),
    ('builder = "cylindrical_panel"\nradius = 2.0\nlength = 1.0\nangle_deg = 40.0', "divisions = { around = 1, along = 1 }"),
])
def test_only_rigid_motions_have_zero_energy(geometry, divisions):
    """Six zero eigenvalues of the free stiffness: no spurious (hourglass) modes. Sampling
    all membrane strains at one shared 2 x 2 set would leave three on a flat element."""
    _, model = make_model(geometry, divisions)
    n = model.n_nodes
    K = np.empty((5 * n, 5 * n))
    for column in range(5 * n):
        unit = np.zeros(5 * n)
        unit[column] = 1.0
        f, fr = stiffness(model, unit[:3 * n].reshape(n, 3).copy(), unit[3 * n:].reshape(n, 2).copy())
        K[:, column] = np.concatenate([f.ravel(), fr.ravel()])
    eigenvalues = np.abs(np.linalg.eigvalsh(0.5 * (K + K.T)))
    assert np.sum(eigenvalues < 1e-9 * eigenvalues.max()) == 6


def hyperelastic_state(model, x, d, e1):
    """(lamina stresses (ne, nq, nt, 5), updated fibre lengths (n,)) at positions x."""
    h = model.h0.copy()
    return internal(model, x, d, e1, h=h)[2], h


def test_hyperelastic_stress_ignores_a_rigid_rotation():
    """A Mooney-Rivlin element stretched in its plane (1.3 x 0.9), then turned rigidly by
    1 rad about a skew axis: the lamina stresses are the same (they live in the rotating
    lamina frame, Technique 1), nonzero, and so is the fibre length."""
    _, model = make_model('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', "divisions = { length = 1, width = 1 }",
                          material=MOONEY_RIVLIN)
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(1.0) * K + (1 - np.cos(1.0)) * K @ K
    stretched = model.x0 * [1.3, 0.9, 1.0]
    still, h_still = hyperelastic_state(model, stretched, model.d0, model.e1f0)
    turned, h_turned = hyperelastic_state(model, stretched @ R.T, model.d0 @ R.T, model.e1f0 @ R.T)
    assert np.abs(still[..., :3]).max() > 10.0
    np.testing.assert_allclose(turned, still, atol=1e-9 * np.abs(still).max())
    np.testing.assert_allclose(h_turned, h_still, rtol=1e-12)


@pytest.mark.parametrize("interior", [(0.5, 0.5), (0.62, 0.41)])
@pytest.mark.parametrize("stretch", [1.5, 3.26])
def test_mooney_rivlin_patch_follows_the_exact_homogeneous_stretches(interior, stretch):
    """Uniaxial (lambda, lambda^-1/2) and equibiaxial stretches of a 2 x 2 patch, regular
    and distorted, up to lambda = 3.26 (Green-Lagrange 4.8, thesis Test 8): Cauchy stress
    sigma = lambda P with P of benchmarks.md 8B at every integration point, the other
    principal stress zero, and fibre lengths t0 lambda_3 (lambda^-1/2, lambda^-2)."""
    C1, C2 = 200.0, 50.0
    model = square_patch(interior=interior, material=MOONEY_RIVLIN)
    lam = stretch
    cases = [((lam, lam**-0.5), (lam * 2 * (lam - lam**-2) * (C1 + C2 / lam), 0.0), lam**-0.5),
             ((lam, lam), (lam * 2 * (lam - lam**-5) * (C1 + C2 * lam**2),) * 2, lam**-2)]
    for (sx, sy), expected, thickness_stretch in cases:
        stress, h = hyperelastic_state(model, model.x0 * [sx, sy, 1.0], model.d0, model.e1f0)
        s11, s22, s12 = stress[..., 0], stress[..., 1], stress[..., 2]
        mean, radius = 0.5 * (s11 + s22), np.sqrt(0.25 * (s11 - s22) ** 2 + s12**2)
        scale = max(expected)
        np.testing.assert_allclose(mean + radius, max(expected), rtol=1e-9)
        np.testing.assert_allclose(mean - radius, min(expected), atol=1e-9 * scale)
        np.testing.assert_allclose(stress[..., 3:], 0.0, atol=1e-9 * scale)
        np.testing.assert_allclose(h, T * thickness_stretch, rtol=1e-9)


#: A fibre law's deck table, one family at 30 degrees from x (Lee-Sacks; HGO's two at
#: +-30, switched on smoothly), and its closed form's parameters given the family's (cos,
#: sin).
FIBRE_PATCH_LAWS = {
    "hgo": ('model = "hgo"\nmu = 20e3\nk1 = 50e3\nk2 = 2.0\nkappa = 0.1\nbeta_deg = 30.0\nswitch_sharpness = 100.0',
            lambda c, s: [20e3, 50e3, 2.0, 0.1, c, s, 100.0]),
    "lee_sacks": ('model = "lee_sacks"\nc0 = 10e3\nc1 = 2e3\nc2 = 4.0\nc3 = 20.0\ndelta = 0.3\nbeta_deg = 30.0',
                  lambda c, s: [10e3, 2e3, 4.0, 20.0, 0.3, c, s]),
}


@pytest.mark.parametrize("interior", [(0.5, 0.5), (0.62, 0.41)])
@pytest.mark.parametrize("model", FIBRE_PATCH_LAWS)
def test_fibre_law_patch_follows_the_exact_homogeneous_stretches(model, interior):
    """The anisotropic laws on a 2 x 2 patch, regular and distorted, material axis 1
    along x: stretched homogeneously (1.3 x 1.1, 1.4 x 0.8, 1.2 x 1.2), the principal
    Cauchy stresses at every integration point meet the closed form of
    tests/test_materials.py to 1e-9, and the fibre lengths follow 1/(l1 l2)."""
    from .test_materials import _hgo_cauchy, _lee_sacks_cauchy

    law, constants = FIBRE_PATCH_LAWS[model]
    table = law + '\naxes = { kind = "fixed", direction = [1.0, 0.0, 0.0] }'
    patch = square_patch(interior=interior, material=(table, ""))
    cauchy = _hgo_cauchy if model == "hgo" else _lee_sacks_cauchy
    params = np.array(constants(np.cos(np.radians(30.0)), np.sin(np.radians(30.0))))
    for l1, l2 in ((1.3, 1.1), (1.4, 0.8), (1.2, 1.2)):
        stress, h = hyperelastic_state(patch, patch.x0 * [l1, l2, 1.0], patch.d0, patch.e1f0)
        s11, s22, s12 = cauchy(params, l1, l2)
        mean, radius = 0.5 * (s11 + s22), np.hypot(0.5 * (s11 - s22), s12)
        got_mean = 0.5 * (stress[..., 0] + stress[..., 1])
        got_radius = np.hypot(0.5 * (stress[..., 0] - stress[..., 1]), stress[..., 2])
        scale = abs(mean) + radius
        np.testing.assert_allclose(got_mean + got_radius, mean + radius, rtol=1e-9, atol=1e-9 * scale)
        np.testing.assert_allclose(got_mean - got_radius, mean - radius, rtol=1e-9, atol=1e-9 * scale)
        np.testing.assert_allclose(stress[..., 3:], 0.0, atol=1e-9 * scale)
        np.testing.assert_allclose(h, T / (l1 * l2), rtol=1e-9)


def technique_model(technique: int, interior: tuple[float, float]):
    law = 'model = "linear_elastic"\nE = 1000.0\nnu = 0.3'
    return square_patch(interior=interior, material=(law, f"technique = {technique}"))


@pytest.mark.parametrize("interior", [(0.5, 0.5), (0.62, 0.41)])
@pytest.mark.parametrize("technique", [2, 3])
def test_constant_tensor_techniques_follow_their_exact_homogeneous_response(technique, interior):
    """Techniques 2 and 3 (a constant tensor at large strain) stretched step by step to
    lambda = 3.26 (Green-Lagrange 4.8) on a regular and a distorted patch. In the limit of
    small steps, with x = ln lambda and lateral stretches lambda^-nu (uniaxial: the free
    edge carries no stress), their laws integrate in closed form (docs/theory.md):
      Technique 3: uniaxial sigma = E x, equibiaxial sigma = E x / (1 - nu);
      Technique 2: uniaxial sigma = E (lambda^(1+2nu) - 1) / (1 + 2nu),
                   equibiaxial sigma = E (lambda^(2nu/(1-nu)) - 1) / (2 nu);
    the fibre length follows lambda_3 = lambda^-nu (uniaxial), lambda^(-2nu/(1-nu)).
    The steps' error is O(1 / steps): 0.07% with 1000 steps, 0.018% with 4000."""
    Em, nu, top, steps = 1000.0, 0.3, 3.26, 2000
    model = technique_model(technique, interior)
    x_end = np.log(top)
    exact = {
        (3, "uniaxial"): Em * x_end, (3, "equibiaxial"): Em * x_end / (1 - nu),
        (2, "uniaxial"): Em * (top ** (1 + 2 * nu) - 1) / (1 + 2 * nu),
        (2, "equibiaxial"): Em * (top ** (2 * nu / (1 - nu)) - 1) / (2 * nu),
    }
    for case, lateral, normal in (("uniaxial", -nu, -nu), ("equibiaxial", 1.0, -2 * nu / (1 - nu))):
        h = model.h0.copy()
        stress = np.zeros((model.n_elements, len(model.rule.wq), len(model.rule.tz), 5))
        previous = model.x0.copy()
        for x in np.linspace(0.0, x_end, steps + 1)[1:]:
            current = model.x0 * [np.exp(x), np.exp(lateral * x), 1.0]
            internal(model, current, model.d0, model.e1f0, h=h, step=current - previous, stress=stress)
            previous = current
        s11, s22, s12 = stress[..., 0], stress[..., 1], stress[..., 2]
        mean, radius = 0.5 * (s11 + s22), np.sqrt(0.25 * (s11 - s22) ** 2 + s12**2)
        expected = exact[technique, case]
        np.testing.assert_allclose(mean + radius, expected, rtol=1e-3)
        np.testing.assert_allclose(mean - radius, expected if case == "equibiaxial" else 0.0, rtol=1e-3, atol=1e-3 * expected)
        np.testing.assert_allclose(h, T * top**normal, rtol=1e-3)


def test_tangent_with_initial_stress_is_the_derivative_of_the_force_when_stretched():
    """At a Mooney-Rivlin element stretched 1.3 x 0.9, K v (the pushed-forward tangent plus
    the initial-stress part of the current stress) is the derivative of the internal
    force along a random translational field; the material part alone misses by 22%."""
    _, model = make_model('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', "divisions = { length = 1, width = 1 }",
                          material=MOONEY_RIVLIN)
    x = model.x0 * [1.3, 0.9, 1.0]
    vu = RNG.standard_normal((model.n_nodes, 3))
    vr = np.zeros((model.n_nodes, 2))

    def force(positions):
        return internal(model, positions, model.d0, model.e1f0)[0]

    stress = internal(model, x, model.d0, model.e1f0)[2]
    eps = 1e-6
    derivative = (force(x + eps * vu) - force(x - eps * vu)) / (2 * eps)
    f, _ = stiffness(model, vu, vr, x=x, stress=stress)
    np.testing.assert_allclose(f, derivative, atol=1e-7 * np.abs(derivative).max())


def test_m2_rotary_inertia_does_not_depend_on_the_thickness_rule():
    """Flat plate: M2's director masses with 1, 2 and 3 points through the thickness are
    the same (the 1-point rule alone would give none: t = 0)."""
    masses = []
    for points in (1, 2, 3):
        _, model = make_model('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', "divisions = { length = 2, width = 2 }",
                              material=('model = "linear_elastic"\nE = 1000.0\nnu = 0.3',
                                        f"points_through_thickness = {points}"))
        mt, mr = np.empty(model.n_nodes), np.empty(model.n_nodes)
        lumped_masses(model.rule, model.body, initial_shape(model), np.ones(model.n_elements), False, mt, mr)
        masses.append(mr)
    assert masses[1].min() > 0.0
    np.testing.assert_allclose(masses[0], masses[1], rtol=1e-12)
    np.testing.assert_allclose(masses[2], masses[1], rtol=1e-12)
