"""The 9-node reference element: Table 2.1 as printed, nodality, partition of unity,
derivatives, Gauss rules, and the node order of gmsh's quad9 against ours."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.element.shape import NODE_RS, gauss_rule_2d, shape, shape_derivatives
from shellsim.geometry.gmsh_extract import GMSH_QUAD9, GMSH_TO_ELEMENT, extract
from shellsim.geometry.session import gmsh_session
from shellsim.mesh import element_normals

RNG = np.random.default_rng(7)
POINTS = RNG.uniform(-1, 1, size=(25, 2))


def table_2_1(r: float, s: float) -> np.ndarray:
    """Thesis Table 2.1 (Bathe 1996) with all nine nodes, transcribed literally: mid-side
    functions corrected by N9, corners by the corrected mid-side functions and N9."""
    n9 = (1 - r * r) * (1 - s * s)
    n5 = 0.5 * (1 - r * r) * (1 + s) - 0.5 * n9
    n6 = 0.5 * (1 - s * s) * (1 - r) - 0.5 * n9
    n7 = 0.5 * (1 - r * r) * (1 - s) - 0.5 * n9
    n8 = 0.5 * (1 - s * s) * (1 + r) - 0.5 * n9
    n1 = 0.25 * (1 + r) * (1 + s) - 0.5 * n5 - 0.5 * n8 - 0.25 * n9
    n2 = 0.25 * (1 - r) * (1 + s) - 0.5 * n5 - 0.5 * n6 - 0.25 * n9
    n3 = 0.25 * (1 - r) * (1 - s) - 0.5 * n6 - 0.5 * n7 - 0.25 * n9
    n4 = 0.25 * (1 + r) * (1 - s) - 0.5 * n7 - 0.5 * n8 - 0.25 * n9
    return np.array([n1, n2, n3, n4, n5, n6, n7, n8, n9])


def test_shape_functions_are_table_2_1():
    expected = np.array([table_2_1(r, s) for r, s in POINTS])
    np.testing.assert_allclose(shape(POINTS), expected, atol=1e-14)


def test_each_function_is_one_at_its_node_and_zero_at_the_others():
    np.testing.assert_allclose(shape(NODE_RS), np.eye(9), atol=1e-14)


def test_partition_of_unity_and_its_derivative():
    np.testing.assert_allclose(shape(POINTS).sum(axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(shape_derivatives(POINTS).sum(axis=1), 0.0, atol=1e-13)


def test_derivatives_match_finite_differences():
    h = 1e-6
    for k in range(2):
        step = np.zeros(2)
        step[k] = h
        fd = (shape(POINTS + step) - shape(POINTS - step)) / (2 * h)
        np.testing.assert_allclose(shape_derivatives(POINTS)[:, :, k], fd, atol=1e-8)


def test_biquadratic_fields_are_reproduced_exactly():
    def field(rs):
        r, s = rs[:, 0], rs[:, 1]
        return 1 + 2 * r - 3 * s + r * s + 0.5 * r**2 - s**2 + r**2 * s - r * s**2 + 2 * r**2 * s**2

    np.testing.assert_allclose(shape(POINTS) @ field(NODE_RS), field(POINTS), atol=1e-13)


def test_3x3_gauss_rule_integrates_degree_five_exactly():
    rs, w = gauss_rule_2d(3)
    assert w.sum() == pytest.approx(4.0)
    # int_{-1}^{1} r^4 dr = 2/5, so int r^4 s^4 = 4/25; odd powers vanish.
    assert np.sum(w * rs[:, 0] ** 4 * rs[:, 1] ** 4) == pytest.approx(4 / 25)
    assert np.sum(w * rs[:, 0] ** 5 * rs[:, 1]) == pytest.approx(0.0, abs=1e-15)


def test_gmsh_quad9_nodes_are_the_elements_nodes_with_axes_turned_half_a_turn():
    with gmsh_session() as gmsh:
        name, dim, order, n_nodes, uv, _ = gmsh.model.mesh.getElementProperties(GMSH_QUAD9)
    assert (dim, order, n_nodes) == (2, 2, 9)
    uv = np.asarray(uv).reshape(9, 2)
    # Element node k sits at gmsh node GMSH_TO_ELEMENT[k], at natural coordinates (-u, -v).
    np.testing.assert_allclose(shape(-uv[GMSH_TO_ELEMENT]), np.eye(9), atol=1e-14)


def test_gmsh_surface_normal_survives_the_node_mapping():
    """A counter-clockwise square (gmsh normal +z) gives elements whose g_r x g_s is +z."""
    with gmsh_session() as gmsh:
        geo = gmsh.model.geo
        p = [geo.addPoint(x, y, 0) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
        loop = geo.addCurveLoop([geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)])
        surface = geo.addPlaneSurface([loop])
        geo.synchronize()
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
        (normal_gmsh,) = np.asarray(gmsh.model.getNormal(surface, [0.5, 0.5])).reshape(1, 3)
        x, conn, _, _ = extract(gmsh, "square")
    normals = element_normals(x, conn, POINTS)
    assert normal_gmsh[2] == pytest.approx(1.0)
    assert np.all(normals[..., 2] > 0)
