"""A valve engineer's model brought over whole: the synthetic atrioventricular valve of
:mod:`shellsim.verify.synthetic_valve` (three leaflets of one user law with their own
constants, per-element orientations, three chord groups of Ogden N=3 laws, per-node
annulus motion, papillary tips held node by node, SPOS pressure on a smooth step, general
contact with friction and a linear pressure-overclosure, variable mass scaling on the
chordae, mm-tonne-s, 5 section points) imported with one mapping of its user law gives a
deck that ``check`` accepts as written; each part is checked against the file."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from typer.testing import CliRunner

from scipy.spatial import cKDTree

from shellsim.cli import app
from shellsim.deck import load_deck
from shellsim.foreign.user_law import UserLaw
from shellsim.geometry.importing import read_mesh
from shellsim.imported_deck import import_model
from shellsim.verify.synthetic_valve import (CHORD_LAWS, FRICTION, LEAFLET_LAWS, LEAFLETS, MASS_SCALING_STEP,
                                             OVERCLOSURE_STIFFNESS, SHAPE, SyntheticValve, abaqus_text, febio_text)

#: A small valve: 3 x 4 x (2 + 1) = 36 shells, 15 chords of 3 elements to 6 tips.
VALVE = SyntheticValve(circumferential=4, belly=2, band=1, segments=3, tips=6)
LEE_SACKS = UserLaw.parse("lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1")


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("valve")
    source = folder / "valve.inp"
    source.write_text(abaqus_text(VALVE))
    return import_model(source, folder / "deck", LEE_SACKS)


def test_the_generated_leaflets_start_apart_near_closed_and_face_the_ventricle():
    """The builder's leaflets upside down: each leaflet's nodes the shape's gap from its
    neighbours' (no overlap at rest, the bands ready to meet), the free edges at z = -12,
    each leaflet's first row on the annulus ring (radius 15, z = 0) and moved, no other
    node (the sides free, as an atrioventricular valve's commissures), and every shell's normal
    toward the ventricle (down, and on the upright bands toward the leaflet's own side,
    e_g), so that the pressure on SPOS lifts the bellies and presses the bands together."""
    valve = SyntheticValve(circumferential=8, belly=4, band=2, segments=3, tips=6)
    leaflet_of = {node: g for _, g, corners in valve.shells for node in corners}
    by_leaflet = [np.array([p for label, p in valve.points.items() if leaflet_of[label] == g]) for g in range(3)]
    for g in range(3):
        nearest, _ = cKDTree(by_leaflet[(g + 1) % 3]).query(by_leaflet[g])
        assert nearest.min() == pytest.approx(SHAPE.gap, rel=1e-12)
        assert valve.points[valve.node(g, valve.rows, 4)][2] == pytest.approx(-SHAPE.height)
        for j in range(valve.circumferential + 1):
            x, y, z = valve.points[valve.node(g, 0, j)]
            assert (np.hypot(x, y), z) == pytest.approx((SHAPE.base_radius, 0.0), abs=1e-12)
    assert [label for label, _ in valve.annulus_motion()] == [valve.node(g, 0, j) for g in range(3)
                                                              for j in range(valve.circumferential + 1)]
    for _, g, corners in valve.shells:
        a, b, c, d = (valve.points[n] for n in corners)
        side = np.radians(90.0 + 120.0 * g)
        normal = np.cross(c - a, d - b)
        assert normal[2] < 0.0 or (normal[2] == pytest.approx(0.0, abs=1e-12) and
                                   normal @ [np.cos(side), np.sin(side), 0.0] > 0.0)


def test_the_imported_valve_checks_as_written(imported):
    """No problem in the deck as written, and ``shellsim check`` says ok."""
    assert imported.problems == []
    result = CliRunner().invoke(app, ["check", str(imported.deck)], env={"COLUMNS": "60"})
    assert result.exit_code == 0, result.output
    assert f"ok {imported.deck}" in " ".join(result.output.split())


def test_each_leaflet_comes_over_as_its_own_material_with_its_constants_and_axes(imported):
    """Three Lee-Sacks tables at delta = 1, each on its leaflet's set with the file's C0,
    C1, C2 and density; every shell's material axis the file's distribution vector of
    its element (found through the element ids the mesh keeps)."""
    deck = load_deck(imported.deck)
    assert len(deck.material) == 3
    for material, name, (c0, c1, c2) in zip(deck.material, LEAFLETS, LEAFLET_LAWS):
        assert material.sets == [f"Leaflet{name}"]
        assert (material.model, material.c0, material.c1, material.c2, material.c3, material.delta) == \
            ("lee_sacks", c0, c1, c2, 0.0, 1.0)
        assert material.density == 1.1e-9 and material.axes.kind == "mesh"
    mesh = read_mesh(imported.mesh)
    file_label = mesh.cell_fields["source_element"].astype(int)
    axes = mesh.cell_vectors[deck.material[0].axes.field]
    np.testing.assert_allclose(axes, VALVE.circumferential_axes()[file_label - 1], atol=1e-12)
    leaflet_of = {label: leaflet for label, leaflet, _ in VALVE.shells}
    for g, name in enumerate(LEAFLETS):
        elements = mesh.sets[f"Leaflet{name}"].elements
        assert {leaflet_of[label] for label in file_label[elements]} == {g}
    assert deck.section.points_through_thickness == 3 and deck.section.thickness == 0.4


def test_every_chord_comes_over_with_its_group_s_law_and_mass_scaling(imported):
    """Three cable tables, one per chord group, each with its Ogden terms as the file
    writes them (the equal exponents merged when the law is evaluated), every chord
    element in the mesh, and the variable mass scaling on the chordae as their
    ``min_step``."""
    deck = load_deck(imported.deck)
    assert [c.set for c in deck.cable] == [f"Chordae{name}" for name in LEAFLETS]
    for cable, terms in zip(deck.cable, CHORD_LAWS):
        assert cable.law.terms() == ([mu for mu, _ in terms], [alpha for _, alpha in terms])
        assert cable.min_step == MASS_SCALING_STEP
    assert imported.cables == len(VALVE.chords[1]) == 3 * 5 * 3
    assert deck.solver.mass_scaling is None


def test_supports_motion_pressure_contact_and_units_come_over(imported):
    """The papillary tips held node by node are one set and one table; the annulus moves
    node by node as the file says; 23 mmHg on the leaflets on the smooth step; one
    self-contact with the file's friction, the overclosure stiffness listed with its
    value; units mm-t-s."""
    deck = load_deck(imported.deck)
    mesh = read_mesh(imported.mesh)
    held = [b for b in deck.boundary if b.type == "fixed" and b.translations == ["x", "y", "z"]]
    assert len(held) == 1
    tips = {label for label, _, _ in VALVE.tip_positions}
    assert set(mesh.point_fields["source_node"][mesh.sets[held[0].set].nodes].astype(int)) == tips
    for b in (b for b in deck.boundary if b.type == "prescribed"):
        axis = "xyz".index(b.translation)
        for label, u in VALVE.annulus_motion():
            node = np.flatnonzero(mesh.point_fields["source_node"] == label)
            assert mesh.point_fields[b.field][node] == pytest.approx(u[axis], abs=1e-12)
    pressure, = deck.load
    assert pressure.curve == "Closing" and pressure.value == pytest.approx(-23 * 133.322387415e-6, rel=1e-12)
    assert deck.curves["Closing"].interpolate == "smooth_step"
    contact, = deck.contact
    assert contact.set == "all" and contact.against is None and contact.friction == FRICTION
    assert any(f"PRESSURE-OVERCLOSURE=LINEAR ({OVERCLOSURE_STIFFNESS})" in line for line in imported.unmapped)
    assert deck.meta.units == "mm-t-s" and imported.units == "mm-t-s"


def test_the_file_s_ids_are_kept_in_the_mesh_and_the_id_map(imported):
    """Every node of the file is a mesh node with its label as ``source_node`` at its own
    position, the new mid-edge nodes 0; ids.csv maps every node, shell and chord element."""
    mesh = read_mesh(imported.mesh)
    rows = list(csv.DictReader(imported.ids.open()))
    nodes = {int(r["label"]): int(r["index"]) for r in rows if r["kind"] == "node"}
    positions = dict(VALVE.points)
    positions |= {label: p for label, _, p in VALVE.tip_positions} | dict(VALVE.chords[0])
    assert set(nodes) == set(positions)
    for label, index in nodes.items():
        assert mesh.point_fields["source_node"][index] == label
        np.testing.assert_allclose(mesh.x[index], positions[label], atol=1e-9)
    assert np.count_nonzero(mesh.point_fields["source_node"] == 0) == len(mesh.x) - len(positions)
    assert sorted(int(r["label"]) for r in rows if r["kind"] == "element") == [label for label, _, _ in VALVE.shells]
    assert sorted(int(r["label"]) for r in rows if r["kind"] == "cable") == [e[0] for e in VALVE.chords[1]]


def test_the_febio_valve_brings_each_domain_over(tmp_path):
    """The FEBio version: three HGO tables with their constants on their leaflets, the
    per-element mat_axis, three truss cables, contact with friction, units mm-t-s."""
    source = tmp_path / "valve.feb"
    source.write_text(febio_text(VALVE))
    done = import_model(source, tmp_path / "deck")
    assert done.problems == []
    deck = load_deck(done.deck)
    assert [m.sets for m in deck.material] == [[f"Leaflet{name}"] for name in LEAFLETS]
    assert [m.k2 for m in deck.material] == [c2 for _, _, c2 in LEAFLET_LAWS]
    mesh = read_mesh(done.mesh)
    file_label = mesh.cell_fields["source_element"].astype(int)
    np.testing.assert_allclose(mesh.cell_vectors[deck.material[0].axes.field],
                               VALVE.circumferential_axes()[file_label - 1], atol=1e-12)
    assert [c.set for c in deck.cable] == [f"Chordae{name}" for name in LEAFLETS]
    assert deck.contact[0].friction == FRICTION and deck.meta.units == "mm-t-s"
