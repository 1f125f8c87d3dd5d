"""A material per part (``[[material]]`` tables naming their surface sets): two laws side
by side in one uniaxial pull, each at its closed-form stress; two linear materials end to
end, the bar stretching by the composite bar's closed form; the answer unchanged, to the
last bit, when the parts' order in the deck changes; the assignment's gaps, overlaps and
missing sets refused by name."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.errors import MeshError
from shellsim.geometry import build_mesh
from shellsim.mesh import NamedSet
from shellsim.output.mesh_files import write_mesh_vtu

from .conftest import ROLLERS, deck_text, prepared, problems_of, run_deck

LENGTH, WIDTH, THICKNESS = 2.0, 1.0, 0.01


def halves(folder: Path, across: str, along: int = 4) -> Path:
    """A LENGTH x WIDTH strip of ``along`` x 2 elements written as a mesh file whose surface sets
    'first' and 'second' split it ``across`` 'x' (two halves end to end along x) or 'y'
    (side by side), with the rectangle builder's edge and corner sets."""
    mesh = build_mesh(parse_deck(deck_text(f'builder = "rectangle"\nlength = {LENGTH}\nwidth = {WIDTH}',
                                           f"[mesh]\ndivisions = {{ length = {along}, width = 2 }}\n")))
    centres = mesh.x[mesh.conn[:, 8]]
    middle = {"x": LENGTH / 2, "y": WIDTH / 2}[across]
    below = centres[:, "xy".index(across)] < middle
    for name, elements in (("first", np.flatnonzero(below)), ("second", np.flatnonzero(~below))):
        mesh.sets[name] = NamedSet("surface", np.unique(mesh.conn[elements]), elements=elements)
    path = folder / f"halves_{across}_{along}.vtu"
    write_mesh_vtu(mesh, path)
    return path


def pulled(path: Path, materials: str, stretch: float) -> str:
    """A static deck of the strip of ``path`` on rollers along x0 and y0, held in its
    plane, its edge x1 moved to ``stretch`` times the length, with the ``materials``
    tables."""
    return f'''
[meta]
title = "two parts pulled"

{materials}

[section]
thickness = {THICKNESS}

[geometry]
builder = "file"
path = "{path.as_posix()}"
{ROLLERS}
[[boundary]]
type = "prescribed"
set = "x1"
translation = "x"
value = {(stretch - 1.0) * LENGTH}

[solver]
method = "static"
end_time = 1.0
static = {{ increments = 4, newton = "full", force_tolerance = 1e-12, energy_tolerance = 1e-24 }}
'''


def _cauchy_xx(run, part: int) -> np.ndarray:
    """sigma_xx at every integration point of the elements of ``part``."""
    return run.sim.point_tensors()[1][run.model.body.part == part][..., 0, 0]


def test_two_laws_side_by_side_each_carry_their_closed_form_stress(tmp_path):
    """Incompressible neo-Hookean (C1 = 100) beside Mooney-Rivlin (C1 = 300, C2 = 50),
    side by side across the strip and pulled together to lambda = 1.4: a uniaxial
    stretch with lateral and normal stretches lambda^-1/2 is the exact state of both, so
    each part carries its own uniaxial Cauchy stress, 2 (lambda^2 - 1/lambda) C1 and
    2 (lambda^2 - 1/lambda) (C1 + C2 / lambda), to 1e-9 at every point."""
    stretch = 1.4
    materials = '''[[material]]
sets = ["first"]
model = "neo_hookean"
C1 = 100.0
density = 1.0

[[material]]
sets = ["second"]
model = "mooney_rivlin"
C1 = 300.0
C2 = 50.0
density = 1.0'''
    run = run_deck(parse_deck(pulled(halves(tmp_path, "y"), materials, stretch)))
    shape = 2.0 * (stretch**2 - 1.0 / stretch)
    np.testing.assert_allclose(_cauchy_xx(run, 0), shape * 100.0, rtol=1e-9)
    np.testing.assert_allclose(_cauchy_xx(run, 1), shape * (300.0 + 50.0 / stretch), rtol=1e-9)
    assert set(run.model.body.part) == {0, 1}


LINEAR = '''[[material]]
sets = ["{0}"]
model = "linear_elastic"
E = {1}
nu = 0.0
density = 1.0
'''


def test_two_materials_end_to_end_stretch_as_the_composite_bar(tmp_path):
    """Two linear elastic halves (E = 1000 and 3000, nu = 0) end to end along the pull,
    the far edge moved by u = 1e-6 L: one force N runs through both, so the halves'
    strains are N / (E_i A), N = u A / (L/2 (1/E1 + 1/E2)): the middle of the strip
    moves by N L / (2 E1 A) = u E2 / (E1 + E2) = 3/4 u, to 1e-6: the element's
    kinematics are those of large displacements, which leave the linear bar by terms of
    the order of the strain (measured: 3.7e-7)."""
    text = pulled(halves(tmp_path, "x"), LINEAR.format("first", 1000.0) + LINEAR.format("second", 3000.0), 1.0 + 1e-6)
    run = run_deck(parse_deck(text))
    middle = np.flatnonzero(np.isclose(run.mesh.x[:, 0], LENGTH / 2))
    u = 1e-6 * LENGTH
    np.testing.assert_allclose(run.sim.state.x[middle, 0] - LENGTH / 2, 0.75 * u, rtol=1e-6)


def test_the_parts_order_in_the_deck_leaves_the_answer_to_the_last_bit(tmp_path):
    """The side-by-side pull with its two materials listed the other way round: the
    groups of each part are formed in the other order, and every position is the same
    to the last bit (nodal sums are taken in one fixed order)."""
    path = halves(tmp_path, "y")
    first, second = LINEAR.format("first", 1000.0), LINEAR.format("second", 3000.0).replace("nu = 0.0", "nu = 0.3")
    one = run_deck(parse_deck(pulled(path, first + "\n" + second, 1.001)))
    other = run_deck(parse_deck(pulled(path, second + "\n" + first, 1.001)))
    assert np.array_equal(one.sim.state.x, other.sim.state.x)
    assert np.array_equal(one.sim.state.d, other.sim.state.d)
    assert not np.array_equal(one.model.body.part, other.model.body.part)


def test_an_assignment_with_gaps_overlaps_or_unnamed_parts_is_refused(tmp_path):
    """A set named by two materials, a material without sets beside another, an unknown
    or edge set, elements no material covers and elements two cover: each refused,
    naming the table, the set or the elements (numbered from 1)."""
    path = halves(tmp_path, "x")
    problems = problems_of(pulled(path, LINEAR.format("first", 1000.0) + LINEAR.format("first", 2000.0), 1.001))
    assert "material[1].sets: 'first' is already material[0]'s" in problems
    unnamed = LINEAR.format("first", 1000.0) + LINEAR.format("second", 2000.0).replace('sets = ["second"]\n', "")
    assert "material[1].sets: missing; with several materials each names the surface sets it covers" in problems_of(
        pulled(path, unnamed, 1.001))
    # a mesh file's sets are known once it is read
    with pytest.raises(MeshError, match="material\\[0\\].sets: unknown set 'frist'"):
        prepared(parse_deck(pulled(path, LINEAR.format("frist", 1.0), 1.001)))
    with pytest.raises(MeshError, match="material\\[0\\].sets: set 'x0' is a edge set; expected a surface set"):
        prepared(parse_deck(pulled(path, LINEAR.format("x0", 1.0), 1.001)))
    with pytest.raises(MeshError, match=r"4 element\(s\) are in no material's sets: elements 5, 6, 7, 8 \(the first at "):
        prepared(parse_deck(pulled(path, LINEAR.format("first", 1000.0), 1.001)))
    overlapping = LINEAR.format("first", 1000.0) + LINEAR.format("all", 2000.0)
    with pytest.raises(MeshError, match=r"4 element\(s\) are in the sets of several materials \(material\[0\], "
                                        r"material\[1\]\): elements 1, 2, 3, 4 "):
        prepared(parse_deck(pulled(path, overlapping, 1.001)))


def test_a_misspelt_key_of_one_part_s_table_is_named_with_its_part():
    """Each [[material]] table is checked as its law's: a misspelt key is named with the
    table's place and the keys that law takes."""
    text = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0').replace(
        "[material]", '[[material]]\nsets = ["all"]').replace("nu = 0.3", "nu = 0.3\nEE = 3.0")
    assert "material[0].EE (line 10): unknown key 'EE'; did you mean 'E'?; keys here: sets, model, E, nu, density" \
        in problems_of(text)


def test_one_material_split_into_parts_of_its_constants_is_the_same_scene(tmp_path):
    """The side-by-side pull with one material, and with that material written as two
    parts of the same constants: every position and director the same to the last bit
    (the parts' groups differ; the sums at the nodes are taken in one order)."""
    path = halves(tmp_path, "y")
    one = LINEAR.format("first", 1000.0).replace('sets = ["first"]\n', "").replace("[[material]]", "[material]")
    parts = LINEAR.format("first", 1000.0) + LINEAR.format("second", 1000.0)
    whole, split = (run_deck(parse_deck(pulled(path, text.replace("nu = 0.0", "nu = 0.3"), 1.001)))
                    for text in (one, parts))
    assert np.array_equal(whole.sim.state.x, split.sim.state.x)
    assert np.array_equal(whole.sim.state.d, split.sim.state.d)
    assert set(split.model.body.part) == {0, 1} and set(whole.model.body.part) == {0}


def test_a_strip_of_two_materials_end_to_end_bends_as_the_composite_beam(tmp_path):
    """A cantilever of the two linear halves end to end (E1 = 1000 at the clamp, E2 = 3000,
    nu = 0; 8 x 2 elements), a force P at its free end: the moment P (L - x) is the
    beam's whatever its stiffness, so the tip deflects by the stepped beam's
    P L^3 / (3 I) (7 / (8 E1) + 1 / (8 E2)), plus the shear's P L / (2 k A) (1/G1 + 1/G2)
    (k = 5/6), I = b h^3 / 12: within 0.2% (measured +0.06% at the corners to -0.03% in
    the middle, the same with 4, 8 and 16 elements along: the five equal nodal forces bend
    the free end across its width, which refining along the strip does not change)."""
    e1, e2, force = 1000.0, 3000.0, 1e-9
    text = pulled(halves(tmp_path, "x", along=8), LINEAR.format("first", e1) + LINEAR.format("second", e2), 1.0)
    text = text[:text.index("[[boundary]]")] + f'''
[[boundary]]
type = "clamped"
set = "x0"

[[load]]
type = "point_force"
set = "x1"
value = [0.0, 0.0, {force / 5}]

[solver]
method = "static"
end_time = 1.0
'''
    run = run_deck(parse_deck(text))
    tip = run.mesh.sets["x1"].nodes
    assert len(tip) == 5
    inertia, area = WIDTH * THICKNESS**3 / 12.0, WIDTH * THICKNESS
    bending = force * LENGTH**3 / (3.0 * inertia) * (7.0 / (8.0 * e1) + 1.0 / (8.0 * e2))
    shear = force * LENGTH / (2.0 * 5.0 / 6.0 * area) * (2.0 / e1 + 2.0 / e2)
    np.testing.assert_allclose(run.sim.state.x[tip, 2], bending + shear, rtol=2e-3)
