"""An Abaqus input with every keyword the reader maps, written here, read back whole: every
node where the file put it, every set, each element's material axis, both shell sections'
thicknesses, every boundary value (one per node too), load and amplitude, the chords'
cables, and nothing listed but what has no counterpart. The sheet is the FEBio round
trip's (:mod:`tests.test_febio_round_trip`)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from shellsim.foreign import read_foreign

from .test_febio_round_trip import (CURL, MIDDLE, NX, NY, PAPILLARY, assert_sheet_loads, axis_of, file_element_under,
                                    file_elements, nearest, sheet_node, surface_z)

#: The two shell sections' thicknesses: the quads', the triangles'.
BELLY, EDGE = 0.4, 0.3
#: The top row's prescribed lift, a value per node (one *BOUNDARY line each).
LIFT = {i: 0.01 * (i + 1) for i in range(NX + 1)}


def abaqus_model() -> str:
    """The model as CAE writes one: a part placed by an identity instance, the sets and
    surface on the assembly, the amplitudes and materials at model level, a static step."""
    elements = file_elements()
    papillary, middle, beam_end = 101, 102, 103
    lines = ["*Heading", " every keyword, read back", '*Part, name="Patch"', "*Node"]
    lines += [f"{sheet_node(i, j)}, {float(i)!r}, {float(j)!r}, {float(surface_z(i))!r}"
              for j in range(NY + 1) for i in range(NX + 1)]
    lines += [f"{papillary}, " + ", ".join(map(repr, PAPILLARY)), f"{middle}, " + ", ".join(map(repr, MIDDLE)),
              f"{beam_end}, 4., 4., -2."]
    for kind, label in (("quad4", "S4R"), ("tri3", "S3R")):
        lines.append(f"*Element, type={label}, elset={'Belly' if kind == 'quad4' else 'Edge'}")
        lines += [", ".join(map(str, [e] + nodes)) for e, (k, nodes) in sorted(elements.items()) if k == kind]
    top, corner = sheet_node(NX // 2, NY), sheet_node(NX, NY)
    lines += ["*Element, type=T3D2, elset=Chord", f"201, {top}, {middle}", f"202, {middle}, {papillary}",
              "*Element, type=B31, elset=Strut", f"203, {corner}, {beam_end}",
              "*Nset, nset=Root, generate", f"1, {NX + 1}, 1", "*Nset, nset=Papillary", f"{papillary}, {beam_end}",
              "*Nset, nset=TipNode", str(top), "*Elset, elset=Centre", "2, 3",
              "*Distribution, name=Fibres, location=ELEMENT, Table=T", ", 1., 0., 0., 0., 1., 0."]
    lines += [f"{e}, " + ", ".join(map(repr, map(float, axis_of(e)))) + ", 0., 0., 1." for e in sorted(elements)]
    lines += ["*Orientation, name=Ori, local directions=2", "Fibres", "3, 0.", "0.8660254, 0.5, 0.",
              "0.8660254, -0.5, 0.",
              "*Shell Section, elset=Belly, material=Leaflet, orientation=Ori", f"{BELLY}, 5",
              "*Shell Section, elset=Edge, material=Leaflet, orientation=Ori", f"{EDGE}, 5",
              "*Solid Section, elset=Chord, material=Chorda", "0.2",
              "*Beam Section, elset=Strut, material=Chorda, section=CIRC", "0.3", "0., 0., -1.",
              "*End Part", "*Assembly, name=Assembly", "*Instance, name=Patch-1, part=Patch", "*End Instance",
              "*Elset, elset=_Quads, internal, instance=Patch-1", "Belly,",
              "*Elset, elset=_Triangles, internal, instance=Patch-1", "Edge,",
              "*Surface, type=ELEMENT, name=Top", "_Quads, SPOS", "_Triangles, SNEG", "*End Assembly",
              "*Amplitude, name=Ramp", "0., 0., 1., 1.",
              "*Amplitude, name=Beat, definition=SMOOTH STEP", "0., 0., 0.5, 1.",
              "*Material, name=Leaflet", "*Density", "1.1e-9",
              "*Anisotropic Hyperelastic, holzapfel, local directions=2", "0.025, 0., 0.2, 3., 0.1",
              "*Material, name=Chorda", "*Density", "1.2e-9", "*Hyperelastic, ogden, n=1", "0.5, 12., 0.",
              "*Boundary", "Patch-1.Root, ENCASTRE", "Patch-1.Papillary, 1, 2",
              "*Step, name=Close, nlgeom=YES", "*Static", "0.1, 1., 1e-05, 0.1",
              "*Boundary, amplitude=Ramp"]
    lines += [f"Patch-1.{sheet_node(i, NY)}, 3, 3, {LIFT[i]!r}" for i in range(NX + 1) if i != NX // 2]
    lines += ["*Dsload, amplitude=Beat", "Top, P, 0.01", "*Cload, amplitude=Ramp", "Patch-1.TipNode, 1, 0.1",
              "*Output, field, variable=PRESELECT", "*End Step"]
    return "\n".join(lines) + "\n"


def test_an_abaqus_model_comes_back_whole(tmp_path):
    path = tmp_path / "valve_patch.inp"
    path.write_text(abaqus_model())
    model = read_foreign(path)
    mesh, tables = model.mesh, model.tables
    # every node where the file put it
    grid = np.array([(i, j, surface_z(i)) for j in range(NY + 1) for i in range(NX + 1)], dtype=float)
    file_nodes = np.vstack([grid, PAPILLARY, MIDDLE, (4.0, 4.0, -2.0)])
    found, gap = nearest(file_nodes, mesh.x)
    assert gap.max() <= 1e-12 and len(set(found)) == len(file_nodes)
    inner = np.setdiff1d(np.flatnonzero((mesh.x[:, 0] >= 1.0) & (mesh.x[:, 0] <= NX - 1.0)), found[-3:])
    np.testing.assert_allclose(mesh.x[inner, 2], surface_z(mesh.x[inner, 0]), atol=1e-3 * CURL * NX**2)
    # sets, named after the instance where they are the part's
    root = mesh.sets["Patch-1_Root"]
    assert set(found[: NX + 1]) <= set(root.nodes) and len(root.nodes) == 4 * NX + 1
    assert sorted(map(tuple, mesh.x[mesh.sets["Patch-1_Papillary"].nodes])) == sorted([PAPILLARY, (4.0, 4.0, -2.0)])
    pieces = np.array([file_element_under(mesh.x[c]) for c in mesh.conn[:, 8]])
    assert sorted(set(pieces[mesh.sets["Patch-1_Centre"].elements])) == [2, 3]
    assert sorted(set(pieces[mesh.sets["Patch-1_Belly"].elements])) == [e for e in file_elements() if e < 100]
    # each piece keeps its element's axis 1 from the distribution; each section its thickness
    assert tables["material"]["axes"] == {"kind": "mesh", "field": "Fibres"}
    np.testing.assert_allclose(mesh.cell_vectors["Fibres"], np.array([axis_of(e) for e in pieces]), atol=1e-12)
    assert np.all(np.isfinite(mesh.thickness))
    for node, index in enumerate(found[: len(grid)]):
        touching = [e for e, (_, nodes) in file_elements().items() if node + 1 in nodes]
        assert mesh.thickness[index] == pytest.approx(np.mean([BELLY if e < 100 else EDGE for e in touching]))
    material = tables["material"]
    assert (material["model"], material["mu"], material["k1"], material["k2"], material["kappa"],
            material["density"]) == ("hgo", 0.05, 0.2, 3.0, 0.1, 1.1e-9)
    assert material["beta_deg"] == pytest.approx(30.0, abs=1e-5)
    # supports, and the top row's lift one value per node as one prescribed motion
    boundary = {(b["type"], b["set"]): b for b in tables["boundary"]}
    assert ("clamped", "Patch-1_Root") in boundary
    assert boundary["fixed", "Patch-1_Papillary"]["translations"] == ["x", "y"]
    lift, = (b for b in tables["boundary"] if b["type"] == "prescribed")
    assert (lift["translation"], lift["curve"]) == ("z", "Ramp")
    field = mesh.point_fields[lift["field"]] * lift["value"]
    for i, value in LIFT.items():
        if i != NX // 2:
            assert field[found[sheet_node(i, NY) - 1]] == pytest.approx(value, rel=1e-12)
    # the pressure on both sides of the surface (SPOS on the quads, SNEG on the triangles),
    # the nodal force, the amplitudes
    assert_sheet_loads(mesh, tables["load"], pieces)
    assert tables["curves"]["Ramp"] == {"t": [0.0, 1.0], "value": [0.0, 1.0]}
    assert tables["curves"]["Beat"] | {"extrapolate": None} == {"t": [0.0, 0.5], "value": [0.0, 1.0],
                                                                "interpolate": "smooth_step", "extrapolate": None}
    # the truss and the beam as cables, each with its section's area and the Ogden law
    cables = {cable["set"]: cable for cable in tables["cable"]}
    assert cables["Patch-1_Chord"]["area"] == 0.2
    assert cables["Patch-1_Strut"]["area"] == pytest.approx(np.pi * 0.09)
    assert all(c["law"] == {"model": "ogden", "mu": 0.5, "alpha": 12.0} and c["density"] == 1.2e-9
               for c in cables.values())
    np.testing.assert_allclose(np.sort(np.linalg.norm(np.diff(mesh.x[mesh.lines], axis=1)[:, 0], axis=1)),
                               np.sort([np.linalg.norm(np.subtract(MIDDLE, (2.0, 3.0, surface_z(2.0)))),
                                        np.linalg.norm(np.subtract(PAPILLARY, MIDDLE)),
                                        np.linalg.norm(np.subtract((4.0, 4.0, -2.0), (4.0, 3.0, surface_z(4.0))))]))
    assert tables["solver"]["method"] == "static" and tables["solver"]["end_time"] == 1.0
    assert tables["section"]["points_through_thickness"] == 3  # the sections' 5 Simpson points
    # nothing listed but what has no counterpart
    expected = [r"8 triangle\(s\) \(first at valve_patch\.inp:\d+\): each split into three quads",
                r"1 B31 beam element\(s\) \(first at valve_patch\.inp:\d+\).*tension only",
                r"output requests \(\*OUTPUT, first at valve_patch\.inp:\d+\)",
                r"\*SHELL SECTION \(valve_patch\.inp:\d+\): 5 section points become points_through_thickness = 3"]
    assert all(any(re.search(pattern, line) for line in model.unmapped) for pattern in expected), model.unmapped
    assert len(model.unmapped) == len(expected), model.unmapped


@pytest.mark.parametrize("data, law", [
    # three terms of one exponent, as Abaqus writes a one-term fit, the D_i on a second line
    (["0.1, 12., 0.2, 12., 0.05, 12., 0., 0.", "0."], {"model": "ogden", "mu": [0.1, 0.2, 0.05],
                                                      "alpha": [12.0, 12.0, 12.0]}),
    # two distinct terms and a third of negative exponent
    (["0.1, 12., 0.02, 4., -0.01, -2., 0., 0.", "0."], {"model": "ogden", "mu": [0.1, 0.02, -0.01],
                                                       "alpha": [12.0, 4.0, -2.0]}),
])
def test_the_chords_ogden_law_of_three_terms_comes_over_term_by_term(tmp_path, data, law):
    """A chord's ``*HYPERELASTIC, OGDEN, N=3`` becomes its cable's Ogden law with the three
    terms in order (nothing listed about the chords), which the deck accepts."""
    from shellsim.loads.cable_laws import Ogden

    path = tmp_path / "valve_patch.inp"
    path.write_text(abaqus_model().replace("*Hyperelastic, ogden, n=1\n0.5, 12., 0.\n",
                                           "*Hyperelastic, ogden, n=3\n" + "\n".join(data) + "\n"))
    model = read_foreign(path)
    assert [c["law"] for c in model.tables["cable"]] == [law, law]
    assert not [line for line in model.unmapped if "Chorda" in line or "1D law" in line]
    Ogden(**law)


def test_each_section_s_material_comes_over_as_a_part_of_its_own(tmp_path):
    """The triangles' section names a material of its own (neo-Hooke, C10 = 0.5): the deck
    has two [[material]] tables, the quads' HGO law with its fibre axes on the belly's set
    and the neo-Hookean one on the edge's, nothing listed about a material, and
    ``shellsim import`` writes a deck that ``check`` accepts with each part's law."""
    from typer.testing import CliRunner

    from shellsim.cli import app

    path = tmp_path / "valve_patch.inp"
    path.write_text(abaqus_model().replace("*Shell Section, elset=Edge, material=Leaflet, orientation=Ori",
                                           "*Shell Section, elset=Edge, material=Stiff")
                    + "*Material, name=Stiff\n*Density\n1.3e-9\n*Hyperelastic, neo hooke\n0.5, 0.\n")
    model = read_foreign(path)
    belly, edge = model.tables["material"]
    assert belly["model"] == "hgo" and belly["sets"] == ["Patch-1_Belly"] and belly["axes"]["kind"] == "mesh"
    assert edge == {"sets": ["Patch-1_Edge"], "model": "neo_hookean", "C1": 0.5, "density": 1.3e-9}
    assert not [line for line in model.unmapped if "material" in line.lower()], model.unmapped
    runner = CliRunner()
    result = runner.invoke(app, ["import", str(path), "--out", str(tmp_path / "deck")])
    assert result.exit_code == 0, result.output
    checked = runner.invoke(app, ["check", str(tmp_path / "deck" / "deck.toml")])
    said = " ".join(checked.output.replace("│", " ").split())
    assert checked.exit_code == 0, checked.output
    assert "hgo (" in said and "on 'Patch-1_Belly'" in said and "neo_hookean (C1=0.5, density=1.3e-09) on 'Patch-1_Edge'" in said


def test_user_materials_come_over_by_one_mapping_each_with_its_constants(tmp_path):
    """Both leaflet sections' materials are user materials of one law, W = C0/2 (I1 - 3)
    + C1/2 (exp(C2 (I1 - 3)^2) - 1), with their own constants: one --user-material
    mapping (Lee-Sacks at delta = 1) brings each over as its own [[material]] table with
    its constants and density, and ``check`` accepts the deck; without it each is listed
    with its constants and the option to use; a mapping that does not read is refused."""
    from typer.testing import CliRunner

    from shellsim.cli import app

    path = tmp_path / "valve_patch.inp"
    path.write_text(abaqus_model()
                    .replace("*Anisotropic Hyperelastic, holzapfel, local directions=2\n0.025, 0., 0.2, 3., 0.1",
                             "*User Material, constants=3\n0.0676, 0.0133, 38.19")
                    .replace("*Shell Section, elset=Edge, material=Leaflet", "*Shell Section, elset=Edge, material=Edge")
                    + "*Material, name=Edge\n*Density\n1.3e-9\n*User Material, constants=3\n0.05, 0.02, 14.86\n")
    mapping = "lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1"
    runner = CliRunner()
    result = runner.invoke(app, ["import", str(path), "--out", str(tmp_path / "deck"), "--user-material", mapping])
    assert result.exit_code == 0, result.output
    from shellsim.deck import load_deck

    deck = load_deck(tmp_path / "deck" / "deck.toml")
    laws = [(m.sets, m.model, m.c0, m.c1, m.c2, m.c3, m.delta, m.density) for m in deck.material]
    assert laws == [(["Patch-1_Belly"], "lee_sacks", 0.0676, 0.0133, 38.19, 0.0, 1.0, 1.1e-9),
                    (["Patch-1_Edge"], "lee_sacks", 0.05, 0.02, 14.86, 0.0, 1.0, 1.3e-9)]
    assert runner.invoke(app, ["check", str(tmp_path / "deck" / "deck.toml")]).exit_code == 0
    notes = read_foreign(path).unmapped
    assert any(re.search(r"user material 'Edge' \(constants 0\.05, 0\.02, 14\.86\): map its law with shellsim import "
                         r"--user-material", line) for line in notes), notes
    refused = runner.invoke(app, ["import", str(path), "--out", str(tmp_path / "other"), "--user-material",
                                  "lee_sacks: c0 = first"])
    assert refused.exit_code == 2 and "--user-material" in refused.output and "Traceback" not in refused.output
