"""Models brought over from Abaqus input files: the mesh made 9-node, the sets, supports,
loads, materials and steps mapped, what does not map listed with its line; checked on
closed forms (a cantilever's tip deflection, a cylinder's radius, pressure resultants)."""

from __future__ import annotations

import os
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.deck import load_deck, parse_deck
from shellsim.errors import MeshError
from shellsim.foreign import abaqus_model, read_foreign
from shellsim.foreign.quad_upgrade import split, upgrade
from shellsim.imported_deck import deck_text, import_model
from shellsim.geometry import build_mesh
from shellsim.geometry.importing import read_mesh
from shellsim.model import build_model

from .conftest import initial_external_forces, run_deck


def strip_inp(tip_force: float = -1e-3, extra_model: str = "", extra_step: str = "", reversed_elements: tuple = (),
              triangles: int = 0, nx: int = 10, ny: int = 2) -> str:
    """An Abaqus input of a cantilever strip as CAE writes one: a part of S4R elements
    placed by an instance shifted 5 along x, an assembly-level node set clamped, a force
    on each tip node ramped by an amplitude in a static step. L = 10, b = 1, t = 0.1,
    E = 2e5, nu = 0; ``extra_model`` and ``extra_step`` lines go before the first
    *BOUNDARY and at the step's end, elements ``reversed_elements`` are numbered clockwise,
    the first ``triangles`` cut into two S3R triangles each."""
    length, width = 10.0, 1.0
    nodes = [(1 + i + j * (nx + 1), i * length / nx, j * width / ny) for j in range(ny + 1) for i in range(nx + 1)]
    lines = ["*Heading", " Cantilever strip, S4R, tip load", "** a comment", '*Part, name="Strip"', "*Node"]
    lines += [f"{n}, {x!r}, {y!r}, 0." for n, x, y in nodes]
    quads, cut = ["*Element, type=S4R"], ["*Element, type=S3R"]
    for j in range(ny):
        for i in range(nx):
            n1 = 1 + i + j * (nx + 1)
            corners = [n1, n1 + 1, n1 + nx + 2, n1 + nx + 1]
            label = 1 + i + j * nx
            corners = corners[::-1] if label in reversed_elements else corners
            if label <= triangles:
                cut += [", ".join(map(str, [label] + corners[:3])), ", ".join(map(str, [1000 + label] + corners[2:] + corners[:1]))]
            else:
                quads.append(", ".join(map(str, [label] + corners)))
    lines += quads + (cut if triangles else [])
    lines += ["*Nset, nset=Root", ", ".join(str(n) for n, x, _ in nodes if x == 0.0) + ",",
              "*Nset, nset=Tip", ", ".join(str(n) for n, x, _ in nodes if x == length),
              "*Elset, elset=Whole, generate", f"1, {nx * ny}, 1"] + (
                  ["*Elset, elset=Whole, generate", f"1001, {1000 + triangles}, 1"] if triangles else []) + [
              "*Shell Section, elset=Whole, material=Steel", "0.1, 5", "*End Part",
              "*Assembly, name=Assembly", "*Instance, name=Strip-1, part=Strip", "5., 0., 0.", "*End Instance",
              "*Nset, nset=Fixed, instance=Strip-1", "Root,",
              "*Elset, elset=_Top, internal, instance=Strip-1, generate", f"1, {nx * ny}, 1",
              "*Surface, type=ELEMENT, name=TopSurf", "_Top, SPOS", "*End Assembly",
              "*Amplitude, name=Ramp", "0., 0., 1., 1.",
              "*Material, name=Steel", "*Density", "7.8e-9", "*Elastic", "200000., 0.0",
              extra_model, "*Boundary", "Fixed, ENCASTRE",
              "*Step, name=Load, nlgeom=YES", "*Static", "0.25, 1., 1e-05, 1.",
              "*Cload, amplitude=Ramp", f"Strip-1.Tip, 3, {tip_force}", extra_step,
              "*Output, field, variable=PRESELECT", "*End Step"]
    return "\n".join(line for line in lines if line) + "\n"


#: The strip's tip deflection under its three tip forces of 1e-3: P L^3 / (3 E I). Shear
#: adds P L / (k G A), 6e-5 of it, and at 0.6% of L the rotations' nonlinearity a few 1e-5:
#: the imported strips are held to 0.1%.
BEAM_TIP = -3e-3 * 10.0**3 / (3 * 2e5 * 1.0 * 0.1**3 / 12)


def tip_deflection(done, tip: str) -> float:
    """The final z displacement of the set ``tip`` of an imported strip solved as its deck says."""
    return tip_deflection_along(done, tip, "z")


def tip_deflection_along(done, tip: str, component: str) -> float:
    """The final displacement along ``component`` of the set ``tip`` of an imported model
    solved as its deck says."""
    done.deck.write_text(done.deck.read_text() + f'''
[[output.probe]]
name = "tip"
quantity = "displacement"
set = "{tip}"
component = "{component}"
''')
    run = run_deck(load_deck(done.deck), done.deck.parent)
    assert run.status == "completed"
    return float(np.asarray(run.history["tip"])[-1])


@pytest.fixture
def strip(tmp_path):
    def write(**options):
        path = tmp_path / "strip.inp"
        path.write_text(strip_inp(**options))
        return path
    return write


def test_an_imported_cantilever_bends_as_beam_theory_says(strip, tmp_path):
    """The strip (L = 10, b = 1, t = 0.1, E = 2e5, nu = 0) brought over and solved
    statically: its tip deflection under the three tip forces is BEAM_TIP within 0.1%."""
    done = import_model(strip(), tmp_path / "imported")
    assert done.problems == []
    assert tip_deflection(done, "Strip-1_Tip") == pytest.approx(BEAM_TIP, rel=1e-3)


def test_triangles_split_into_quads_still_bend_as_beam_theory_says(tmp_path):
    """Half the strip's elements as S3R triangles (two per square): each triangle split
    into three quads and each quad into four so that they meet, 100 elements in all; the
    tip deflection is still P L^3 / (3 E I) within 0.1%, the split listed."""
    path = tmp_path / "strip.inp"
    path.write_text(strip_inp(triangles=10))
    done = import_model(path, tmp_path / "imported")
    assert done.problems == [] and done.elements == 20 * 3 + 10 * 4
    assert any(re.search(r"20 triangle\(s\) \(first at strip\.inp:\d+\): each split into three quads", line)
               for line in done.unmapped)
    assert tip_deflection(done, "Strip-1_Tip") == pytest.approx(BEAM_TIP, rel=1e-3)


def test_the_strip_s_deck_says_what_the_file_says(strip, tmp_path):
    """Sets qualified by the instance and renamed to deck names, the clamp, the tip force on
    the three nodes the file names (not the new ones between them), the amplitude as a
    curve, the static step's span and first increment, NLGEOM as the total formulation,
    the instance's shift applied, the output request listed with its line."""
    done = import_model(strip(), tmp_path / "imported")
    deck = load_deck(done.deck)
    mesh = build_mesh(deck, done.deck.parent)
    assert mesh.n_elements == 20 and mesh.x[:, 0].min() == 5.0 and mesh.x[:, 0].max() == 15.0
    assert deck.boundary[0].type == "clamped" and deck.boundary[0].set == "Fixed"
    assert len(mesh.sets["Fixed"].nodes) == 5 and mesh.sets["Fixed"].kind == "edge"  # 3 corners and 2 new mid-edge nodes
    force, = deck.load
    assert force.type == "point_force" and tuple(force.value) == (0.0, 0.0, -1e-3) and force.curve == "Ramp"
    assert len(mesh.sets[force.set].nodes) == 3
    assert deck.curves["Ramp"].t == [0.0, 1.0] and deck.solver.method == "static"
    assert deck.solver.static.increments == 4 and deck.section.technique == 1
    assert any(re.search(r"\*OUTPUT.*strip\.inp:\d+", line) for line in done.unmapped)
    assert done.deck.read_text().startswith("# Brought over from strip.inp")


@pytest.mark.parametrize("face, step, sign", [
    ("SPOS", "*Dsload\nTopSurf, P, 2.0", -1.0),
    ("SNEG", "*Dsload\nTopSurf, P, 2.0", 1.0),
    ("SPOS", "*Dload\nStrip-1.Whole, P, 2.0", -1.0),
])
def test_pressure_pushes_where_abaqus_pushes_whichever_way_elements_were_numbered(tmp_path, face, step, sign):
    """A pressure p = 2 on the SPOS face pushes against each element's own Abaqus normal
    (on SNEG along it; *DLOAD P as SPOS): with element 3 (area 0.5) numbered the other way
    round (normal -z) and the rest (area 9.5) +z, the resultant along z is
    -+p (9.5 - 0.5). shellsim orients the mesh one way and splits the load in two, one
    for each of Abaqus' orientations, with opposite signs."""
    path = tmp_path / "plate.inp"
    path.write_text(strip_inp(tip_force=0.0, reversed_elements=(3,), extra_step=step).replace("_Top, SPOS", f"_Top, {face}"))
    model = read_foreign(path)
    assert all("*OUTPUT" in line or "5 section points become" in line for line in model.unmapped)
    tables = model.tables | {"geometry": {"builder": "file", "path": str(path)}, "solver": {"end_time": 1.0}}
    tables["load"] = [t for t in tables["load"] if t["type"] == "pressure"]
    assert len(tables["load"]) == 2 and {t["value"] for t in tables["load"]} == {2.0, -2.0}
    deck = parse_deck(deck_text(tables))
    f, _ = initial_external_forces(build_model(deck, build_mesh(deck)))
    assert f[:, 2].sum() == pytest.approx(sign * 2.0 * (9.5 - 0.5), rel=1e-9)
    assert np.abs(f[:, :2].sum(axis=0)).max() <= 1e-12


def test_new_mid_edge_nodes_lie_on_a_curved_surface_not_on_its_chords():
    """A cylinder of radius 1 meshed with 4-node quads 30 degrees apart: the new mid-edge
    and centre nodes are within 0.2% of the radius (the Hermite curve's error is
    1 - cos 15 (1 + sin^2 15 / 2) = 0.17%), where chord midpoints fall 3.4% inside; so
    are those of its lower half cut into triangles, split with the upper half's quads
    (the nodes the pieces then gain, between those, within 0.25%); on a flat mesh the
    new nodes are the chord midpoints exactly."""
    angles = np.radians(np.arange(0, 360, 30))
    ring = np.column_stack([np.cos(angles), np.sin(angles)])
    x = np.concatenate([np.column_stack([ring, np.full(12, z)]) for z in (0.0, 0.5, 1.0)])
    quads = np.asarray([[i + 12 * k, (i + 1) % 12 + 12 * k, (i + 1) % 12 + 12 * (k + 1), i + 12 * (k + 1)]
                        for k in range(2) for i in range(12)])
    up = upgrade(x, quads)
    radius = np.linalg.norm(up.x[36:, :2], axis=1)
    assert np.abs(radius - 1).max() <= 2e-3
    pieces, parent = split(x, np.concatenate([quads[:12, :3], quads[:12, [2, 3, 0]]]), quads[12:])
    fine = upgrade(pieces.x, pieces.conn)
    assert len(fine.conn) == 24 * 3 + 12 * 4 and np.array_equal(np.bincount(parent), [3] * 24 + [4] * 12)
    assert np.abs(np.linalg.norm(pieces.x[36:, :2], axis=1) - 1).max() <= 2e-3
    assert np.abs(np.linalg.norm(fine.x[36:, :2], axis=1) - 1).max() <= 2.5e-3  # the pieces' nodes lean on those
    flat = upgrade(x[:, [0, 2, 1]] * [1, 1, 0], quads)  # the cylinder's nodes pressed onto z = 0
    new = flat.x[len(x):len(x) + len(flat.edge_ends)]
    assert np.allclose(new, flat.x[flat.edge_ends].mean(axis=1), atol=1e-12)


def test_what_cannot_come_over_is_listed_with_its_line_and_a_mesh_deck_refuses_it(strip, tmp_path):
    """3-node line elements, a user material, a keyword shellsim does not read and a second
    step each named with file and line; the import still writes the deck (its problems say
    what to edit: a material), while a deck reading the file's mesh refuses the lines."""
    extra_model = "*Element, type=T3D3, elset=Chords\n900, 1, 2, 3\n*Equation\n2\n1, 1, 1., 2, 1, -1."
    path = strip(extra_model=extra_model)
    text = path.read_text().replace("*Elastic\n200000., 0.0", "*User Material, constants=2\n1., 2.")
    path.write_text(text + "*Step\n*Static\n*End Step\n")
    done = import_model(path, tmp_path / "imported")
    listed = "\n".join(done.unmapped)
    for pattern in (r"1 T3D3 element\(s\) \(first at strip\.inp:\d+\)", r"\*USER MATERIAL \(strip\.inp:\d+\).*lee_sacks",
                    r"\*EQUATION \(strip\.inp:\d+\): not read", r"\*STEP \(strip\.inp:\d+\): only the first step"):
        assert re.search(pattern, listed), pattern
    assert any("material" in p for p in done.problems)
    for line in done.unmapped:
        assert line in done.deck.read_text()
    with pytest.raises(MeshError, match=r"T3D3.*strip\.inp:\d+"):
        read_mesh(path)


def test_included_files_per_node_motion_and_symmetry(strip, tmp_path):
    """The nodes read from an *INCLUDE file; XSYMM on the root as a symmetry plane; a tip
    pulled by a different value at each node (one *BOUNDARY line per node) as one
    prescribed motion with a point field, the new tip node between two given ones moving
    by their mean; a rotation held alone listed."""
    text = strip_inp()
    nodes = text[text.index("*Node"):text.index("*Element")]
    (tmp_path / "nodes.inp").write_text(nodes)
    text = text.replace(nodes, "*Include, input=nodes.inp\n").replace("Fixed, ENCASTRE", "Fixed, XSYMM\nStrip-1.Tip, 5, 5")
    text = text.replace("*Output", "*Boundary\nStrip-1.11, 3, 3, 0.1\nStrip-1.22, 3, 3, 0.2\nStrip-1.33, 3, 3, 0.3\n*Output")
    path = tmp_path / "strip.inp"
    path.write_text(text)
    model = read_foreign(path)
    tables = model.tables
    symmetry = [b for b in tables["boundary"] if b["type"] == "symmetry"]
    assert symmetry and symmetry[0]["normal"] == [1.0, 0.0, 0.0]
    moved, = [b for b in tables["boundary"] if b["type"] == "prescribed"]
    field = model.mesh.point_fields[moved["field"]]
    tip = model.mesh.sets[moved["set"]].nodes
    assert len(tip) == 5
    assert sorted(np.round(field[tip], 12)) == [0.1, 0.15, 0.2, 0.25, 0.3]
    assert any("rotation about y alone" in line for line in model.unmapped)
    # the deck reads the file's mesh itself, and each node moves by its own share
    tables = model.tables | {"geometry": {"builder": "file", "path": str(path)}}
    deck = parse_deck(deck_text(tables))
    mesh = build_mesh(deck)
    prescribed = build_model(deck, mesh).constraints.prescribed
    assert sorted(np.round(prescribed.values, 12)) == [0.1, 0.15, 0.2, 0.25, 0.3]
    assert np.array_equal(np.sort(prescribed.nodes), np.sort(mesh.sets[moved["set"]].nodes))
    wrong = parse_deck(deck_text(tables | {"boundary": [moved | {"field": "nowhere"}]}))
    with pytest.raises(MeshError, match=r"boundary set 'moved_z': field 'nowhere' is not a scalar point field.*'moved_z'"):
        build_model(wrong, build_mesh(wrong))


def test_hgo_constants_and_fibre_axes_from_a_distribution(strip, tmp_path):
    """*ANISOTROPIC HYPERELASTIC, HOLZAPFEL (C10, D, k1, k2, kappa) as hgo with mu = 2 C10,
    the families at +-beta from the orientation's two local directions, material axis 1
    per element from a *DISTRIBUTION (default row and one element's own)."""
    text = strip_inp().replace("*Elastic\n200000., 0.0",
                               "*Anisotropic Hyperelastic, holzapfel, local directions=2\n0.0035, 0., 2.3632, 0.8393, 0.226")
    text = text.replace("*Shell Section, elset=Whole, material=Steel",
                        "*Distribution, name=Fibres, location=ELEMENT, Table=T\n, 1., 0., 0., 0., 1., 0.\n"
                        "7, 0., 1., 0., -1., 0., 0.\n*Orientation, name=Ori, local directions=2\nFibres\n3, 0.\n"
                        "0.7660444, 0.6427876, 0.\n0.7660444, -0.6427876, 0.\n"
                        "*Shell Section, elset=Whole, material=Steel, orientation=Ori")
    path = tmp_path / "hgo.inp"
    path.write_text(text)
    model = read_foreign(path)
    material = model.tables["material"]
    assert material["model"] == "hgo" and material["mu"] == pytest.approx(0.007)
    assert (material["k1"], material["k2"], material["kappa"]) == (2.3632, 0.8393, 0.226)
    assert material["beta_deg"] == pytest.approx(40.0, abs=1e-5)
    assert material["axes"] == {"kind": "mesh", "field": "Fibres"}
    vectors = model.mesh.cell_vectors["Fibres"]
    assert np.allclose(vectors[6], [0, 1, 0]) and np.allclose(np.delete(vectors, 6, axis=0), [1, 0, 0])


def test_shellsim_import_writes_a_deck_that_checks(strip, tmp_path):
    """The command: the deck and mesh written, the unmapped lines shown, ``check`` passes on
    the deck; a second import into the same folder is refused, the first deck kept."""
    runner = CliRunner()
    out = tmp_path / "imported"
    result = runner.invoke(app, ["import", str(strip()), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "not brought over" in result.output and (out / "deck.toml").is_file() and (out / "strip.vtu").is_file()
    assert runner.invoke(app, ["check", str(out / "deck.toml")]).exit_code == 0
    before = (out / "deck.toml").read_text()
    again = runner.invoke(app, ["import", str(strip()), "--out", str(out)])
    assert again.exit_code == 2 and "exists" in again.output and (out / "deck.toml").read_text() == before


def feb_set(version: str, tag: str, name: str, ids: list[int], child: str) -> str:
    """A FEBio node or element set: its ids as a comma list (format 4.0) or as ``child``
    elements (3.0)."""
    body = ",".join(map(str, ids)) if version.startswith("4") else "".join(f'<{child} id="{i}"/>' for i in ids)
    return f'<{tag} name="{name}">{body}</{tag}>'


def feb_held(version: str, name: str, node_set: str, axes: str) -> str:
    """A FEBio zero displacement of ``axes`` (e.g. "yz") on a node set, as either format writes it."""
    if version.startswith("4"):
        dofs = "".join(f"<{a}_dof>{int(a in axes)}</{a}_dof>" for a in "xyz")
        return f'<bc name="{name}" type="zero displacement" node_set="{node_set}">{dofs}</bc>'
    return f'<bc name="{name}" type="fix" node_set="{node_set}"><dofs>{",".join(axes)}</dofs></bc>'


def feb_force(version: str, name: str, node_set: str, axis: str, value: float) -> str:
    """A FEBio nodal force ``value`` along ``axis`` on a node set, on load curve 1."""
    if version.startswith("4"):
        vector = ",".join(repr(value if a == axis else 0.0) for a in "xyz")
        return f'<nodal_load name="{name}" type="nodal_force" node_set="{node_set}"><value lc="1">{vector}</value></nodal_load>'
    return (f'<nodal_load name="{name}" type="nodal_load" node_set="{node_set}"><dof>{axis}</dof>'
            f'<scale lc="1">{value!r}</scale></nodal_load>')


def strip_feb(version: str = "4.0", pressure_facets: bool = False, reversed_elements: tuple = (),
              tip_force: float = -0.001) -> str:
    """The cantilever strip of :func:`strip_inp` as FEBio Studio saves it (format
    ``version``): a quad4 shell domain of thickness 0.1 (3.0: as element data), the root
    node set held (displacements and shell displacements), a nodal force on the tip nodes
    ramped by a load curve, a static step of four steps; ``pressure_facets``: a surface
    of those elements' facets (each element's nodes, reversed for ``reversed_elements``)
    under pressure 2."""
    nx, ny, four = 10, 2, version.startswith("4")
    nodes = [(1 + i + j * (nx + 1), i * 1.0, j * 0.5) for j in range(ny + 1) for i in range(nx + 1)]
    elements = {}
    for j in range(ny):
        for i in range(nx):
            n1 = 1 + i + j * (nx + 1)
            elements[1 + i + j * nx] = [n1, n1 + 1, n1 + nx + 2, n1 + nx + 1]

    root = [n for n, x, _ in nodes if x == 0.0]
    tip = [n for n, x, _ in nodes if x == 10.0]
    facets = "".join(f'<quad4 id="{k}">{",".join(map(str, elements[k][::-1] if k in reversed_elements else elements[k]))}'
                     "</quad4>" for k in elements) if pressure_facets else ""
    thickness = ('<shell_thickness>0.1</shell_thickness>' if four else "")
    data = ("" if four else '<MeshData><ElementData var="shell thickness" elem_set="Strip">'
            + "".join(f'<e lid="{k}">0.1,0.1,0.1,0.1</e>' for k in elements) + "</ElementData></MeshData>")
    pressure = ('<surface_load type="pressure" surface="Top"><pressure lc="1">2.0</pressure></surface_load>'
                if pressure_facets else "")
    points = "<pt>0,0</pt><pt>1,1</pt>" if four else "<point>0,0</point><point>1,1</point>"
    return f'''<?xml version="1.0" encoding="ISO-8859-1"?>
<febio_spec version="{version}">
  <Module type="solid"/>
  <Control><analysis>STATIC</analysis><time_steps>4</time_steps><step_size>0.25</step_size></Control>
  <Material><material id="1" name="Steel" type="isotropic elastic"><density>7.8e-9</density><E>200000</E><v>0</v></material></Material>
  <Mesh>
    <Nodes name="Object1">{"".join(f'<node id="{n}">{x},{y},0</node>' for n, x, y in nodes)}</Nodes>
    <Elements type="quad4" name="Strip">{"".join(f'<elem id="{k}">{",".join(map(str, v))}</elem>' for k, v in elements.items())}</Elements>
    {feb_set(version, "NodeSet", "Root", root, "n")}
    {feb_set(version, "NodeSet", "Tip", tip, "n")}
    <Surface name="Top">{facets}</Surface>
  </Mesh>
  <MeshDomains><ShellDomain name="Strip" mat="Steel">{thickness}</ShellDomain></MeshDomains>
  {data}
  <Boundary>
    {feb_held(version, "Root", "Root", "xyz")}
    <bc name="RootShell" type="zero shell displacement" node_set="Root"><sx_dof>1</sx_dof><sy_dof>1</sy_dof><sz_dof>1</sz_dof></bc>
  </Boundary>
  <Loads>{feb_force(version, "Tip", "Tip", "z", tip_force)}{pressure}</Loads>
  <LoadData><load_controller id="1" name="Ramp" type="loadcurve">
    <interpolate>LINEAR</interpolate><points>{points}</points></load_controller></LoadData>
  <Output><plotfile type="febio"><var type="displacement"/></plotfile></Output>
</febio_spec>
'''


@pytest.mark.parametrize("version", ["4.0", "3.0"])
def test_an_imported_febio_cantilever_bends_as_beam_theory_says(tmp_path, version):
    """The strip from a FEBio file (both formats): clamped by its zero displacements and
    shell displacements, the force on the three tip nodes, the load curve, the thickness
    (from the domain, or the element data) and the static step come over, and the tip
    deflection is P L^3 / (3 E I) within 0.1%."""
    path = tmp_path / "strip.feb"
    path.write_text(strip_feb(version))
    done = import_model(path, tmp_path / "imported")
    assert done.problems == [] and done.elements == 20
    deck = load_deck(done.deck)
    assert deck.boundary[0].type == "clamped" and deck.section.thickness == 0.1 and deck.solver.end_time == 1.0
    assert tip_deflection(done, "Tip") == pytest.approx(BEAM_TIP, rel=1e-3)
    assert any(re.search(r"output requests \(<Output> \(strip\.feb:\d+\)\)", line) for line in done.unmapped)


def test_febio_pressure_pushes_against_each_facet_s_normal(tmp_path):
    """A pressure 2 on facets that follow their elements' nodes except element 3's (given
    the other way round): FEBio pushes against each facet's normal, 19 facets' along -z
    and one's along +z: the resultant along z is -2 (9.5 - 0.5)."""
    path = tmp_path / "plate.feb"
    path.write_text(strip_feb(pressure_facets=True, reversed_elements=(3,), tip_force=0.0))
    model = read_foreign(path)
    tables = model.tables | {"geometry": {"builder": "file", "path": str(path)}, "solver": {"end_time": 1.0}}
    tables["load"] = [t for t in tables["load"] if t["type"] == "pressure"]
    assert len(tables["load"]) == 2
    deck = parse_deck(deck_text(tables))
    f, _ = initial_external_forces(build_model(deck, build_mesh(deck)), t=1.0)  # the curve's end: factor 1
    assert f[:, 2].sum() == pytest.approx(-2.0 * (9.5 - 0.5), rel=1e-9)


@pytest.mark.parametrize("kind", ["mat_axis", "fiber"])
def test_febio_hgo_and_per_element_material_axes(tmp_path, kind):
    """FEBio's Holzapfel-Gasser-Ogden (c, k1, k2, kappa, gamma) as hgo with mu = c and the
    families at +-gamma, material axis 1 per element from the mesh data's mat_axis (its a
    vector; format 4.0) or fiber (format 3.0)."""
    text = strip_feb().replace(
        '<material id="1" name="Steel" type="isotropic elastic"><density>7.8e-9</density><E>200000</E><v>0</v></material>',
        '<material id="1" name="Media" type="Holzapfel-Gasser-Ogden"><density>1.2e-9</density><c>0.0035</c>'
        '<k1>2.3632</k1><k2>0.8393</k2><kappa>0.226</kappa><gamma>40</gamma><k>100</k></material>').replace(
        'mat="Steel"', 'mat="Media"')
    axis = {k: "0,1,0" if k == 7 else "1,0,0" for k in range(1, 21)}
    if kind == "mat_axis":
        data = '<ElementData type="mat_axis" elem_set="Strip">' + "".join(
            f'<e lid="{k}"><a>{a}</a><d>0,0,1</d></e>' for k, a in axis.items())
    else:
        data = '<ElementData var="fiber" elem_set="Strip">' + "".join(f'<e lid="{k}">{a}</e>' for k, a in axis.items())
    text = text.replace("<Boundary>", f"<MeshData>{data}</ElementData></MeshData>\n  <Boundary>")
    path = tmp_path / "hgo.feb"
    path.write_text(text)
    model = read_foreign(path)
    assert model.tables["material"] == {"model": "hgo", "mu": 0.0035, "k1": 2.3632, "k2": 0.8393, "kappa": 0.226,
                                         "beta_deg": 40.0, "axes": {"kind": "mesh", "field": kind},
                                         "density": 1.2e-9}
    vectors = model.mesh.cell_vectors[kind]
    assert np.allclose(vectors[model.mesh.sets["Strip"].elements[6]], [0, 1, 0])
    assert np.allclose(np.delete(vectors, 6, axis=0), [1, 0, 0])


@pytest.mark.parametrize("name, text, message", [
    ("bad.inp", "1, 0., 0., 0.\n*Node\n", r"data before the first keyword"),
    ("bad.inp", "*Node\n1, 0., 0.\n*Element, type=S4\n1, 1, 2, 3, 4\n", r"nodes that are not defined: 2"),
    ("bad.inp", "*Node\n1, a, 0., 0.\n", r"bad\.inp:2.*label, x, y, z"),
    ("bad.inp", "*Nset, nset=A\nNowhere\n", r"\*NSET \(bad\.inp:1\): unknown node set 'Nowhere'"),
    ("bad.inp", "*Include, input=missing.inp\n", r"\*INCLUDE \(bad\.inp:1\): model file '.*missing\.inp' not found"),
    ("bad.inp", "*Node\n1, 0., 0., 0.\n", r"no shell elements shellsim reads"),
    ("bad.feb", "<febio_spec version='4.0'><Mesh>", r"not well-formed XML"),
    ("bad.feb", "<febio_spec version='2.5'/>", r"not a FEBio model of format 3\.0 or 4\.0 .*version '2\.5'"),
    ("bad.feb", "<febio_spec version='4.0'><Mesh><Nodes><node id='1'>0,x,0</node></Nodes></Mesh></febio_spec>",
     r"<node> \(bad\.feb:1\): a node is 'x,y,z'"),
    ("bad.feb", "<febio_spec version='4.0'><Mesh/></febio_spec>", r"no shell elements in a <ShellDomain>"),
    ("bad.stl", "solid", r"not a model file shellsim reads \(suffixes: \.feb, \.inp\)"),
    ("bad.inp", "*Nset, nset=A, generate\n1, 100000000000, 1\n", r"bad\.inp:2\): GENERATE from 1 to 100000000000 by 1 "
                                                                  r"is not a range .* past 10,000,000 labels in all"),
    ("bad.inp", "*Include, input=.\n", r"model file '.*' is not a regular file"),
])
def test_a_broken_model_file_is_refused_naming_its_line(tmp_path, name, text, message):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(MeshError, match=message):
        read_foreign(path)


def test_many_generate_lines_are_bounded_in_all_not_each(tmp_path, monkeypatch):
    """GENERATE lines each within the bound but past it together (30 lines of 10 million
    labels ran for ever) are refused at the line that passes it."""
    monkeypatch.setattr(abaqus_model, "MAX_GENERATED", 1000)
    path = tmp_path / "many.inp"
    path.write_text("*Heading\n*Nset, nset=A, generate\n" + "1, 400, 1\n" * 30)
    with pytest.raises(MeshError, match=r"many\.inp:5\): GENERATE from 1 to 400 by 1 .* past 1,000 labels in all"):
        read_foreign(path)


def test_a_value_that_is_not_a_number_is_a_message_not_a_traceback(tmp_path):
    path = tmp_path / "strip.inp"
    path.write_text(strip_inp().replace("*Density\n7.8e-9", "*Density\nheavy"))
    with pytest.raises(MeshError, match=r"strip\.inp' holds a value shellsim cannot read .*'heavy'"):
        read_foreign(path)


def test_a_pipe_named_as_a_model_is_refused_not_read(tmp_path):
    """A FIFO would block the read for ever: it is named instead, as the model and as an
    included file."""
    pipe = tmp_path / "pipe.inp"
    os.mkfifo(pipe)
    with pytest.raises(MeshError, match=r"pipe\.inp' is not a regular file"):
        read_foreign(pipe)
    (tmp_path / "model.inp").write_text("*Include, input=pipe.inp\n")
    with pytest.raises(MeshError, match=r"\*INCLUDE \(model\.inp:1\): .*pipe\.inp' is not a regular file"):
        read_foreign(tmp_path / "model.inp")


def tethered_plate_feb(version: str, domain: str = "linear-truss", area: str = "0.5") -> str:
    """:func:`tethered_plate_inp` as FEBio Studio saves it (format ``version``): the chord
    a truss2 in a beam domain of ``domain`` type with cross_sectional_area ``area``, of a
    'linear truss' material E = 1000; the force ramped by a load curve over a static step."""
    four = version.startswith("4")

    thickness = "<shell_thickness>0.1</shell_thickness>" if four else ""
    data = ("" if four else '<MeshData><ElementData var="shell thickness" elem_set="Plate">'
            '<e lid="1">0.1,0.1,0.1,0.1</e></ElementData></MeshData>')
    points = "<pt>0,0</pt><pt>1,1</pt>" if four else "<point>0,0</point><point>1,1</point>"
    return f'''<?xml version="1.0" encoding="ISO-8859-1"?>
<febio_spec version="{version}">
  <Module type="solid"/>
  <Control><analysis>STATIC</analysis><time_steps>4</time_steps><step_size>0.25</step_size></Control>
  <Material>
    <material id="1" name="Skin" type="isotropic elastic"><density>1e-9</density><E>1000000</E><v>0.3</v></material>
    <material id="2" name="Cord" type="linear truss"><density>1.1e-9</density><E>1000</E><v>0.3</v></material>
  </Material>
  <Mesh>
    <Nodes name="Object1"><node id="1">0,0,0</node><node id="2">1,0,0</node><node id="3">1,1,0</node>
      <node id="4">0,1,0</node><node id="5">2,0,0</node></Nodes>
    <Elements type="quad4" name="Plate"><elem id="1">1,2,3,4</elem></Elements>
    <Elements type="truss2" name="Chord"><elem id="10">2,5</elem></Elements>
    {"".join(feb_set(version, "NodeSet", name, ids, "n") for name, ids in (("Root", [1, 4]), ("Pin", [2]), ("End", [5])))}
  </Mesh>
  <MeshDomains><ShellDomain name="Plate" mat="Skin">{thickness}</ShellDomain>
    <BeamDomain name="Chord" mat="Cord" type="{domain}"><cross_sectional_area>{area}</cross_sectional_area></BeamDomain>
  </MeshDomains>
  {data}
  <Boundary>{feb_held(version, "Root", "Root", "xyz")}
    <bc name="RootShell" type="zero shell displacement" node_set="Root"><sx_dof>1</sx_dof><sy_dof>1</sy_dof><sz_dof>1</sz_dof></bc>
    {feb_held(version, "Pin", "Pin", "xyz")}{feb_held(version, "Across", "End", "yz")}</Boundary>
  <Loads>{feb_force(version, "Pull", "End", "x", 100.0)}</Loads>
  <LoadData><load_controller id="1" name="Ramp" type="loadcurve">
    <interpolate>LINEAR</interpolate><points>{points}</points></load_controller></LoadData>
</febio_spec>
'''


@pytest.mark.parametrize("version", ["4.0", "3.0"])
def test_febio_trusses_come_over_as_cables_that_stretch_as_their_law_says(tmp_path, version):
    """A truss2 in a beam domain comes over as a cable, as Abaqus' T3D2 does: its own node,
    its domain a line set, a [[cable]] table with the domain's cross_sectional_area and its
    'linear truss' material's E and density; pulled by F = 100 with EA = 500 it stretches
    by F / EA = 0.2 (the linear law's closed form). A domain with no area, or a truss
    material with no 1D law, is listed with its line and its cables left out."""
    path = tmp_path / "tethered.feb"
    path.write_text(tethered_plate_feb(version))
    done = import_model(path, tmp_path / "imported")
    assert done.problems == [] and done.sets["Chord"] == "line"
    mesh = read_mesh(done.mesh)
    assert len(mesh.lines) == 1 and mesh.sets["Chord"].kind == "line"
    np.testing.assert_allclose(mesh.x[mesh.lines[0]], [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    cable, = load_deck(done.deck).cable
    assert (cable.set, cable.area, cable.density, cable.law.model, cable.law.E) == ("Chord", 0.5, 1.1e-9, "linear",
                                                                                   1000.0)
    assert tip_deflection_along(done, "End", "x") == pytest.approx(100.0 / 500.0, rel=1e-9)
    without_area = read_foreign(_written(tmp_path / "no_area.feb", tethered_plate_feb(version, area="0")))
    assert "cable" not in without_area.tables
    assert any(re.search(r'<BeamDomain name="Chord"> \(no_area\.feb:\d+\): no positive cross_sectional_area', line)
               for line in without_area.unmapped)
    other_law = tethered_plate_feb(version).replace('type="linear truss"', 'type="Mooney-Rivlin"')
    unmapped = read_foreign(_written(tmp_path / "law.feb", other_law))
    assert "cable" not in unmapped.tables
    assert any(re.search(r"<material name=\"Cord\"> \(law\.feb:\d+\): a truss of type 'Mooney-Rivlin'", line)
               for line in unmapped.unmapped)


def _written(path, text: str):
    """``path`` with ``text`` written to it."""
    path.write_text(text)
    return path


def tethered_plate_inp(line: str = "T3D2", section: str = "*Solid Section, elset=Chord, material=Cord\n0.5") -> str:
    """A clamped S4R plate 1 x 1 and a cable (a ``line`` element) of length 1 from its
    corner (2; pinned) along x to a node of its own (5), held across and pulled along
    it by a force of 100 in a static step; the cable's ``section`` area 0.5, E = 1000."""
    return "\n".join([
        "*Heading", " a plate and a chord", "*Node", "1, 0., 0., 0.", "2, 1., 0., 0.", "3, 1., 1., 0.", "4, 0., 1., 0.",
        "5, 2., 0., 0.", "*Element, type=S4R, elset=Plate", "1, 1, 2, 3, 4", f"*Element, type={line}, elset=Chord",
        "10, 2, 5", "*Nset, nset=Root", "1, 4", "*Nset, nset=End", "5",
        "*Shell Section, elset=Plate, material=Skin", "0.1", section,
        "*Material, name=Skin", "*Density", "1e-9", "*Elastic", "1000000., 0.3",
        "*Material, name=Cord", "*Density", "1.1e-9", "*Elastic", "1000., 0.3",
        "*Boundary", "Root, ENCASTRE", "2, PINNED", "End, 2, 3",
        "*Step, nlgeom=YES", "*Static", "0.25, 1.", "*Cload", "End, 1, 100.", "*End Step"]) + "\n"


def test_truss_elements_come_over_as_cables_that_stretch_as_their_law_says(tmp_path):
    """A T3D2 truss comes over as a cable: its node that no shell has kept, its element set
    a line set of the written mesh (and of the file read as a deck's mesh), a [[cable]]
    table with its section's area, its material's E and density; solved as the deck says,
    the chord pulled by F = 100 with EA = 500 stretches by F / EA = 0.2 (the linear law's
    closed form) to 1e-9. A B31 beam comes over the same way, its area pi r^2 from a
    circular section, listed as carrying tension only."""
    path = tmp_path / "tethered.inp"
    path.write_text(tethered_plate_inp())
    done = import_model(path, tmp_path / "imported")
    assert done.problems == [] and done.sets["Chord"] == "line"
    written, direct = read_mesh(done.mesh), read_mesh(path)
    for mesh in (written, direct):
        assert len(mesh.lines) == 1 and mesh.sets["Chord"].kind == "line"
        np.testing.assert_allclose(mesh.x[mesh.lines[0]], [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    deck = load_deck(done.deck)
    cable, = deck.cable
    assert (cable.set, cable.area, cable.density, cable.law.model, cable.law.E) == ("Chord", 0.5, 1.1e-9, "linear",
                                                                                   1000.0)
    assert tip_deflection_along(done, "End", "x") == pytest.approx(100.0 / 500.0, rel=1e-9)
    beam = tmp_path / "beam.inp"
    beam.write_text(tethered_plate_inp("B31", "*Beam Section, elset=Chord, material=Cord, section=CIRC\n0.4"))
    model = read_foreign(beam)
    assert model.tables["cable"][0]["area"] == pytest.approx(np.pi * 0.16)
    assert any(re.search(r"1 B31 beam element\(s\) \(first at beam\.inp:\d+\).*tension only", line)
               for line in model.unmapped)


def test_notes_of_one_kind_are_said_once_and_a_soft_contact_is_listed_with_its_constants(tmp_path):
    """Five *BOUNDARY, OP=NEW in the step give one note with their count and first three
    places; a surface interaction's linear pressure-overclosure and contact damping are
    listed with their constants, not dropped."""
    interaction = ("*Surface Interaction, name=Soft\n*Friction\n0.01\n"
                   "*Surface Behavior, pressure-overclosure=LINEAR\n1000.\n*Contact Damping, definition=DAMPING COEFFICIENT\n0.1")
    step = "\n".join(["*Boundary, op=NEW\nStrip-1.Root, ENCASTRE"] * 5
                     + ["*Contact\n*Contact Inclusions, all exterior\n*Contact Property Assignment\n, , Soft"])
    path = tmp_path / "strip.inp"
    path.write_text(strip_inp(extra_model=interaction, extra_step=step))
    notes = read_foreign(path).unmapped
    op_new = [line for line in notes if "OP=NEW" in line]
    assert len(op_new) == 1 and re.match(r"\*BOUNDARY \(5 times: strip\.inp:\d+, strip\.inp:\d+, strip\.inp:\d+, "
                                         r"\.\.\.\): OP=NEW", op_new[0]), op_new
    assert any(re.match(r"\*SURFACE BEHAVIOR \(strip\.inp:\d+\): PRESSURE-OVERCLOSURE=LINEAR \(1000\.\) is not carried",
                        line) for line in notes), notes
    assert any(line.startswith("*CONTACT DAMPING") for line in notes), notes


def test_a_run_of_an_imported_model_writes_the_file_s_numbers_in_every_frame(strip, tmp_path):
    """The strip solved as imported: each frame holds ``source_element``, the file's
    element number on each of its cells, and ``source_node``, the file's node number at
    the points that are its corners (0 at the others), so results compare with Abaqus'
    by number."""
    from shellsim.output.series import StoredSeries

    done = import_model(strip(), tmp_path / "imported")
    result = CliRunner().invoke(app, ["run", str(done.deck), "--out", str(tmp_path / "out")], env={"COLUMNS": "60"})
    assert result.exit_code == 0, result.output
    series = StoredSeries(tmp_path / "out")
    points, cells = series.frame(len(series.times) - 1)
    assert sorted(set(cells["source_element"].astype(int))) == list(range(1, 21))
    assert np.all(np.bincount(cells["source_element"].astype(int))[1:] == 9)  # 3 x 3 sub-cells each
    numbered = points["source_node"] > 0
    assert set(points["source_node"][numbered].astype(int)) == set(range(1, 34))
    # the points of a number lie where the file's node is (the instance shifts the part by 5 along x)
    file_x = {1 + i + j * 11: (5.0 + i, 0.5 * j) for j in range(3) for i in range(11)}
    for label in (1, 17, 33):
        at = series.points[points["source_node"] == label]
        np.testing.assert_allclose(at[:, :2], np.tile(file_x[label], (len(at), 1)), atol=1e-12)


def test_orientations_go_to_every_law_with_axes_and_are_listed_where_a_law_has_none(strip, tmp_path):
    """A section's *ORIENTATION becomes the axes of a user material mapped to Lee-Sacks
    (a law with axes), is listed for an isotropic law without axes, and an orientation of
    no length is listed, not written."""
    from shellsim.foreign.user_law import UserLaw

    orientation = "*Orientation, name=Along\n1., 1., 0., 0., 1., 0.\n3, 0."
    user = "*User Material, constants=3\n0.001, 0.0005, 4.57"
    text = strip_inp(extra_model=orientation).replace("material=Steel", "material=Steel, orientation=Along")
    law = UserLaw.parse("lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1")
    path = tmp_path / "strip.inp"
    path.write_text(text.replace("*Elastic\n200000., 0.0", user))
    model = read_foreign(path, law)
    assert model.tables["material"]["axes"] == {"kind": "fixed", "direction": [1.0, 1.0, 0.0]}
    path.write_text(text)
    model = read_foreign(path)
    assert "axes" not in model.tables["material"]
    assert any(re.search(r"ORIENTATION=Along is not carried: the linear_elastic law has no material axes", line)
               for line in model.unmapped), model.unmapped
    path.write_text(text.replace("*Elastic\n200000., 0.0", user).replace("1., 1., 0., 0., 1., 0.", "0., 0., 0., 0., 1., 0."))
    model = read_foreign(path, law)
    assert "axes" not in model.tables["material"]
    assert any("is (0, 0, 0), which points nowhere" in line for line in model.unmapped), model.unmapped


@pytest.mark.parametrize("keyword, throughout", [("*Variable Mass Scaling", True), ("*Fixed Mass Scaling", False)])
def test_whole_model_mass_scaling_comes_over_held_throughout_when_variable(tmp_path, keyword, throughout):
    """Mass scaling of the whole model to DT in an explicit step: variable scaling (applied
    again through the step) as [solver.mass_scaling] throughout, fixed scaling (at the
    step's start) as a scaling at the start only; each listed as one factor for every mass."""
    text = strip_inp(extra_step=f"{keyword}, dt=2e-5, type=uniform, frequency=10").replace(
        "*Static\n0.25, 1., 1e-05, 1.", "*Dynamic, Explicit\n, 1.")
    (tmp_path / "strip.inp").write_text(text)
    done = import_model(tmp_path / "strip.inp", tmp_path / "imported")
    scaling = load_deck(done.deck).solver.mass_scaling
    assert scaling.step == 2e-5 and scaling.throughout is throughout
    said = next(line for line in done.unmapped if "MASS SCALING" in line.upper())
    assert ("throughout = true" in said) is throughout and "one factor" in said
