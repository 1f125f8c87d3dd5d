"""A mid-surface that passes through itself: found where two parts cross, and nowhere
else (stacked plates a gap apart, a T-junction that only touches, every shipped deck's
mesh through `check`)."""

from __future__ import annotations

import numpy as np
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.element.shape import NODE_RS
from shellsim.geometry.crossings import crossing_pairs, crossing_problem
from shellsim.verify.surfaces import tube_facets, write_facets

from .conftest import BASE, deck_text


def _plate(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A unit square in z = 0 as n x n 9-node elements: nodes (m, 3), elements (n^2, 9)."""
    side = np.linspace(0.0, 1.0, 2 * n + 1)
    x, y = np.meshgrid(side, side, indexing="ij")
    index = np.arange(x.size).reshape(x.shape)
    conn = np.array([[index[2 * a + 1 + int(r), 2 * b + 1 + int(s)] for r, s in NODE_RS]
                     for a in range(n) for b in range(n)])
    return np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]), conn


def _two(first: np.ndarray, second: np.ndarray, conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.vstack([first, second]), np.vstack([conn, conn + len(first)])


def test_a_plate_standing_through_another_crosses_it_along_their_common_line():
    """An upright plate (the plane y = 0.53, z from -0.47 to 0.53) through a flat 10 x 10
    plate: every crossing pair is one element of each, the flat one's ten elements along
    x all cross, and each crossing point lies on the line y = 0.53, z = 0."""
    flat, conn = _plate(10)
    upright = flat[:, [0, 2, 1]] + [0.0, 0.53, -0.47]
    pairs, points = crossing_pairs(*_two(flat, upright, conn))
    assert len(pairs) and np.all(pairs[:, 0] < 100) and np.all(pairs[:, 1] >= 100)
    assert len(np.unique(pairs[:, 0])) == 10
    np.testing.assert_allclose(points[:, 1:], np.tile([0.53, 0.0], (len(points), 1)), atol=1e-12)
    assert "the mid-surface passes through itself" in crossing_problem(*_two(flat, upright, conn))


def test_plates_a_gap_apart_and_a_plate_meeting_another_along_a_line_do_not_cross():
    """Two plates 1e-3 apart, a plate whose edge lies on another (a T-junction), and a
    wavy plate: nothing passes through anything."""
    flat, conn = _plate(10)
    assert crossing_problem(*_two(flat, flat + [0.0, 0.0, 1e-3], conn)) is None
    assert crossing_problem(*_two(flat, flat[:, [0, 2, 1]] + [0.0, 0.53, 0.0], conn)) is None
    wavy = flat + np.outer(np.sin(6 * flat[:, 0]) * np.sin(5 * flat[:, 1]), [0.0, 0.0, 0.05])
    assert crossing_problem(wavy, conn) is None


def test_check_warns_of_two_tubes_meshed_across_each_other(tmp_path):
    """Two tubes of radius 5 mm whose axes cross 4 mm apart, in one surface file that
    meshes cleanly: `check` says the mid-surface passes through itself and where, and still
    passes the deck (a warning: the mesh is the user's to mend)."""
    points, triangles = tube_facets(0.005, 0.005, 0.04, 48, 24)
    points = points - [0.0, 0.0, 0.02]
    across = points[:, [2, 1, 0]] + [0.0, 0.004, 0.0]
    write_facets(tmp_path / "two.stl", np.vstack([points, across]), np.vstack([triangles, triangles + len(points)]))
    deck = tmp_path / "deck.toml"
    deck.write_text(deck_text('builder = "file"\npath = "two.stl"\nelement_size = 0.003',
                              base=BASE.replace("thickness = 0.01", "thickness = 0.0005")))
    result = CliRunner().invoke(app, ["check", str(deck)])
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())
    assert "warning: the mid-surface passes through itself" in said and "move or trim one" in said
