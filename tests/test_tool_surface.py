"""Rigid tools read from triangulated surfaces: the signed distance against the closed
form of a box (inside, outside, by faces, edges and corners), a flat surface pushing
exactly as the analytic plane it lies in, and the file's defects named."""

from __future__ import annotations

import meshio
import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.errors import MeshError
from shellsim.geometry import build_mesh
from shellsim.loads.tool_surface import read_tool, search_grid, signed_distance
from shellsim.model import build_model

from .conftest import deck_text, initial_external_forces, problems_of
from .test_contact import PLATE, tool_forces


def write_surface(path, points, triangles):
    """Write a triangulated surface (STL or VTP by the ending) and return its path."""
    meshio.write_points_cells(path, np.asarray(points, float), [("triangle", np.asarray(triangles))]) \
        if path.suffix != ".vtp" else _write_vtp(path, points, triangles)
    return path


def _write_vtp(path, points, triangles):
    import pyvista

    faces = np.column_stack([np.full(len(triangles), 3), triangles]).ravel()
    pyvista.PolyData(np.asarray(points, float), faces).save(path)


def cube(half: float = 1.0):
    """The corners (8, 3) and twelve triangles of the cube [-half, half]^3, every normal
    facing out."""
    points = half * np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    triangles = []
    for axis in range(3):
        for sign in (-1, 1):
            square = [v for v in range(8) if points[v, axis] == sign * half]
            a, b, c, d = square[0], square[1], square[3], square[2]  # around the square
            for triangle in ([a, b, c], [a, c, d]):
                p = points[triangle]
                if np.cross(p[1] - p[0], p[2] - p[0])[axis] * sign < 0:
                    triangle = triangle[::-1]
                triangles.append(triangle)
    return points, np.array(triangles)


def box_distance(p, half):
    """The closed-form signed distance of points p (m, 3) from the box [-half, half]^3."""
    q = np.abs(p) - half
    return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)


@pytest.mark.parametrize("suffix", [".stl", ".vtp"])
def test_the_signed_distance_from_a_cube_is_the_box_distance_by_faces_edges_and_corners(suffix, tmp_path):
    """2000 points about a cube of twelve triangles, read from an STL and a VTP file:
    within the search's reach the distance is the closed form's to 1e-12 on both sides,
    by faces, edges and corners (where the pseudo-normals tell inside from outside);
    beyond it, none."""
    half, reach = 1.0, 0.5
    corners, pseudo = read_tool(write_surface(tmp_path / f"cube{suffix}", *cube(half)))
    boxes, start, entries, frame = search_grid(corners, reach)
    tool = (corners, pseudo, np.zeros(len(corners), dtype=np.int64), boxes, start, entries, frame, reach)
    points = np.random.default_rng(7).uniform(-1.6, 1.6, (2000, 3))
    exact = box_distance(points, half)
    normal = np.empty(3)
    found = np.array([signed_distance(tool, 0, tuple(p), normal) for p in points])
    near = np.abs(exact) < reach - 1e-9
    assert near.sum() > 500 and (exact[near] < 0).sum() > 200  # inside and out, edges and corners among them
    assert (np.sum(np.abs(points[near]) > half, axis=1) >= 2).sum() > 50
    np.testing.assert_allclose(found[near], exact[near], rtol=0, atol=1e-12)
    assert np.all(np.isinf(found[np.abs(exact) > reach + 1e-9]))


def test_a_flat_surface_tool_pushes_as_the_plane_it_lies_in(tmp_path):
    """Two triangles in the plane z = 0, facing +z, under the plate of
    test_contact's plane test: the same forces on the nodes and the directors as the
    analytic plane there, to 1e-10 of the push (measured 4e-11: the nearest points on the
    triangles' shared diagonal carry the round-off of a length 200 times the depth)."""
    square = write_surface(tmp_path / "floor.stl", [[-1, -1, 0], [2, -1, 0], [2, 2, 0], [-1, 2, 0]],
                           [[0, 1, 2], [0, 2, 3]])
    f_plane, g_plane, _, _ = tool_forces('shape = "plane"\nnormal = [0.0, 0.0, 1.0]', lift=-0.005)
    f, g, _, _ = tool_forces(f'shape = "surface"\nfile = "{square.as_posix()}"', lift=-0.005)
    scale = np.abs(f_plane).max()
    assert scale > 0.0
    np.testing.assert_allclose(f, f_plane, rtol=1e-12, atol=1e-10 * scale)
    np.testing.assert_allclose(g, g_plane, rtol=1e-12, atol=1e-10 * scale)


def test_a_surface_moved_by_a_curve_pushes_from_where_it_is(tmp_path):
    """The same two triangles 0.1 below the plate, moved up by 0.095 x curve(t): at t = 1
    its bottom face (z = -0.01) is 0.005 deep and every node is pushed up by k times
    that, as the plane in test_contact's first test."""
    square = write_surface(tmp_path / "floor.stl", [[-1, -1, 0], [2, -1, 0], [2, 2, 0], [-1, 2, 0]],
                           [[0, 1, 2], [0, 2, 3]])
    keys = f'shape = "surface"\nfile = "{square.as_posix()}"\npoint = [0.0, 0.0, -0.1]\nmotion = [0.0, 0.0, 0.095]'
    text = deck_text(PLATE, f'[mesh]\ndivisions = {{ length = 2, width = 2 }}\n[[contact]]\ntype = "rigid_tool"\n'
                            f'name = "tool"\n{keys}\ncurve = "lift"\n[curves.lift]\nt = [0.0, 1.0]\n'
                            'value = [0.0, 1.0]\n').replace("thickness = 0.01", "thickness = 0.02")
    from shellsim.loads import calibrate

    model = build_model(parse_deck(text), build_mesh(parse_deck(text)))
    calibrate(model, np.ones(model.n_nodes), np.ones(model.n_nodes), 1.0)
    for t, depth in ((0.0, 0.0), (1.0, 0.005)):
        f, _ = initial_external_forces(model, t)
        np.testing.assert_allclose(f[:, 2], 0.1 / (1.0 + 0.01**2) * depth, rtol=1e-9, atol=1e-18)


@pytest.mark.parametrize(("keys", "expected"), [
    ('shape = "surface"', "shape = 'surface' takes file; missing file"),
    ('shape = "plane"\nnormal = [0.0, 0.0, 1.0]\nfile = "floor.stl"', "file is not for it"),
    ('shape = "surface"\nfile = "nowhere.stl"', "contact[0].file: file 'nowhere.stl' not found"),
])
def test_a_surface_tool_the_deck_cannot_have_is_named(keys, expected):
    assert expected in problems_of(deck_text(PLATE, f'[[contact]]\ntype = "rigid_tool"\nname = "tool"\n{keys}\n'))


@pytest.mark.parametrize(("triangles", "expected"), [
    ([[0, 1, 2], [0, 3, 2]], "not consistently oriented"),
    ([[0, 1, 2], [0, 2, 3], [0, 2, 4]], "the edge between points 0 and 2 is shared by 3 triangles"),
])
def test_a_surface_without_an_inside_and_outside_is_refused(triangles, expected, tmp_path):
    points = [[-1, -1, 0], [2, -1, 0], [2, 2, 0], [-1, 2, 0], [0.5, 0.5, 1.0]]
    path = write_surface(tmp_path / "floor.stl", points, triangles)
    with pytest.raises(MeshError, match=expected):
        read_tool(path)
