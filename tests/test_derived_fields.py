"""The fields a tissue engineer plots first, derived from the stress and the fibres:
principal stresses, the stresses in a vessel's axes, each fibre family's stretch and the
wall's through-thickness stretch, against closed forms, the probes and the algebra that
ties them to the stress."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.deck import load_deck, parse_deck
from shellsim.mesh import layer_geometry
from shellsim.output.encoding import symmetric_tensors
from shellsim.output.fields import frame_fields, output_mesh
from shellsim.measures.probes import probe_value, resolve_probes

from .conftest import BASE, ROLLERS, ROOT, deck_text, prepared, problems_of, run_deck

TEST9 = ROOT / "decks" / "verification" / "test09_aorta_static.toml"
DERIVED = ["cauchy_stress", "pressure_band", "principal_stress", "vessel_stress", "fibre_stretch"]


@pytest.fixture(scope="module")
def inflated_tube():
    """Test 9's closed-end Guccione tube inflated statically, with its cells' derived
    fields in the shell view: (run, cell_data, Gauss points (ne * 9, 3) in cell order)."""
    text = TEST9.read_text().replace("[output]\n", f"[output]\nfields = {DERIVED}\n", 1)
    run = run_deck(parse_deck(text))
    assert run.status == "completed"
    model = run.model
    nq = len(model.rule.wq)
    _, cell_data = frame_fields(run.sim, output_mesh(model), DERIVED, run.deck.output.vessel_axes)
    points, _ = layer_geometry(model.x0, model.d0, model.h0, model.conn, model.rule.N[:nq], model.rule.dNr[:nq],
                               model.rule.dNs[:nq], 0.0)
    return run, cell_data, points.reshape(-1, 3)


def test_the_hoop_stress_is_the_probes_circumferential_stress(inflated_tube):
    """Two paths to the hoop stress meet: the vessel axes (the material's cylindrical axes,
    borrowed by default) projected on the current lamina, and a probe's circumferential
    component about the deck's axis, at the integration point nearest the probe's node.
    They differ by the lamina's tilt off the exact cylinder (the 2 x 8 mesh's quadratic
    arcs: about 0.005 rad there, so a few 1e-5 of the stress). The axial stress is about
    half the hoop stress, as closed ends have it."""
    run, cell_data, points = inflated_tube
    assert run.deck.output.vessel_axes == run.deck.material[0].axes
    node = run.mesh.sets["z0_x"].nodes[0]
    nearest = np.argmin(np.linalg.norm(points - run.model.x0[node], axis=1))
    probe = next(p for p in run.deck.output.probe if p.name == "stress_xx")  # hoop + radial near the x axis
    circumferential = probe.model_copy(update={"name": "hoop", "component": "circumferential"})
    (reader,) = resolve_probes([circumferential], run.mesh, run.model)
    hoop = probe_value(run.sim, reader)
    assert cell_data["hoop_stress"][nearest] == pytest.approx(hoop, rel=1e-4)
    # resultants: hoop p r_i / t, axial p r_i^2 / (r_o^2 - r_i^2), in the ratio r_i / (r_i + r_o)
    r_i, t = run.history["inner_radius"][-1], run.history["wall_thickness"][-1]
    ratio = cell_data["axial_stress"][nearest] / cell_data["hoop_stress"][nearest]
    # this coarse mesh's point stresses read 3-7% short of the resultants (docs/verification.md)
    assert ratio == pytest.approx(r_i / (2 * r_i + t), rel=0.05)


def test_vessel_and_principal_stresses_are_the_stress_in_other_axes(inflated_tube):
    """At every cell: hoop + axial + radial and the principal values each sum to the trace,
    the principal values come largest first, each with its unit direction (sigma n = s n),
    and every normal component lies between the largest and the smallest principal value."""
    _, cell_data, _ = inflated_tube
    sigma = symmetric_tensors(cell_data["cauchy_stress"])
    trace = np.trace(sigma, axis1=1, axis2=2)
    scale = np.abs(sigma).max()
    vessel = np.column_stack([cell_data[f"{name}_stress"] for name in ("hoop", "axial", "radial")])
    principal = np.column_stack([cell_data[f"principal_stress_{k}"] for k in (1, 2, 3)])
    np.testing.assert_allclose(vessel.sum(axis=1), trace, atol=1e-12 * scale)
    np.testing.assert_allclose(principal.sum(axis=1), trace, atol=1e-12 * scale)
    assert (np.diff(principal, axis=1) <= 0.0).all()
    for k in (1, 2, 3):
        n = cell_data[f"principal_direction_{k}"]
        np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-12)
        np.testing.assert_allclose(np.einsum("cij,cj->ci", sigma, n), principal[:, k - 1, None] * n, atol=1e-10 * scale)
    assert (vessel <= principal[:, :1] + 1e-12 * scale).all() and (vessel >= principal[:, 2:] - 1e-12 * scale).all()


def test_a_fibre_stretch_is_its_closed_form_under_a_homogeneous_stretch():
    """A flat HGO sheet stretched by lambda_x = 1.2, lambda_y = 0.9: each family at +-30
    degrees from x is stretched sqrt(1.2^2 cos^2 30 + 0.9^2 sin^2 30), recruited (> 1), at
    every point of both views; its written direction is F a0 over that stretch."""
    material = ('[material]\nmodel = "hgo"\nmu = 10.0\nk1 = 20.0\nk2 = 5.0\nbeta_deg = 30.0\ndensity = 1.0\n'
                'axes = { kind = "fixed", direction = [1.0, 0.0, 0.0] }\n')
    text = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0').replace(
        '[material]\nmodel = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0\n', material)
    run = prepared(parse_deck(text))
    run.sim.state.x[:] = run.model.x0 * [1.2, 0.9, 1.0]
    beta = np.radians(30.0)
    stretch = np.hypot(1.2 * np.cos(beta), 0.9 * np.sin(beta))
    for solid in (False, True):
        _, cells = frame_fields(run.sim, output_mesh(run.model, solid), ["fibres", "fibre_stretch"])
        for family, sign in ((1, 1.0), (2, -1.0)):
            np.testing.assert_allclose(cells[f"fibre_stretch_{family}"], stretch, rtol=1e-12)
            expected = np.array([1.2 * np.cos(beta), sign * 0.9 * np.sin(beta), 0.0]) / stretch
            np.testing.assert_allclose(cells[f"fibre_{family}"], np.broadcast_to(expected, cells[f"fibre_{family}"].shape),
                                       atol=1e-12)


def test_vessel_stress_asks_for_axes_it_can_use():
    """Without a tube's or centreline's axes to borrow, vessel_stress names the key to
    give; turned vessel axes are refused; fibre fields need a fibre law."""
    plate = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0')
    assert "give output.vessel_axes" in problems_of(plate + '\n[output]\nfields = ["vessel_stress"]\n')
    assert "a vessel's axes are not turned" in problems_of(
        plate + '\n[output]\nfields = ["vessel_stress"]\nvessel_axes = { kind = "cylindrical", angle_deg = 10.0 }\n')
    assert "'fibre_stretch' is of a fibre-reinforced law's fibres" in problems_of(
        plate + '\n[output]\nfields = ["fibre_stretch"]\n')
    given = parse_deck(plate + '\n[output]\nfields = ["vessel_stress"]\nvessel_axes = { kind = "cylindrical" }\n')
    assert given.output.vessel_axes.kind == "cylindrical"
    assert load_deck(TEST9).output.vessel_axes is None  # borrowed only when vessel_stress is written


def test_the_shell_view_gives_the_inner_and_outer_layers_as_the_solid_view_has_them(inflated_tube):
    """``faces``: each field at the integration layer nearest the bottom (the inner wall)
    and top face is the solid view's value on that layer, the principal and vessel
    stresses included; along the cylinder the hoop stress is larger at the inner wall, as
    in a thick tube under inner pressure (Lame)."""
    run, _, _ = inflated_tube
    model = run.model
    _, shell = frame_fields(run.sim, output_mesh(model), DERIVED, run.deck.output.vessel_axes, ("bottom", "top"))
    _, solid = frame_fields(run.sim, output_mesh(model, solid=True), DERIVED, run.deck.output.vessel_axes)
    layers = len(model.rule.tz)
    for name in ("cauchy_stress", "hoop_stress", "axial_stress", "principal_stress_1"):
        by_layer = solid[name].reshape(model.n_elements, layers, 9, *solid[name].shape[1:])
        np.testing.assert_array_equal(shell[f"{name}_bottom"], by_layer[:, 0].reshape(shell[name].shape))
        np.testing.assert_array_equal(shell[f"{name}_top"], by_layer[:, -1].reshape(shell[name].shape))
    view = output_mesh(model)
    on_cylinder = view.points[view.cells].mean(axis=1)[:, 2] < 0.025  # 15 mm from the cap's bending
    assert (shell["hoop_stress_bottom"] > shell["hoop_stress_top"])[on_cylinder].all()


def test_pk2_and_material_stresses_are_the_closed_form_and_turn_with_the_material():
    """A flat HGO sheet (families at +-30 degrees from its material axis 1 along x)
    stretched homogeneously by 1.2 x 0.9, its thickness 1 / (1.2 x 0.9) of the initial
    (incompressible): at every point of both views ``pk2_stress`` is the closed form's
    S = F^-1 sigma F^-T in material axes (tests/test_materials.py, sigma_33 = 0) and
    ``material_stress`` its sigma. Turned rigidly by 40 degrees about z and 25 about x
    after stretching, both stay as they were to round-off while ``cauchy_stress`` turns."""
    from scipy.spatial.transform import Rotation

    from .test_materials import _hgo_cauchy

    material = ('[material]\nmodel = "hgo"\nmu = 10.0\nk1 = 20.0\nk2 = 5.0\nkappa = 0.1\nbeta_deg = 30.0\ndensity = 1.0\n'
                'axes = { kind = "fixed", direction = [1.0, 0.0, 0.0] }\n')
    text = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0').replace(
        '[material]\nmodel = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0\n', material)
    run = prepared(parse_deck(text))
    beta = np.radians(30.0)
    s11, s22, _ = _hgo_cauchy([10.0, 20.0, 5.0, 0.1, np.cos(beta), np.sin(beta), 0.0], 1.2, 0.9)
    pk2 = np.array([s11 / 1.2**2, s22 / 0.9**2, 0.0, 0.0, 0.0, 0.0])
    sigma = np.array([s11, s22, 0.0, 0.0, 0.0, 0.0])
    fields = ["cauchy_stress", "pk2_stress", "material_stress"]
    turn = Rotation.from_euler("zx", [40.0, 25.0], degrees=True).as_matrix()
    for rotation in (np.eye(3), turn):
        run.sim.state.x[:] = (run.model.x0 * [1.2, 0.9, 1.0]) @ rotation.T
        run.sim.state.d[:] = run.model.d0 @ rotation.T
        run.sim.state.h[:] = run.model.h0 / (1.2 * 0.9)
        run.sim.evaluate_forces()
        for solid in (False, True):
            _, cells = frame_fields(run.sim, output_mesh(run.model, solid), fields)
            np.testing.assert_allclose(cells["pk2_stress"], np.broadcast_to(pk2, cells["pk2_stress"].shape),
                                       rtol=1e-9, atol=1e-9 * abs(pk2).max())
            np.testing.assert_allclose(cells["material_stress"], np.broadcast_to(sigma, cells["material_stress"].shape),
                                       rtol=1e-9, atol=1e-9 * abs(sigma).max())
            turned = rotation @ np.diag(sigma[:3]) @ rotation.T
            np.testing.assert_allclose(symmetric_tensors(cells["cauchy_stress"]),
                                       np.broadcast_to(turned, (len(cells["cauchy_stress"]), 3, 3)),
                                       atol=1e-9 * abs(sigma).max())


def test_material_axes_fields_ask_for_a_hyperelastic_material():
    plate = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0')
    assert ("'pk2_stress' is in the axes of a hyperelastic material (section.technique = 1), and material.model = "
            "'linear_elastic' with section.technique = None has none") in problems_of(
        plate + '\n[output]\nfields = ["pk2_stress"]\n')


def test_an_incompressible_strip_pulled_to_a_stretch_thins_to_its_inverse_root():
    """An incompressible neo-Hookean strip on rollers, its far edge pulled to a stretch
    lambda = 1.5 (a static solve): uniaxial, so its through-thickness stretch,
    ``thickness_stretch``, is lambda^(-1/2) at every point, while the unloaded strip's is 1."""
    stretch = 1.5
    text = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 0.5', f'''
[mesh]
divisions = {{ length = 2, width = 2 }}
{ROLLERS}
[[boundary]]
type = "prescribed"
set = "x1"
translation = "x"
value = {stretch - 1.0}
[output]
fields = ["displacement", "thickness_stretch"]
''', base=BASE.replace('model = "linear_elastic"\nE = 1000.0\nnu = 0.3', 'model = "neo_hookean"\nC1 = 100.0')
        .replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0'))
    run = prepared(parse_deck(text))
    mesh = output_mesh(run.model)
    np.testing.assert_allclose(frame_fields(run.sim, mesh, ["thickness_stretch"])[0]["thickness_stretch"], 1.0,
                               rtol=1e-14)
    run = run_deck(run.deck)
    points = frame_fields(run.sim, mesh, ["thickness_stretch"])[0]["thickness_stretch"]
    np.testing.assert_allclose(points, stretch**-0.5, rtol=1e-6)
