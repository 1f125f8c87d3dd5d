"""A FEBio model with every part the reader maps, written here in formats 4.0 and 3.0, read
back whole: every node where the file put it, every set, each element's material axis and
thickness, every boundary value, load and curve, the chord's cable, and nothing listed but
what has no counterpart."""

from __future__ import annotations

import re

import numpy as np
import pytest

from shellsim.foreign import read_foreign

from .test_import import feb_force, feb_held, feb_set

#: The sheet: NX x NY unit squares over z = CURL x^2, quads below the top row, two
#: triangles a square in it; a chord of two trusses from the top row's middle node.
NX, NY, CURL = 4, 3, 0.1
PAPILLARY, MIDDLE = (2.0, 4.0, -2.0), (2.0, 3.5, -0.5)


def sheet_node(i: int, j: int) -> int:
    return 1 + i + j * (NX + 1)


def surface_z(x):
    return CURL * np.asarray(x) ** 2


def file_elements() -> dict[int, tuple[str, list[int]]]:
    """Shell elements by id: (kind, nodes), quads numbered from 1, triangles from 101."""
    elements = {}
    for j in range(NY):
        for i in range(NX):
            a, b, c, d = sheet_node(i, j), sheet_node(i + 1, j), sheet_node(i + 1, j + 1), sheet_node(i, j + 1)
            if j < NY - 1:
                elements[1 + i + j * NX] = ("quad4", [a, b, c, d])
            else:
                elements[101 + 2 * i] = ("tri3", [a, b, c])
                elements[102 + 2 * i] = ("tri3", [a, c, d])
    return elements


def axis_of(element: int) -> np.ndarray:
    """Each element's own material axis, in the sheet's tangent plane direction x-ish."""
    angle = 0.1 * element
    return np.array([np.cos(angle), np.sin(angle), 0.0])


def thickness_of(element: int) -> float:
    return 0.3 + 0.01 * (element % 7)


def febio_model(version: str) -> str:
    """The model as FEBio Studio saves it in format ``version``."""
    four = version.startswith("4")
    elements = file_elements()
    nodes = {sheet_node(i, j): (float(i), float(j), float(surface_z(i))) for j in range(NY + 1) for i in range(NX + 1)}
    text = lambda values: ",".join(repr(float(v)) for v in values)  # noqa: E731 - a vector as the file writes it
    middle_id, papillary_id = len(nodes) + 1, len(nodes) + 2
    nodes[middle_id], nodes[papillary_id] = MIDDLE, PAPILLARY
    top = sheet_node(NX // 2, NY)

    def element_data(kind: str, rows: str) -> str:
        return f'<ElementData {"type" if four else "var"}="{kind}" elem_set="Shells">{rows}</ElementData>'

    shells = sorted(elements)
    blocks = "".join(
        f'<Elements type="{kind}" name="{name}">'
        + "".join(f'<elem id="{e}">{",".join(map(str, elements[e][1]))}</elem>' for e in shells if elements[e][0] == kind)
        + "</Elements>" for kind, name in (("quad4", "Belly"), ("tri3", "Edge")))
    # the triangles' facets listed the other way round: the pressure must still push against each facet's normal
    facets = "".join(f'<{kind} id="{k + 1}">{",".join(map(str, nodes_ if kind == "quad4" else nodes_[::-1]))}</{kind}>'
                     for k, (kind, nodes_) in enumerate(elements[e] for e in shells))
    axes = "".join(f'<e lid="{k + 1}"><a>{text(axis_of(e))}</a><d>0,0,1</d></e>'
                   for k, e in enumerate(shells))
    thickness = "".join(f'<e lid="{k + 1}">{text([thickness_of(e)] * (3 if elements[e][0] == "tri3" else 4))}'
                        "</e>" for k, e in enumerate(shells))
    prescribed = ('<bc name="Lift" type="prescribed displacement" node_set="Papillary"><dof>z</dof>'
                  '<value lc="1">-0.5</value><relative>0</relative></bc>' if four else
                  '<bc name="Lift" type="prescribe" node_set="Papillary"><dof>z</dof><scale lc="1">-0.5</scale></bc>')
    point = "pt" if four else "point"
    curves = "".join(
        f'<load_controller id="{i}" name="{name}" type="loadcurve"><interpolate>{how}</interpolate><points>'
        + "".join(f"<{point}>{t},{v}</{point}>" for t, v in points) + "</points></load_controller>"
        for i, name, how, points in ((1, "Ramp", "LINEAR", [(0, 0), (1, 1)]),
                                     (2, "Beat", "SMOOTH", [(0, 0), (0.5, 1), (1, 1)])))
    return f'''<?xml version="1.0" encoding="ISO-8859-1"?>
<febio_spec version="{version}">
  <Module type="solid"/>
  <Control><analysis>STATIC</analysis><time_steps>10</time_steps><step_size>0.1</step_size></Control>
  <Material>
    <material id="1" name="Leaflet" type="Holzapfel-Gasser-Ogden"><density>1.1e-9</density><c>0.05</c>
      <k1>0.2</k1><k2>3</k2><kappa>0.1</kappa><gamma>30</gamma></material>
    <material id="2" name="Chorda" type="linear truss"><density>1.2e-9</density><E>40</E><v>0.5</v></material>
  </Material>
  <Mesh>
    <Nodes name="Object1">{"".join(f'<node id="{n}">{text(x)}</node>' for n, x in nodes.items())}</Nodes>
    {blocks}
    <Elements type="truss2" name="Chord"><elem id="201">{top},{middle_id}</elem><elem id="202">{middle_id},{papillary_id}</elem></Elements>
    {feb_set(version, "NodeSet", "Root", [sheet_node(i, 0) for i in range(NX + 1)], "n")}
    {feb_set(version, "NodeSet", "Papillary", [papillary_id], "n")}
    {feb_set(version, "NodeSet", "TipNode", [top], "n")}
    {feb_set(version, "ElementSet", "Centre", [2, 3], "e")}
    {feb_set(version, "ElementSet", "Shells", shells, "e")}
    <Surface name="Top">{facets}</Surface>
  </Mesh>
  <MeshDomains><ShellDomain name="Belly" mat="Leaflet"/><ShellDomain name="Edge" mat="Leaflet"/>
    <BeamDomain name="Chord" mat="Chorda" type="linear-truss"><cross_sectional_area>0.2</cross_sectional_area></BeamDomain>
  </MeshDomains>
  <MeshData>{element_data("mat_axis", axes)}{element_data("shell thickness", thickness)}</MeshData>
  <Boundary>{feb_held(version, "Root", "Root", "xyz")}
    <bc name="RootShell" type="zero shell displacement" node_set="Root"><sx_dof>1</sx_dof><sy_dof>1</sy_dof><sz_dof>1</sz_dof></bc>
    {feb_held(version, "Guide", "Papillary", "xy")}{prescribed}</Boundary>
  <Loads><surface_load type="pressure" surface="Top"><pressure lc="2">0.01</pressure></surface_load>
    {feb_force(version, "Tug", "TipNode", "x", 0.1)}</Loads>
  <LoadData>{curves}</LoadData>
  <Output><plotfile type="febio"><var type="displacement"/></plotfile></Output>
</febio_spec>
'''


def nearest(points: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each point (k, 3): the index of the nearest row of x (n, 3) and its distance."""
    distance = np.linalg.norm(points[:, None, :] - x[None, :, :], axis=2)
    return distance.argmin(axis=1), distance.min(axis=1)


def file_element_under(centre: np.ndarray) -> int:
    """The file element whose footprint in the x-y plane holds a point of the sheet."""
    i, j = int(np.floor(centre[0])), int(np.floor(centre[1]))
    if j < NY - 1:
        return 1 + i + j * NX
    return 101 + 2 * i if centre[0] - i > centre[1] - j else 102 + 2 * i  # below or above the diagonal


def assert_sheet_loads(mesh, loads: list[dict], pieces: np.ndarray) -> None:
    """The sheet's loads as both round trips give them: a pressure of 0.01 on every element
    on the curve 'Beat', pushing one way on the quads and the other on the triangles (whose
    facets the files give the other way round), and a force of 0.1 along x on the top row's
    middle node on 'Ramp'. ``pieces``: each mesh element's file element."""
    pressures = [load for load in loads if load["type"] == "pressure"]
    covered = np.concatenate([mesh.sets[load["set"]].elements for load in pressures])
    assert sorted(covered) == list(range(len(mesh.conn))) and {load["curve"] for load in pressures} == {"Beat"}
    by_value = {load["value"]: set(pieces[mesh.sets[load["set"]].elements] < 100) for load in pressures}
    assert sorted(by_value) == [-0.01, 0.01] and sorted(map(tuple, by_value.values())) == [(False,), (True,)]
    tug, = (load for load in loads if load["type"] == "point_force")
    assert (tug["value"], tug["curve"]) == ([0.1, 0.0, 0.0], "Ramp")
    assert mesh.x[mesh.sets[tug["set"]].nodes].tolist() == [[2.0, 3.0, surface_z(2.0).item()]]


@pytest.mark.parametrize("version", ["4.0", "3.0"])
def test_a_febio_model_comes_back_whole(tmp_path, version):
    path = tmp_path / "valve_patch.feb"
    path.write_text(febio_model(version))
    model = read_foreign(path)
    mesh, tables = model.mesh, model.tables
    # every node where the file put it; the new nodes on the sheet's surface away from its
    # open ends x = 0 and 4 (there the averaged normals are one element's, half a sagitta off)
    grid = np.array([(i, j, surface_z(i)) for j in range(NY + 1) for i in range(NX + 1)], dtype=float)
    file_nodes = np.vstack([grid, MIDDLE, PAPILLARY])
    found, gap = nearest(file_nodes, mesh.x)
    assert gap.max() <= 1e-12 and len(set(found)) == len(file_nodes)
    inner = np.setdiff1d(np.flatnonzero((mesh.x[:, 0] >= 1.0) & (mesh.x[:, 0] <= NX - 1.0)), found[-2:])
    np.testing.assert_allclose(mesh.x[inner, 2], surface_z(mesh.x[inner, 0]), atol=1e-3 * CURL * NX**2)
    # sets: the root row (and the new nodes between its members), the papillary point, the chosen quads' pieces
    root = mesh.sets["Root"]
    assert set(found[: NX + 1]) <= set(root.nodes) and np.abs(mesh.x[root.nodes, 1]).max() <= 1e-12
    assert len(root.nodes) == 4 * NX + 1  # the quads beside triangles split in four, each piece's edge halved
    assert mesh.x[mesh.sets["Papillary"].nodes].tolist() == [list(PAPILLARY)]
    centre = mesh.sets["Centre"]
    assert centre.kind == "surface"
    assert sorted({file_element_under(mesh.x[mesh.conn[e, 8]]) for e in centre.elements}) == [2, 3]
    pieces = np.array([file_element_under(mesh.x[c]) for c in mesh.conn[:, 8]])
    assert sorted(set(pieces)) == sorted(file_elements())
    # each piece keeps its file element's material axis; each file node its elements' mean thickness
    field = tables["material"]["axes"]["field"]
    np.testing.assert_allclose(mesh.cell_vectors[field], np.array([axis_of(e) for e in pieces]), atol=1e-12)
    assert np.all(np.isfinite(mesh.thickness))  # the chord's own nodes too (no element: 0)
    for node, index in enumerate(found[: len(grid)]):
        touching = [e for e, (_, nodes) in file_elements().items() if node + 1 in nodes]
        assert mesh.thickness[index] == pytest.approx(np.mean([thickness_of(e) for e in touching]), rel=1e-12)
    # the material, the supports and prescribed motion, the loads, the curves, the chord
    assert tables["material"] | {"axes": None} == {"model": "hgo", "mu": 0.05, "k1": 0.2, "k2": 3.0, "kappa": 0.1,
                                                  "beta_deg": 30.0, "axes": None, "density": 1.1e-9}
    boundary = {(b["type"], b["set"]): b for b in tables["boundary"]}
    assert boundary["clamped", "Root"] == {"type": "clamped", "set": "Root"}
    assert boundary["fixed", "Papillary"]["translations"] == ["x", "y"]
    assert boundary["prescribed", "Papillary"] == {"type": "prescribed", "set": "Papillary", "translation": "z",
                                                   "value": -0.5, "curve": "Ramp"}
    assert_sheet_loads(mesh, tables["load"], pieces)
    assert tables["curves"] == {"Ramp": {"t": [0.0, 1.0], "value": [0.0, 1.0]},
                                "Beat": {"t": [0.0, 0.5, 1.0], "value": [0.0, 1.0, 1.0], "interpolate": "smooth"}}
    cable, = tables["cable"]
    assert cable == {"name": "Chord_cable", "set": "Chord", "area": 0.2, "density": 1.2e-9,
                     "law": {"model": "linear", "E": 40.0}}
    np.testing.assert_allclose(mesh.x[mesh.lines], [[[2.0, 3.0, surface_z(2.0)], MIDDLE], [MIDDLE, PAPILLARY]])
    assert tables["solver"] == {"method": "static", "end_time": 1.0, "static": {"increments": 10}}
    # nothing listed but what has no counterpart: the output request, the smooth curve's
    # shape, and the triangles split into quads
    expected = [r"output requests \(<Output> \(valve_patch\.feb:\d+\)\)",
                r'<load_controller name="Beat"> \(valve_patch\.feb:\d+\): SMOOTH is brought over',
                r"8 triangle\(s\) \(first at valve_patch\.feb:\d+\): each split into three quads"]
    assert len(model.unmapped) == len(expected), model.unmapped
    assert all(any(re.search(pattern, line) for line in model.unmapped) for pattern in expected), model.unmapped


def test_each_shell_domain_s_material_comes_over_as_a_part_of_its_own(tmp_path):
    """The edge's shell domain takes a Mooney-Rivlin material of its own: two [[material]]
    tables, the HGO law on the belly's set and the Mooney-Rivlin one (c1, c2) on the
    edge's, nothing listed about a material."""
    path = tmp_path / "valve_patch.feb"
    path.write_text(febio_model("4.0").replace('<ShellDomain name="Edge" mat="Leaflet"/>',
                                               '<ShellDomain name="Edge" mat="Stiff"/>')
                    .replace("</Material>", '<material id="3" name="Stiff" type="Mooney-Rivlin"><density>1.3e-9'
                                            "</density><c1>0.4</c1><c2>0.1</c2></material></Material>"))
    model = read_foreign(path)
    belly, edge = model.tables["material"]
    assert belly["model"] == "hgo" and belly["sets"] == ["Belly"]
    assert edge == {"sets": ["Edge"], "model": "mooney_rivlin", "C1": 0.4, "C2": 0.1, "density": 1.3e-9}
    assert not [line for line in model.unmapped if "material" in line.lower()], model.unmapped
