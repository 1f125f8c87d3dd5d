"""Load kinds as registered items: the registry's own rules, and the mapped pressure (a
follower pressure whose amplitude is a field of the mesh file) against closed forms: its
resultant and first moment on a plate, its agreement with a plain pressure for a field of
ones, and the tip deflection of a cantilever under a triangular load."""

from __future__ import annotations

import meshio
import numpy as np
import pytest
from numba import njit

from shellsim import loads
from shellsim.deck import parse_deck
from shellsim.errors import MeshError
from shellsim.geometry import build_mesh
from shellsim.model import build_model
from shellsim.output.mesh_files import write_mesh_vtu

from .conftest import deck_text, initial_external_forces, run_deck

LENGTH, WIDTH = 2.0, 1.0


def plate_file(tmp_path, divisions="length = 4, width = 2", point=None, cell=None):
    """A flat rectangle [0, LENGTH] x [0, WIDTH] written as a VTU mesh file with the scalar
    fields ``point`` (a function of the nodes' x (n, 3)) and ``cell`` (of the element
    centres (ne, 3)); its thickness is the deck's."""
    deck = parse_deck(deck_text(f'builder = "rectangle"\nlength = {LENGTH}\nwidth = {WIDTH}',
                                f"[mesh]\ndivisions = {{ {divisions} }}"))
    plate = build_mesh(deck)
    path = tmp_path / "plate.vtu"
    write_mesh_vtu(plate, path)
    written = meshio.read(path)
    del written.point_data["thickness"]  # the deck's section sets it
    if point is not None:
        written.point_data["wall_pressure"] = point(written.points)
    if cell is not None:
        written.cell_data["region_pressure"] = [cell(plate.x[plate.conn[:, 8]])]
    written.write(path)
    return path


def forces(text: str) -> tuple[np.ndarray, object]:
    """External forces (n, 3) at t = 0 on the initial shape of the deck ``text``, and its model."""
    deck = parse_deck(text)
    model = build_model(deck, build_mesh(deck))
    return initial_external_forces(model)[0], model


def mapped(path, value=1.0, field="wall_pressure") -> str:
    return deck_text(f'builder = "file"\npath = "{path.as_posix()}"',
                     f'[[load]]\ntype = "mapped_pressure"\nfield = "{field}"\nvalue = {value}\n')


def test_every_deck_table_belongs_to_one_kind_and_every_carrier_has_its_parts():
    tags = [table.model_fields["type"].annotation.__args__[0] for table in loads.TABLES]
    assert len(tags) == len(set(tags))
    for kind in loads.CARRIERS:
        assert callable(kind.add_forces) and kind.Bundle._fields
    assert loads.Loads._fields == tuple(kind.__name__.rsplit(".", 1)[1] for kind in loads.CARRIERS)


def test_a_scene_holds_only_the_kinds_it_uses_or_always_compiles_and_an_absent_kind_is_never_compiled():
    _, model = forces(deck_text(f'builder = "rectangle"\nlength = {LENGTH}\nwidth = {WIDTH}',
                                '[[load]]\ntype = "pressure"\nvalue = 1.0\n'))
    held = {name for name, bundle in model.loads._asdict().items() if bundle is not None}
    assert held == {"nodal", "pressure"} == {name for name, kind in zip(loads.Loads._fields, loads.CARRIERS)
                                             if hasattr(kind, "empty")}

    @njit
    def add_one(t, model, shape, bundle, f):
        f += bundle

    call = loads._if_present(add_one)

    @njit
    def compiled_caller(bundle, f):
        call(0.0, None, None, bundle, (f,))

    f = np.zeros(2)
    compiled_caller(None, f)
    assert add_one.signatures == [] and f.tolist() == [0.0, 0.0]
    compiled_caller(np.ones(2), f)
    assert len(add_one.signatures) == 1 and f.tolist() == [1.0, 1.0]


def test_a_linear_field_gives_the_exact_resultant_and_first_moment(tmp_path):
    """p = 2 + 3 x - y on the plate: a nodal field interpolates it exactly and the 3 x 3
    rule integrates p and x p exactly, so the forces sum to int p dA and their moment to
    int x p dA (closed forms), times the load's value."""
    path = plate_file(tmp_path, point=lambda x: 2.0 + 3.0 * x[:, 0] - x[:, 1])
    f, model = forces(mapped(path, value=-0.5))
    area = LENGTH * WIDTH
    int_p = 2.0 * area + 3.0 * WIDTH * LENGTH**2 / 2 - LENGTH * WIDTH**2 / 2
    int_xp = 2.0 * WIDTH * LENGTH**2 / 2 + 3.0 * WIDTH * LENGTH**3 / 3 - LENGTH**2 / 2 * WIDTH**2 / 2
    normal = model.d0[0]  # the plate's directors, all alike
    np.testing.assert_allclose((f @ normal).sum(), -0.5 * int_p, rtol=1e-13)
    np.testing.assert_allclose((f @ normal) @ model.x0[:, 0], -0.5 * int_xp, rtol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(f - np.outer(f @ normal, normal)), 0.0, atol=1e-13)


def test_a_field_of_ones_is_the_plain_pressure_and_an_element_field_is_piecewise(tmp_path):
    """A nodal field of ones gives the follower pressure's forces (to round-off); an
    element field gives each element its own pressure: the forces sum to sum p_e A_e."""
    path = plate_file(tmp_path, point=lambda x: np.ones(len(x)), cell=lambda c: 1.0 + c[:, 0])
    f_mapped, _ = forces(mapped(path, value=3.0))
    plain = deck_text(f'builder = "file"\npath = "{path.as_posix()}"', '[[load]]\ntype = "pressure"\nvalue = 3.0\n')
    f_plain, model = forces(plain)
    np.testing.assert_allclose(f_mapped, f_plain, rtol=0, atol=1e-14 * np.abs(f_plain).max())
    f_cells, _ = forces(mapped(path, value=3.0, field="region_pressure"))
    element_area = LENGTH * WIDTH / model.n_elements
    centres = model.x0[model.conn[:, 8], 0]
    np.testing.assert_allclose((f_cells @ model.d0[0]).sum(), 3.0 * np.sum((1.0 + centres) * element_area), rtol=1e-13)


def test_a_cantilever_under_a_triangular_load_meets_beam_theory(tmp_path):
    """A plate strip (L = 2, b = 1, h = 0.02, nu = 0) clamped at x = 0 under q(x) = q0 (1 -
    x / L), q0 b the root's load per length, solved statically: the tip deflection is
    q0 b L^4 / (30 E I) (Euler-Bernoulli, e.g. Roark's Formulas, Table 8.1 case 2a), small
    enough for the linear answer (0.4 h). Measured: +0.026% on 4 x 1 elements, +0.011% on
    8 x 1, +0.010% on 16 x 1: what is left is the shear deformation the beam leaves out,
    of order (h / L)^2 = 1e-4."""
    path = plate_file(tmp_path, divisions="length = 8, width = 1", point=lambda x: 1.0 - x[:, 0] / LENGTH)
    E, h, q0 = 1.0e6, 0.02, 1.0e-2
    text = deck_text(
        f'builder = "file"\npath = "{path.as_posix()}"',
        f'[mesh]\npoints = {{ tip = [{LENGTH}, 0.0, 0.0] }}\n'
        '[[boundary]]\ntype = "clamped"\nset = "x0"\n'
        f'[[load]]\ntype = "mapped_pressure"\nfield = "wall_pressure"\nvalue = {q0}\n'
        '[[output.probe]]\nname = "tip"\nquantity = "displacement"\nset = "tip"\ncomponent = "z"\n')
    text = text.replace("E = 1000.0\nnu = 0.3", f"E = {E}\nnu = 0.0").replace("thickness = 0.01", f"thickness = {h}")
    text = text.replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0\nstatic = { newton = "full" }')
    deck = parse_deck(text)
    run = run_deck(deck)
    inertia = WIDTH * h**3 / 12
    expected = q0 * WIDTH * LENGTH**4 / (30 * E * inertia)
    tip = run.history["tip"][-1]
    assert abs(tip / expected - 1.0) < 1e-3, (tip, expected)
    assert abs(tip) < 0.5 * h


def test_a_field_the_mesh_lacks_is_named_with_the_fields_it_has(tmp_path):
    path = plate_file(tmp_path, point=lambda x: x[:, 0])
    with pytest.raises(MeshError, match=r"load\[0\] \(mapped_pressure on 'all'\): field 'pressure_map' is not a "
                                        r"scalar field of the mesh; it has 'wall_pressure'"):
        forces(mapped(path, field="pressure_map"))
    builder = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0',
                        '[[load]]\ntype = "mapped_pressure"\nfield = "p"\n')
    with pytest.raises(MeshError, match="only a mesh file carries fields"):
        forces(builder)


def test_scalar_fields_survive_a_mesh_file_round_trip(tmp_path):
    path = plate_file(tmp_path, point=lambda x: x[:, 0] ** 2, cell=lambda c: c[:, 1])
    deck = parse_deck(mapped(path))
    mesh = build_mesh(deck)
    np.testing.assert_allclose(mesh.point_fields["wall_pressure"], mesh.x[:, 0] ** 2)
    np.testing.assert_allclose(mesh.cell_fields["region_pressure"], mesh.x[mesh.conn[:, 8], 1])
    write_mesh_vtu(mesh, tmp_path / "again.vtu")
    again = build_mesh(parse_deck(mapped(tmp_path / "again.vtu")))
    np.testing.assert_array_equal(again.point_fields["wall_pressure"], mesh.point_fields["wall_pressure"])
    np.testing.assert_array_equal(again.cell_fields["region_pressure"], mesh.cell_fields["region_pressure"])


def test_the_pressures_summed_node_by_node_over_the_threads_are_a_loop_over_the_faces_to_the_bit():
    """The follower pressures' forces (shellsim.loads.pressure.add_face_forces: the faces'
    area vectors face by face, then each node's sum over its faces in face order) equal
    those of a loop over the faces that adds each one's forces (face_forces) at its nodes
    in turn, every bit: three tables, the bottom, top and mid faces of the whole plate, so
    that every node sums faces of three tables, on a shape moved off the plane."""
    from shellsim.bundles import Shape
    from shellsim.loads.pressure import add_face_forces, face_forces

    text = deck_text(f'builder = "rectangle"\nlength = {LENGTH}\nwidth = {WIDTH}', "[mesh]\ndivisions = { length = 5, width = 3 }\n"
                     + "".join(f'[[load]]\ntype = "pressure"\nvalue = {value}\nface = "{face}"\n'
                               for value, face in ((1.5, "bottom"), (-0.7, "top"), (2.25, "mid"))))
    deck = parse_deck(text)
    model = build_model(deck, build_mesh(deck))
    faces = model.loads.pressure
    assert len(faces.elements) == 3 * model.n_elements
    rng = np.random.default_rng(3)
    shape = Shape(x=model.x0 + 0.05 * rng.standard_normal(model.x0.shape), d=model.d0.copy(), e1=model.e1f0.copy(),
                  h=model.h0 * (1.0 + 0.1 * rng.random(model.n_nodes)))
    f, g = rng.standard_normal((2, model.n_nodes, 3))  # the kinds before add onto these
    start, expected_f, expected_g = f.copy(), f.copy(), g.copy()
    add_face_forces(model.rule, model.body.conn, model.curves, 0.0, shape, faces, f, g)
    for m, element in enumerate(faces.elements):
        nodes = model.body.conn[element]
        fe, ge = expected_f[nodes], expected_g[nodes]
        face_forces(model.rule, shape.x[nodes], shape.d[nodes], shape.h[nodes], faces.face[m], faces.values[m], fe, ge)
        expected_f[nodes], expected_g[nodes] = fe, ge
    assert np.abs(f - start).min() > 0.0  # every node carries faces' forces
    np.testing.assert_array_equal(f, expected_f)
    np.testing.assert_array_equal(g, expected_g)
