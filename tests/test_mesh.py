"""Meshes from every builder: 9 nodes in the element's order on the exact surface, positive
Jacobians, exact areas, the right nodes in every named set, directors, and file import."""

from __future__ import annotations

import math
import signal
import threading

from pathlib import Path

import numpy as np
import pytest

from shellsim.element.shape import NODE_RS, shape, shape_derivatives
from shellsim.errors import MeshError
from shellsim.geometry import build_mesh
from shellsim.geometry.session import gmsh_session
from shellsim.mesh import jacobian_determinants, mid_surface_area

from .conftest import cylinder_stl, deck_text

T = 0.01  # section thickness of the test decks
RM = 1.0 + T / 2  # tube mid-surface radius for inner radius 1

RNG = np.random.default_rng(3)
INTERIOR = RNG.uniform(-1, 1, size=(12, 2))


def helicoid_area(length, width, twist):
    """Area of (x, w cos a, w sin a), a = twist x / length: length * int sqrt(1 + (k w)^2) dw."""
    k = twist / length
    h = width / 2
    return length * (h * math.sqrt(1 + (k * h) ** 2) + math.asinh(k * h) / k)


# builder: (geometry table, [mesh] table, exact area, distance of a point from the exact surface)
BUILDERS = {
    "rectangle": ('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', "", 2.0, lambda p: p[:, 2]),
    "cylindrical_panel": (
        'builder = "cylindrical_panel"\nradius = 25.0\nlength = 25.0\nangle_deg = 40.0',
        "divisions = { around = 4, along = 2 }", 25.0 * 25.0 * math.radians(40),
        lambda p: np.hypot(p[:, 0], p[:, 2]) - 25.0),
    "twisted_strip": (
        'builder = "twisted_strip"\nlength = 12.0\nwidth = 1.1', "divisions = { length = 8, width = 2 }",
        helicoid_area(12.0, 1.1, math.pi / 2),
        lambda p: p[:, 1] * np.sin(math.pi / 2 * p[:, 0] / 12) - p[:, 2] * np.cos(math.pi / 2 * p[:, 0] / 12)),
    "annular_sector": (
        'builder = "annular_sector"\ninner_radius = 3.0\nouter_radius = 9.0', "divisions = { around = 4, radial = 2 }",
        math.pi / 4 * (81 - 9), lambda p: p[:, 2]),
    "plate_with_hole": (
        'builder = "plate_with_hole"\nhalf_width = 0.05\nhole_radius = 0.025', "divisions = { around = 2, radial = 1 }",
        0.05**2 - math.pi * 0.025**2 / 4, lambda p: p[:, 2]),
    "tube": (
        'builder = "tube"\ninner_radius = 1.0\nlength = 4.0', "divisions = { around = 4, axial = 4 }",
        math.pi / 2 * RM * 4.0, lambda p: np.hypot(p[:, 0], p[:, 1]) - RM),
    "tube_with_cap": (
        'builder = "tube"\ninner_radius = 1.0\nlength = 4.0\ncap = "hemisphere"', "divisions = { around = 4, axial = 4 }",
        math.pi / 2 * RM * 4.0 + math.pi / 2 * RM**2,
        lambda p: np.where(p[:, 2] <= 4.0, np.hypot(p[:, 0], p[:, 1]),
                           np.linalg.norm(p - [0, 0, 4.0], axis=1)) - RM),
    "hemisphere": (
        'builder = "hemisphere"\nradius = 10.0', "divisions = { patch = 2 }", math.pi / 2 * 100.0,
        lambda p: np.linalg.norm(p, axis=1) - 10.0),
    # the zone between colatitude 18 degrees and the equator: a quarter of 2 pi R^2 cos 18
    "hemisphere with a polar hole": (
        'builder = "hemisphere"\nradius = 10.0\nhole_deg = 18.0', "divisions = { patch = 4 }",
        math.pi / 2 * 100.0 * math.cos(math.radians(18.0)), lambda p: np.linalg.norm(p, axis=1) - 10.0),
}


def build(geometry: str, mesh: str = "", extra: str = ""):
    from shellsim.deck import parse_deck

    deck = parse_deck(deck_text(geometry, f"[mesh]\n{mesh}\n{extra}").replace("thickness = 0.01", f"thickness = {T}"))
    return deck, build_mesh(deck)


@pytest.fixture(scope="module", params=list(BUILDERS))
def built(request):
    geometry, mesh, area, distance = BUILDERS[request.param]
    deck, m = build(geometry, mesh)
    return request.param, deck, m, area, distance


def test_elements_have_nine_nodes_and_positive_jacobians(built):
    _, _, mesh, _, _ = built
    assert mesh.conn.shape[1] == 9
    assert len(np.unique(mesh.conn)) == mesh.n_nodes  # every node used, numbered from 0
    assert np.all(jacobian_determinants(mesh, 3, 2) > 0)


def test_nodes_and_interpolated_points_lie_on_the_exact_surface(built):
    """Nodes are on the surface; the isoparametric map between them stays within the
    second-order geometric error, which a wrong node order would exceed by far."""
    name, _, mesh, _, distance = built
    size = np.ptp(mesh.x, axis=0).max()
    assert np.abs(distance(mesh.x)).max() < 1e-9 * size
    inside = np.einsum("qa,eai->eqi", shape(INTERIOR), mesh.x[mesh.conn]).reshape(-1, 3)
    assert np.abs(distance(inside)).max() < 2e-3 * size


def test_mid_surface_area_matches_the_exact_area(built):
    _, _, mesh, area, _ = built
    assert mid_surface_area(mesh, n_gauss=5) == pytest.approx(area, rel=1e-4)


def test_named_sets_are_the_declared_ones(built):
    _, deck, mesh, _, _ = built
    assert set(mesh.sets) == set(deck.geometry.sets()) | {"all"}


def test_directors_are_unit_surface_normals(built):
    name, _, mesh, _, _ = built
    np.testing.assert_allclose(np.linalg.norm(mesh.director, axis=1), 1.0, atol=1e-12)
    # The director at each node is normal to the surface tangents of every element there.
    g = np.einsum("qad,eai->eqdi", shape_derivatives(NODE_RS), mesh.x[mesh.conn])
    d = mesh.director[mesh.conn]
    tilt = np.abs(np.einsum("eqdi,eqi->eqd", g, d)) / np.linalg.norm(g, axis=-1)
    assert tilt.max() < 0.05  # within the interpolation error of the tangents, a few degrees


EXACT_NORMALS = {
    "cylindrical_panel": lambda p: p * [1, 0, 1] / np.hypot(p[:, 0], p[:, 2])[:, None],
    "tube": lambda p: p * [1, 1, 0] / np.hypot(p[:, 0], p[:, 1])[:, None],
    "hemisphere": lambda p: p / np.linalg.norm(p, axis=1)[:, None],
    "hemisphere with a polar hole": lambda p: p / np.linalg.norm(p, axis=1)[:, None],
    "rectangle": lambda p: np.tile([0.0, 0.0, 1.0], (len(p), 1)),
}


@pytest.mark.parametrize("name", list(EXACT_NORMALS))
def test_directors_are_the_exact_outward_normals(name):
    geometry, mesh_options, _, _ = BUILDERS[name]
    _, mesh = build(geometry, mesh_options)
    # gmsh evaluates CAD normals through an inverse parametrisation solved to about 1e-8.
    np.testing.assert_allclose(mesh.director, EXACT_NORMALS[name](mesh.x), atol=1e-7)


def on(mesh, name):
    return mesh.x[mesh.sets[name].nodes]


def test_rectangle_sets_hold_the_right_nodes():
    _, mesh = build(BUILDERS["rectangle"][0], "divisions = { length = 3, width = 2 }")
    assert np.allclose(on(mesh, "x0")[:, 0], 0.0) and len(on(mesh, "x0")) == 2 * 2 + 1
    assert np.allclose(on(mesh, "x1")[:, 0], 2.0) and len(on(mesh, "x1")) == 2 * 2 + 1
    assert np.allclose(on(mesh, "y0")[:, 1], 0.0) and len(on(mesh, "y0")) == 2 * 3 + 1
    assert np.allclose(on(mesh, "y1")[:, 1], 1.0) and len(on(mesh, "y1")) == 2 * 3 + 1
    np.testing.assert_allclose(on(mesh, "x1y1"), [[2.0, 1.0, 0.0]])
    assert len(mesh.sets["x0"].edges) == 2 and len(mesh.sets["y0"].edges) == 3


def test_tube_sets_hold_the_right_nodes():
    _, mesh = build(BUILDERS["tube_with_cap"][0], "divisions = { around = 4, axial = 3 }")
    assert np.allclose(on(mesh, "sym_x")[:, 0], 0.0) and np.allclose(on(mesh, "sym_y")[:, 1], 0.0)
    assert np.allclose(on(mesh, "z0")[:, 2], 0.0) and len(on(mesh, "z0")) == 2 * 4 + 1
    np.testing.assert_allclose(on(mesh, "pole"), [[0.0, 0.0, 4.0 + RM]], atol=1e-12)
    np.testing.assert_allclose(on(mesh, "z0_x"), [[RM, 0.0, 0.0]], atol=1e-12)
    # sym_x runs along the wall (2 x 3 + 1 nodes) and over the cap to the pole (2 arcs of
    # 2 elements, 2 more nodes each).
    assert len(on(mesh, "sym_x")) == 2 * 3 + 1 + 2 * 2 * 2
    assert len(mesh.sets["wall"].elements) == 4 * 3 and len(mesh.sets["cap"].elements) == 3 * 2 * 2


def test_plate_with_hole_sets_hold_the_right_nodes():
    _, mesh = build(BUILDERS["plate_with_hole"][0], "divisions = { around = 1, radial = 1 }")
    assert mesh.n_elements == 2
    np.testing.assert_allclose(np.hypot(*on(mesh, "hole")[:, :2].T), 0.025)
    np.testing.assert_allclose(on(mesh, "A"), [[0.025, 0, 0]], atol=1e-15)
    np.testing.assert_allclose(on(mesh, "B"), [[0, 0.025, 0]], atol=1e-15)
    np.testing.assert_allclose(on(mesh, "C"), [[0.05, 0.05, 0]], atol=1e-15)


def test_irregular_rectangle_follows_the_given_element_boundaries():
    """Thesis Figure 4.7, irregular 3-element mesh: straight edges with mid-side nodes at
    their mid-points and the centre node at the mean of the corners."""
    _, mesh = build('builder = "rectangle"\nlength = 12.0\nwidth = 1.0',
                    "divisions = { length = 3, width = 1 }\nboundaries_y0 = [0.0, 0.25, 0.75, 1.0]\n"
                    "boundaries_y1 = [0.0, 0.3333333333333333, 0.6666666666666666, 1.0]")
    corners = mesh.x[mesh.conn[:, :4]]
    bottom = sorted({round(x, 9) for x, y, _ in corners.reshape(-1, 3) if y == 0.0})
    top = sorted({round(x, 9) for x, y, _ in corners.reshape(-1, 3) if y == 1.0})
    assert bottom == [0.0, 3.0, 9.0, 12.0] and top == [0.0, 4.0, 8.0, 12.0]
    xe = mesh.x[mesh.conn]
    for edge, (a, b) in zip(range(4, 8), [(0, 1), (1, 2), (2, 3), (3, 0)]):
        np.testing.assert_allclose(xe[:, edge], 0.5 * (xe[:, a] + xe[:, b]), atol=1e-12)
    np.testing.assert_allclose(xe[:, 8], xe[:, :4].mean(axis=1), atol=1e-12)


def test_deck_points_snap_to_nodes_and_off_node_points_are_refused():
    _, mesh = build(BUILDERS["rectangle"][0], "points = { tip = [2.0, 0.5, 0.0] }")
    np.testing.assert_allclose(on(mesh, "tip"), [[2.0, 0.5, 0.0]])
    with pytest.raises(MeshError, match=r"mesh.points.tip: \[2.0, 0.3, 0.0\] is not at a node"):
        build(BUILDERS["rectangle"][0], "points = { tip = [2.0, 0.3, 0.0] }")


def test_gmsh_session_restores_the_sigint_handler_and_finalises_on_error():
    import gmsh

    def custom(signum, frame):  # pragma: no cover - never called
        pass

    previous = signal.signal(signal.SIGINT, custom)
    try:
        build(BUILDERS["tube"][0], BUILDERS["tube"][1])
        assert signal.getsignal(signal.SIGINT) is custom
        with pytest.raises(RuntimeError, match="boom"):
            with gmsh_session():
                raise RuntimeError("boom")
        assert not gmsh.isInitialized()
        assert signal.getsignal(signal.SIGINT) is custom
    finally:
        signal.signal(signal.SIGINT, previous)


def test_meshing_works_outside_the_main_thread():
    """Study workers run tasks in threads; gmsh must not touch signals there."""
    outcome = {}

    def work():
        try:
            outcome["mesh"] = build(BUILDERS["rectangle"][0])[1]
        except Exception as error:  # reported below
            outcome["error"] = error

    thread = threading.Thread(target=work)
    thread.start()
    thread.join()
    assert "error" not in outcome, outcome.get("error")
    assert outcome["mesh"].n_elements == 4


def test_mesh_vtu_round_trips_through_file_import(tmp_path):
    from shellsim.output.mesh_files import write_mesh_vtu

    _, original = build(BUILDERS["tube_with_cap"][0], BUILDERS["tube_with_cap"][1])
    write_mesh_vtu(original, tmp_path / "mesh.vtu")
    _, imported = build('builder = "file"\n' f'path = "{tmp_path / "mesh.vtu"}"')
    np.testing.assert_allclose(imported.x, original.x)
    np.testing.assert_array_equal(imported.conn, original.conn)
    np.testing.assert_allclose(imported.director, original.director)
    for name, named in original.sets.items():
        assert imported.sets[name].kind == named.kind
        np.testing.assert_array_equal(imported.sets[name].nodes, named.nodes)
        if named.kind == "edge":
            assert {frozenset(e) for e in imported.sets[name].edges.tolist()} == {
                frozenset(e) for e in named.edges.tolist()}


def test_gmsh_msh_file_with_physical_groups_imports_with_its_sets(tmp_path):
    with gmsh_session() as gmsh:
        geo = gmsh.model.geo
        p = [geo.addPoint(x, y, 0) for x, y in ((0, 0), (2, 0), (2, 1), (0, 1))]
        lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        for line in lines:
            geo.mesh.setTransfiniteCurve(line, 3)
        geo.mesh.setTransfiniteSurface(surface)
        geo.synchronize()
        gmsh.model.addPhysicalGroup(2, [surface], name="plate")
        gmsh.model.addPhysicalGroup(1, [lines[3]], name="left")
        gmsh.model.addPhysicalGroup(0, [p[2]], name="corner")
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
        gmsh.write(str(tmp_path / "plate.msh"))
    deck, mesh = build('builder = "file"\npath = "' + str(tmp_path / "plate.msh") + '"',
                       extra='[[boundary]]\ntype = "clamped"\nset = "left"\n')
    assert mesh.n_elements == 4 and mesh.sets["plate"].kind == "surface"
    assert np.allclose(on(mesh, "left")[:, 0], 0.0) and len(mesh.sets["left"].edges) == 2
    np.testing.assert_allclose(on(mesh, "corner"), [[2.0, 1.0, 0.0]])
    np.testing.assert_allclose(mesh.director, np.tile([0, 0, 1.0], (mesh.n_nodes, 1)), atol=1e-12)


def _two_patch_plate(path: Path, groups, version: float = 4.1) -> None:
    """A 2 x 1 plate of two square surfaces, 2 x 2 quad9 each, written to ``path`` in
    gmsh's file format ``version`` with physical ``groups``: (dimension, name, which)
    where which picks entities from the points, lines and surfaces."""
    with gmsh_session() as gmsh:
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        geo = gmsh.model.geo
        p = [geo.addPoint(x, y, 0) for x, y in ((0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1))]
        lines = [geo.addLine(p[i], p[(i + 1) % 6]) for i in range(6)] + [geo.addLine(p[1], p[4])]
        loops = [[lines[0], lines[6], lines[4], lines[5]], [lines[1], lines[2], lines[3], -lines[6]]]
        surfaces = [geo.addPlaneSurface([geo.addCurveLoop(loop)]) for loop in loops]
        for line in lines:
            geo.mesh.setTransfiniteCurve(abs(line), 3)
        for surface in surfaces:
            geo.mesh.setTransfiniteSurface(surface)
            geo.mesh.setRecombine(2, surface)
        geo.synchronize()
        entities = {0: p, 1: lines, 2: surfaces}
        for dim, name, which in groups:
            gmsh.model.addPhysicalGroup(dim, [entities[dim][i] for i in which], name=name)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
        gmsh.write(str(path))


@pytest.mark.parametrize("version", [4.1, 2.2])
def test_a_physical_group_over_several_entities_keeps_all_of_them(tmp_path, version):
    """Groups spanning two surfaces, two lines and two points, in gmsh's two file formats:
    every element and node of every entity is in the set (one block per entity used to
    leave only the last)."""
    path = tmp_path / "plate.msh"
    _two_patch_plate(path, [(2, "plate", [0, 1]), (1, "bottom", [0, 1]), (0, "ends", [0, 2])], version)
    _, mesh = build('builder = "file"\npath = "' + str(path) + '"')
    assert mesh.n_elements == 8
    np.testing.assert_array_equal(np.sort(mesh.sets["plate"].elements), np.arange(8))
    bottom = on(mesh, "bottom")
    assert len(bottom) == 9 and np.allclose(bottom[:, 1], 0.0) and len(mesh.sets["bottom"].edges) == 4
    np.testing.assert_allclose(np.sort(bottom[:, 0]), np.linspace(0.0, 2.0, 9), atol=1e-12)
    np.testing.assert_allclose(on(mesh, "ends")[np.argsort(on(mesh, "ends")[:, 0])], [[0, 0, 0], [2, 0, 0]],
                               atol=1e-12)


def test_one_name_on_cells_of_two_kinds_is_refused(tmp_path, monkeypatch):
    """A cell set over quad9 cells and lines (gmsh's files cannot say it, but a meshio
    mesh can) is not a set of one kind: refused with the name."""
    import meshio

    from shellsim.geometry import importing

    path = tmp_path / "plate.msh"
    _two_patch_plate(path, [(2, "plate", [0, 1])])
    m = meshio.read(path)
    m.cells.append(meshio.CellBlock("line3", np.array([[0, 1, 4]])))
    m.cell_sets = {"left": [np.array([0])] * (len(m.cells) - 1) + [np.array([0])]}
    monkeypatch.setattr(importing, "read_meshio", lambda _: m)
    with pytest.raises(MeshError, match=r"plate.msh': the name 'left' is given to edge and surface cells"):
        build('builder = "file"\npath = "' + str(path) + '"')


def test_a_file_without_quad9_is_refused_with_what_it_holds(tmp_path):
    import meshio

    meshio.write(tmp_path / "tri.vtu", meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))]))
    from shellsim.deck import parse_deck

    deck = parse_deck(deck_text('builder = "file"\npath = "tri.vtu"'), base_dir=tmp_path)
    with pytest.raises(MeshError, match=r"tri.vtu' has no 9-node quadrilaterals \(quad9\); found triangle"):
        build_mesh(deck, tmp_path)


def test_a_set_the_mesh_file_lacks_is_named_with_the_file_and_the_sets_it_has(tmp_path):
    from shellsim.output.mesh_files import write_mesh_vtu

    _, original = build(BUILDERS["rectangle"][0], BUILDERS["rectangle"][1])
    write_mesh_vtu(original, tmp_path / "plate.vtu")
    with pytest.raises(MeshError, match=r"(?s)mesh file '.*plate.vtu' does not have.*"
                                        r"boundary\[0\].set: unknown set 'x1y11'; did you mean 'x1y1'\?.*y0"):
        build('builder = "file"\npath = "' + str(tmp_path / "plate.vtu") + '"',
              extra='[[boundary]]\ntype = "clamped"\nset = "x1y11"\n')


def test_mesh_png_is_not_blank(tmp_path):
    from PIL import Image

    from shellsim.output.render import render_mesh

    _, mesh = build(BUILDERS["tube_with_cap"][0], BUILDERS["tube_with_cap"][1])
    render_mesh(mesh, tmp_path / "mesh.png", size=(400, 300))
    pixels = np.asarray(Image.open(tmp_path / "mesh.png").convert("L"), dtype=float)
    assert pixels.shape == (300, 400)
    assert pixels.std() > 20  # a blank (uniform) image has zero spread


def test_a_triangulated_cylinder_is_remeshed_into_quad9_on_its_surface(tmp_path):
    """An STL of an open cylinder (R = 1, L = 3, 128 facets around) remeshed with elements
    of 0.3: 9-node quads only, every node within 0.1% of the radius (the facets' chords
    sit 0.03% inside it), the area within 0.1% of 2 pi R L, directors pointing outward,
    and the two open ends as edge sets: the one the deck names by a point, and open_1."""
    stl = cylinder_stl(tmp_path / "cylinder.stl", 1.0, 3.0)
    _, mesh = build(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = 0.3\n'
                    'boundaries = { inlet = [1.0, 0.0, 0.0] }')
    assert mesh.conn.shape[1] == 9 and mesh.n_elements > 100
    radius = np.hypot(mesh.x[:, 0], mesh.x[:, 1])
    np.testing.assert_allclose(radius, 1.0, rtol=1e-3)
    np.testing.assert_allclose(mid_surface_area(mesh), 2 * np.pi * 3.0, rtol=1e-3)
    outward = np.einsum("ni,ni->n", mesh.director[:, :2], mesh.x[:, :2] / radius[:, None])
    assert outward.min() > 0.99
    assert {"inlet", "open_1"} <= set(mesh.sets) and "open_2" not in mesh.sets
    np.testing.assert_allclose(mesh.x[mesh.sets["inlet"].nodes, 2], 0.0, atol=1e-9)
    np.testing.assert_allclose(mesh.x[mesh.sets["open_1"].nodes, 2], 3.0, atol=1e-9)
    assert len(mesh.sets["inlet"].edges) * 2 == len(mesh.sets["inlet"].nodes)  # a closed loop of 3-node edges


def test_a_surface_needs_an_element_size_and_two_names_cannot_share_a_loop(tmp_path):
    """A surface without element_size, two boundary points finding one loop, a point far
    from every loop and a loop named 'all' are each refused with a message naming the key."""
    from shellsim.deck import parse_deck
    from shellsim.errors import DeckError

    stl = cylinder_stl(tmp_path / "cylinder.stl", 1.0, 3.0, around=32, along=8)
    with pytest.raises(DeckError, match="element_size"):
        parse_deck(deck_text(f'builder = "file"\npath = "{stl.as_posix()}"', ""))
    with pytest.raises(MeshError, match="find the same boundary loop"):
        build(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = 0.5\n'
              'boundaries = { a = [1.0, 0.0, 0.0], b = [0.0, 1.0, 0.1] }')
    # a point in other units (here mm on a surface in m) finds no loop near it
    with pytest.raises(MeshError, match=r"geometry.boundaries.inlet = \(1000, 0, 0\) is 999 from the nearest boundary "
                                        r"loop of '.*cylinder.stl' \(near \(.*\), 1.99. across\)"):
        build(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = 0.5\n'
              'boundaries = { inlet = [1000.0, 0.0, 0.0] }')
    # 'all' is every element's set, which would hide the loop's
    with pytest.raises(DeckError, match="boundaries: 'all' names the set of every element"):
        parse_deck(deck_text(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = 0.5\n'
                             'boundaries = { all = [1.0, 0.0, 0.0] }', ""))


def test_fibres_from_a_mesh_file_set_the_material_axes(tmp_path):
    """Per-element vectors in a quad9 file's cell data (written back by write_mesh_vtu)
    give material axis 1, projected on the lamina and turned by angle_deg: a plate whose
    elements carry (1, 1, 5) (mostly normal to it) gets axis 1 along (1, 1, 0) / sqrt 2,
    turned 30 degrees toward axis 2 on every layer; the same vectors stored as integers
    are read as the same directions."""
    import meshio

    from shellsim.deck import parse_deck
    from shellsim.model import build_model
    from shellsim.output.mesh_files import write_mesh_vtu

    _, plate = build('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', "divisions = { length = 2, width = 2 }")
    write_mesh_vtu(plate, tmp_path / "plate.vtu")
    written = meshio.read(tmp_path / "plate.vtu")
    written.cell_data["fibre"] = [np.tile([1.0, 1.0, 5.0], (plate.n_elements, 1))]
    written.cell_data["fibre_int"] = [np.tile([1, 1, 5], (plate.n_elements, 1))]  # stored as integers
    written.write(tmp_path / "plate.vtu")
    text = deck_text(f'builder = "file"\npath = "{(tmp_path / "plate.vtu").as_posix()}"')
    text = text.replace('model = "linear_elastic"\nE = 1000.0\nnu = 0.3',
                        'model = "guccione"\nC1 = 100.0\nC2 = 8.0\nC3 = 4.0\nC4 = 4.0\n'
                        'axes = { kind = "mesh", field = "fibre", angle_deg = 30.0 }')
    deck = parse_deck(text)
    mesh = build_mesh(deck)
    np.testing.assert_allclose(mesh.cell_vectors["fibre"], np.tile([1.0, 1.0, 5.0], (plate.n_elements, 1)))
    np.testing.assert_array_equal(mesh.cell_vectors["fibre_int"], mesh.cell_vectors["fibre"])
    axes = build_model(deck, mesh).material.axes0
    expected = np.radians(45.0 + 30.0)
    np.testing.assert_allclose(axes[..., 0, :], np.broadcast_to([np.cos(expected), np.sin(expected), 0.0], axes[..., 0, :].shape),
                               atol=1e-12)
    with pytest.raises(MeshError, match="material.axes.field = 'fibres'.*it has 'fibre', 'fibre_int'"):
        build_model(parse_deck(text.replace('field = "fibre"', 'field = "fibres"')), mesh)


def _guccione_plate(axes: str) -> str:
    """A 2 x 1 plate in z = 0 of two elements, of Guccione's law with material ``axes``."""
    text = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', "[mesh]\ndivisions = { length = 2, width = 1 }")
    return text.replace('model = "linear_elastic"\nE = 1000.0\nnu = 0.3',
                        f'model = "guccione"\nC1 = 100.0\nC2 = 8.0\nC3 = 4.0\nC4 = 4.0\naxes = {axes}')


def test_a_fibre_direction_along_the_shell_normal_is_refused_with_where():
    """Fixed axes whose direction is the plate's normal gave every point the element's own
    first direction, silently: refused, naming the key, the points and elements and a
    place. A direction 30 degrees off the normal is projected on the plate as before."""
    from shellsim.deck import parse_deck
    from shellsim.model import build_model

    text = _guccione_plate('{ kind = "fixed", direction = DIRECTION }')
    deck = parse_deck(text.replace("DIRECTION", "[0.0, 0.0, 2.0]"))
    with pytest.raises(MeshError, match=r"material.axes.direction = \(0, 0, 2\) lies along the shell's normal at "
                                        r"\d+ of \d+ points, in elements 1, 2 \(element 1 at \(0.5, 0.5, 0\)\): "
                                        "material axis 1 is its projection on the shell"):
        build_model(deck, build_mesh(deck))
    tilted = parse_deck(text.replace("DIRECTION", f"[{math.sin(math.radians(30))}, 0.0, {math.cos(math.radians(30))}]"))
    axes = build_model(tilted, build_mesh(tilted)).material.axes0
    np.testing.assert_allclose(axes[..., 0, :], np.broadcast_to([1.0, 0.0, 0.0], axes[..., 0, :].shape), atol=1e-12)


def test_a_vessel_axis_lying_in_the_shell_is_refused_and_one_across_it_is_not():
    """Cylindrical axes about x on the plate in z = 0 (the axis lies in the plate): the
    circumferential direction x cross p is the plate's normal at every point off the axis,
    and axis 1 was laid by the fallback without a word; refused, naming the elements. About
    z (across the plate), axis 1 is the circumferential direction, and the point on the
    axis (the corner at the origin) falls back as a tube's cap does."""
    from shellsim.deck import parse_deck
    from shellsim.model import build_model

    text = _guccione_plate('{ kind = "cylindrical", axis = AXIS }')
    lying = parse_deck(text.replace("AXIS", "[1.0, 0.0, 0.0]"))
    with pytest.raises(MeshError, match=r"the cylindrical material.axes' circumferential direction lies along the "
                                        r"shell's normal at \d+ of \d+ points, in elements 1, 2 .* the axis lies in "
                                        "the shell there"):
        build_model(lying, build_mesh(lying))
    across = parse_deck(text.replace("AXIS", "[0.0, 0.0, 1.0]"))
    mesh = build_mesh(across)
    axes = build_model(across, mesh).material.axes0
    position = mesh.x[mesh.conn[:, 8]]
    hoop = np.cross([0.0, 0.0, 1.0], position)
    np.testing.assert_allclose(axes[:, 4, 0, 0, :], hoop / np.linalg.norm(hoop, axis=1, keepdims=True), atol=1e-12)


def test_facets_segmentation_leaves_are_cleaned_and_a_non_manifold_edge_is_named(tmp_path):
    """A cylinder STL with what segmentation leaves in (a facet with a corner twice, one
    collapsed to a point, repeats of five facets) is remeshed as the clean file is (gmsh
    raised or hung on each); a fin on an inner edge, which makes it no surface, is refused
    naming the edge's place."""
    import meshio

    from shellsim.geometry.surfaces import clean_facets
    from shellsim.mesh_reading import read_triangles

    clean = cylinder_stl(tmp_path / "clean.stl", 1.0, 3.0, around=32, along=8)
    points, triangles = read_triangles(clean)
    lone = len(points)
    messy = np.vstack([triangles, [[triangles[0, 0], triangles[0, 0], triangles[0, 1]]], [[lone, lone, lone]],
                       triangles[:5]])
    meshio.write(tmp_path / "messy.stl", meshio.Mesh(np.vstack([points, points[:1]]), [("triangle", messy)]))
    meshes = [build(f'builder = "file"\npath = "{path.as_posix()}"\nelement_size = 0.3')[1]
              for path in (clean, tmp_path / "messy.stl")]
    assert meshes[0].n_elements == meshes[1].n_elements > 50
    np.testing.assert_allclose(mid_surface_area(meshes[1]), mid_surface_area(meshes[0]), rtol=1e-9)
    b, c = triangles[0, 1], triangles[0, 2]  # an inner edge of two facets
    fin = np.vstack([triangles, [[b, c, lone]]])
    with pytest.raises(MeshError, match=r"fin.stl' is not a surface: 1 edge\(s\) are shared by more than two facets, "
                                        r"e.g. near \("):
        clean_facets(np.vstack([points, [[5.0, 5.0, 1.0]]]), fin, tmp_path / "fin.stl")
