"""Contact between shells: the nearest point of a quadratic face against brute force,
two plates with non-matching meshes pressed together (the contact patch test's uniform
state, statically and settled explicitly), a plate dropped on another keeping its
energy, Test 4's strip rolled one and a half turns lying in two turns one thickness
apart or folded onto itself by a pressure, and the deck's word on a contact it cannot
use."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from shellsim.bench import stacked_plates
from shellsim.cli import app
from shellsim.deck import parse_deck
from shellsim.element.shape import NODE_RS, shape
from shellsim.errors import DeckError
from shellsim.geometry import build_mesh
from shellsim.loads import ToolForces
from shellsim.loads.contact_search import nearest_point, projection_scratch
from shellsim.mesh import NamedSet
from shellsim.output.fields import contact_pressure, output_mesh
from shellsim.output.mesh_files import write_mesh_vtu
from shellsim.solver.explicit import EXTERNAL, INTERNAL, KINETIC

from .conftest import PLATE_THICKNESS as H
from .conftest import ROOT, deck_text, initial_shape, pressed_plates, pressed_plates_deck, run_deck


def test_the_nearest_point_of_a_curved_face_is_the_nearest_of_a_fine_sampling():
    """A distorted, curved 9-node face and 300 points around it, some over its edges and
    corners: the projected Newton's distance is never above the least distance to the
    face sampled on a 801 x 801 grid of (r, s), and within that grid's resolution below
    it (a point found off the face, or a local minimum, would fail one or the other):
    a sample lies within delta of the nearest point, delta the grid step times the
    face's largest stretch, so the sampled distance exceeds the true one d by at most
    sqrt(d^2 + delta^2) - d."""
    rng = np.random.default_rng(7)
    x = np.column_stack([0.5 * NODE_RS, 0.1 * NODE_RS[:, 0] ** 2 + 0.05 * NODE_RS[:, 1]]) + rng.normal(0, 0.02, (9, 3))
    grid = np.linspace(-1.0, 1.0, 801)
    r, s = np.meshgrid(grid, grid)
    samples = shape(np.column_stack([r.ravel(), s.ravel()])) @ x
    rs, point, normal = np.empty(2), np.empty(3), np.empty(3)
    scratch = projection_scratch()
    stretch = np.linalg.norm(np.diff(samples.reshape(801, 801, 3), axis=0), axis=-1).max()
    stretch = max(stretch, np.linalg.norm(np.diff(samples.reshape(801, 801, 3), axis=1), axis=-1).max())
    for y in rng.normal(0.0, 0.6, (300, 3)):
        distance = nearest_point(x, np.arange(9), y, rs, point, normal, scratch)
        assert np.all(np.abs(rs) <= 1.0)
        np.testing.assert_allclose(point + distance * normal, y, atol=1e-12)
        sampled = np.linalg.norm(samples - y, axis=1).min()
        assert distance <= sampled + 1e-12
        assert sampled - distance <= np.hypot(distance, stretch) - distance


@pytest.mark.parametrize("method", ["static", "explicit"])
def test_a_plate_pressed_on_another_with_a_mesh_of_its_own_takes_the_pressure_everywhere(tmp_path, method):
    """The contact patch test (Taylor & Papadopoulos 1991) on shells: a 3 x 3 plate pressed
    by p onto a clamped 4 x 4 plate (non-matching meshes, node against face both ways).
    In equilibrium the contact must carry p at every point of the pressed plate: the
    contact pressure field there is p within 1% everywhere (the issue's bound), the
    contact force p A within 0.5%, and the mid-surfaces lie the two half thicknesses
    apart, within the penalty's give (the spring k = s m / dt_c^2 of each node leaves a
    depth of p A_node / k, a few 1e-5 of H here) and its smoothing width (1e-3 H).
    Measured, statically and settled explicitly alike: the field 0.99924 to 1.00072 p,
    the force p A to 1e-7, the separation 0.99985 to 0.99994 H. The clamped plate's
    nodes take the spread of the pressed plate's nodes by the faces' shape functions
    (0.69 to 2.04 p A_node): node against face passes the patch test on the side whose
    nodes are pressed, not on the other side, as is known of it."""
    p = 0.01
    run = pressed_plates(tmp_path / "plates.vtu", p, method)
    upper, lower = run.mesh.sets["upper"].nodes, run.mesh.sets["lower"].nodes
    pressure = contact_pressure(run.sim, output_mesh(run.model))
    np.testing.assert_allclose(pressure[upper], p, rtol=0.01)
    assert run.history["between"][-1] == pytest.approx(p * 1.0, rel=0.005)
    # every node of both plates touches: each plate's area, counted once
    assert run.history["between_area"][-1] == pytest.approx(1.0, rel=1e-12)
    separation = run.sim.state.x[upper, 2] - run.sim.state.x[lower, 2].mean()
    assert np.all(separation < H * (1.0 + 1e-3)) and np.all(separation > H * (1.0 - 1e-3))


def test_a_step_held_short_by_dt_max_sets_the_springs_on_the_critical_step_it_stands_for(tmp_path):
    """The patch test's plates, explicit: the springs are set on the structure's critical
    step dt_c (k = s m / dt_c^2); with solver.dt_max an eighth of the step at rest, on the
    critical step that step stands for, dt_max x dt_safety_factor / share (share = 1 /
    sqrt(1 + s / 2), the penalties' part of the step): springs as much stiffer as the
    shorter step bears, and no stiffer: pressed from rest, 400 steps are not stopped as
    unstable, the balance within 2% of the work (measured -1.3% as the springs engage;
    -0.6% over the same time without the cap) and every node of the upper plate above the
    lower plate's top."""
    from shellsim.loads import step_share

    from .conftest import prepared

    def deck(solver: str):
        return parse_deck(pressed_plates_deck(tmp_path / "plates.vtu", 0.01, solver))

    plain = prepared(deck("[solver]\nend_time = 1e-3\ndamping = 50.0"))
    structure = float(plain.sim.critical_time_step())
    contact = next(b for b in plain.model.loads if b is not None and hasattr(b, "face_inverse_mass"))
    # a second estimate of the same step: equal to the Lanczos iteration's tolerance
    np.testing.assert_allclose(np.sqrt(contact.penalty / contact.spring), structure, rtol=1e-3)
    cap = structure / 8.0
    capped = run_deck(deck(f"[solver]\nend_time = {400 * cap!r}\ndamping = 50.0\ndt_max = {cap!r}"))
    contact = next(b for b in capped.model.loads if b is not None and hasattr(b, "face_inverse_mass"))
    stands_for = cap * capped.deck.solver.dt_safety_factor / step_share(capped.model)
    np.testing.assert_allclose(np.sqrt(contact.penalty / contact.spring), stands_for, rtol=1e-12)
    assert stands_for < 0.25 * structure  # springs over 16 times stiffer
    assert capped.status == "completed" and capped.sim.state.steps == 400
    assert abs(capped.balance_error) < 0.02 * capped.sim.state.energy[EXTERNAL]
    lower_top = capped.sim.state.x[capped.mesh.sets["lower"].nodes, 2].mean() + H / 2
    assert np.all(capped.sim.state.x[capped.mesh.sets["upper"].nodes, 2] > lower_top)


def test_a_plate_dropped_on_another_bounces_back_keeping_its_energy(tmp_path):
    """A free 3 x 3 plate 0.02 above a clamped 4 x 4 one falls under gravity, bounces and
    rises again: frictionless and elastic, the contact gives back what it took, so the
    energy balance (internal + kinetic - external work, gravity's and the contact's)
    stays within 1% of the largest kinetic energy (the issue's bound). The plates are
    not rigid: the impact sets both ringing (its nodes meet the other's faces at
    different places, with springs of their own), so the plate rises back short of its
    drop by what rings on. Measured: the balance within 5.4e-4 of the largest kinetic
    energy; the plate back to 92% of its drop."""
    text = deck_text(f'builder = "file"\npath = "{stacked_plates(tmp_path / "drop.vtu", 4, 3, 0.02).as_posix()}"', '''
[mesh]
points = { centre = [0.5, 0.5, 0.03] }
[[boundary]]
type = "clamped"
set = "lower"
[[load]]
type = "body_force"
set = "upper"
value = [0.0, 0.0, -9.81]
[[contact]]
type = "shells"
name = "between"
set = "upper"
against = "lower"
[[output.probe]]
name = "height"
quantity = "displacement"
set = "centre"
component = "z"
''').replace("E = 1000.0", "E = 1.0e4").replace("end_time = 1.0", "end_time = 0.14")
    run = run_deck(parse_deck(text))
    height = np.asarray(run.history["height"])
    lowest = int(np.argmin(height))
    assert height[lowest] == pytest.approx(-0.02, abs=1e-3)  # it reached the lower plate
    assert max(run.history["between"]) > 0.0 and run.history["between"][-1] == 0.0
    assert 0.0 < max(run.history["between_area"]) <= 1.0 + 1e-12 and run.history["between_area"][-1] == 0.0
    assert height[lowest:].max() > -0.5 * 0.02  # it bounced
    energies = np.asarray(run.energies)
    balance = energies[:, INTERNAL] + energies[:, KINETIC] - energies[:, EXTERNAL]
    assert np.abs(balance).max() <= 0.01 * energies[:, KINETIC].max()


ROLLED = ROOT / "decks" / "verification" / "test04_strip_rollup_static.toml"


def test_a_strip_rolled_one_and_a_half_turns_keeps_its_turns_one_thickness_apart(tmp_path):
    """Test 4's strip (L = 12, h = 0.1) under its end moment doubled, ramped to 0.7 of
    that (504 degrees of free rolling), solved statically with self-contact. The strip
    is clamped on a flat run-in (4 more elements, x < 0), so that the rolled end meets
    a face rather than the clamp: it slides on inside the first turn. Every node then
    stays at least 0.97 h from every face of the strip not near it along the strip (a
    node that crossed would come within 0 of one); where the turns touch (nodes within
    1.02 h of a face), the later turn's nodes lie inside the earlier turn and the
    earlier turn's outside the later (the sides the directors tell). Measured: nearest
    1.0003 h; the end's row of 3 nodes rests on the first turn and the 3 under it on the
    end, each on its side (under a uniform moment both turns keep one curvature, so
    they touch along a line), 206 load steps (361 before the Newton steps held their
    contact pairs after four iterations; 124 before a step was kept from moving a node
    near a face, relative to it, more than half its distance from it)."""
    flat, element = 4, 0.8
    text = ROLLED.read_text().split("[[reference]]")[0]
    deck = parse_deck(text.replace("length = 12.0", f"length = {12.0 + flat * element}")
                      .replace("length = 15,", f"length = {15 + flat},")
                      .replace("tip = [12.0,", f"tip = [{12.0 + flat * element},"))
    mesh = build_mesh(deck)
    run_in = np.flatnonzero(mesh.x[mesh.conn[:, 8], 0] < flat * element)
    sets = dict(mesh.sets) | {"run_in": NamedSet("surface", np.unique(mesh.conn[run_in]), elements=run_in)}
    path = tmp_path / "strip.vtu"
    write_mesh_vtu(dataclasses.replace(mesh, x=mesh.x - [flat * element, 0.0, 0.0], sets=sets), path)
    text = (text.replace('builder = "rectangle"\nlength = 12.0\nwidth = 0.5', f'builder = "file"\npath = "{path.as_posix()}"')
            .replace("divisions = { length = 15, width = 1 }\npoints = { tip = [12.0, 0.5, 0.0] }\n", "")
            .replace('set = "x0"', 'set = "run_in"').replace("-52.3598776", "-104.7197551")
            .replace("end_time = 4.0\nstatic = { increments = 10 }", 'end_time = 2.8\nstatic = { increments = 28, newton = "full" }')
            .replace("times = [0.4, 0.8, 1.2, 1.6, 2.0, 2.4, 2.8, 3.2, 3.6]", "times = [2.0]"))
    text = text.replace('[[output.probe]]\nname = "tip_u"', '[[contact]]\ntype = "shells"\nname = "fold"\n\n'
                                                               '[[output.probe]]\nname = "tip_u"', 1)
    run = run_deck(parse_deck(text))
    model, x = run.model, run.sim.state.x
    h = 0.1
    rs, point, normal = np.empty(2), np.empty(3), np.empty(3)
    scratch = projection_scratch()
    nearest, sides = np.full(model.n_nodes, np.inf), []
    for node in range(model.n_nodes):
        for nodes in model.conn:
            if abs(model.x0[nodes[8], 0] - model.x0[node, 0]) < 3.0:  # near it along the strip
                continue
            distance = nearest_point(x, nodes, x[node], rs, point, normal, scratch)
            if distance < nearest[node]:
                nearest[node] = distance
                director = scratch[0] @ run.sim.state.d[nodes]  # towards the first turn's inside
                on_the_inside = normal @ director > 0.0
                farther_along = model.x0[node, 0] > model.x0[nodes[8], 0]
        if nearest[node] < 1.02 * h:
            sides.append((farther_along, on_the_inside))
    assert nearest.min() > 0.97 * h, nearest.min() / h
    assert len(sides) >= 6 and any(later for later, _ in sides) and not all(later for later, _ in sides)
    assert all(later == inside for later, inside in sides), sides  # the later turn inside the earlier


def _crossings_and_nearest(s: np.ndarray, line: np.ndarray, apart: float) -> tuple[int, float]:
    """Of a planar polyline's points ``line`` (P, 2) at arc lengths ``s`` (P,): how many
    pairs of its segments farther than ``apart`` from each other along it cross, and the
    nearest any point comes to such a segment."""
    def side(a, b, c):
        return np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    crossings, nearest = 0, np.inf
    for i in range(len(line) - 1):
        for j in range(len(line) - 1):
            if abs(s[i] - s[j]) <= apart:
                continue
            a, b, c, d = line[i], line[i + 1], line[j], line[j + 1]
            crossings += side(a, b, c) * side(a, b, d) < 0 and side(c, d, a) * side(c, d, b) < 0
            t = np.clip((line[i] - c) @ (d - c) / ((d - c) @ (d - c)), 0.0, 1.0)
            nearest = min(nearest, np.linalg.norm(line[i] - c - t * (d - c)))
    return crossings // 2, nearest


@pytest.mark.parametrize("contact", [False, True])
def test_a_strip_folded_onto_itself_by_pressure_rests_on_itself_one_thickness_away(contact):
    """Test 4's strip made thicker (L = 12, h = 0.3, 15 elements) under a follower
    pressure of 260 on one face: it curls into a loop whose end comes back onto the
    strip near the clamp. Solved statically without contact, the end goes into the strip
    (the centre lines come within half a thickness: the scene needs contact). With
    self-contact, explicitly (the pressure ramped smoothly over 1.8, the motion damped,
    the density raised to 1.51 so that it comes to rest in 3; the static solve stalls as
    the end slides over the face, its residual stuck near 1e-4 of the force scale), it
    rests on the strip's face: the centre line never crosses itself, no point nearer than
    0.9 h to a part of the strip more than 3 away along it (the penalty gives a little
    under the fold's push), the fold pressing; the contact takes the shell's whole
    thickness (``own_surface_limit = 0``: with the default single-surface limit, 0.4 of
    the node spacing, the strip rests at 0.31 h). Measured: free, the centre lines 0.46 h
    apart; with contact, nearest 0.970 h, at rest (kinetic energy 1e-4 of the internal)."""
    h = 0.3
    text = (ROLLED.read_text().split("[[reference]]")[0]
            .replace('type = "edge_moment"\nset = "x1"\nvalue = [0.0, -52.3598776, 0.0]',
                     'type = "pressure"\nset = "all"\nvalue = -260.0')
            .replace("thickness = 0.1", f"thickness = {h}")
            .replace("times = [0.4, 0.8, 1.2, 1.6, 2.0, 2.4, 2.8, 3.2, 3.6]", "times = []"))
    if contact:
        text = (text.replace("density = 1.510e-4", "density = 1.51")
                .replace('method = "static"\nend_time = 4.0\nstatic = { increments = 10 }', "end_time = 3.0\ndamping = 10.0")
                .replace("t = [0.0, 4.0]\nvalue = [0.0, 1.0]", 't = [0.0, 1.8]\nvalue = [0.0, 1.0]\ninterpolate = "smooth"'))
        # the shell's whole thickness: its nodes are 0.4 apart, so the single-surface limit
        # (0.4 of that, 0.16) would let the turns come within about half of h
        text += '\n[[contact]]\ntype = "shells"\nname = "fold"\nown_surface_limit = 0.0\n'
    run = run_deck(parse_deck(text.replace("static = { increments = 10 }", "static = { increments = 40 }")))
    assert run.status == "completed"
    x0, x = run.model.x0, run.sim.state.x
    centre = np.flatnonzero(np.isclose(x0[:, 1], 0.5))  # the symmetry plane's line of nodes
    centre = centre[np.argsort(x0[centre, 0])]
    crossings, nearest = _crossings_and_nearest(x0[centre, 0], x[centre][:, [0, 2]], 3.0)
    if contact:
        energy = run.sim.state.energy
        assert crossings == 0 and nearest > 0.9 * h, (crossings, nearest / h)
        assert run.history["fold"][-1] > 0.0 and energy[KINETIC] < 1e-2 * energy[INTERNAL]
    else:
        assert nearest < 0.5 * h, nearest / h


@pytest.mark.parametrize(("keys", "expected"), [
    ('against = "nowhere"', "contact[0].against: unknown set 'nowhere'"),
    ('[[contact]]\ntype = "shells"\nname = "fold_area"', "contact[1].name: 'fold_area' is already a history column"),
    ('against = "x0"', "contact[0].against: set 'x0' is a edge set"),
    ("offset = 0.0", "contact[0].offset"),
])
def test_a_shell_contact_the_scene_cannot_use_is_named_in_the_deck(keys, expected):
    text = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', f'[[contact]]\ntype = "shells"\nname = "fold"\n{keys}\n')
    with pytest.raises(DeckError) as caught:
        parse_deck(text)
    assert expected in str(caught.value)


def test_check_names_each_shell_contact_with_its_cost(tmp_path):
    deck = tmp_path / "fold.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', '[[contact]]\ntype = "shells"\n'
                                                                                   'name = "fold"\npenalty = 0.2\n'))
    checked = CliRunner().invoke(app, ["check", str(deck)])
    said = " ".join(checked.output.replace("│", " ").split())
    assert checked.exit_code == 0, checked.output
    assert "'fold': shell faces of 'all' against itself, both ways, 1 x the half thicknesses apart" in said
    assert "penalty 0.2, the critical step x 0.953 (" in said
    # the forecast counts the contact's forces, timed on the model at rest
    assert re.search(r"per unit of simulated time; contact \d+% of each step at rest, more as it spreads", said), said


@pytest.mark.parametrize(("lift", "expected"), [(0.003, 0.003), (0.05, np.nan)])
def test_the_gap_between_two_plates_is_their_faces_clearance_within_the_search_s_reach(lift, expected, tmp_path):
    """Two plates (h = 0.01) with their facing faces ``lift`` apart: every node's gap is
    that clearance (to 1e-12), both ways; 0.05 apart, farther than the gaps are looked
    for (about a thickness), there is none to tell."""
    from shellsim.model import build_model

    text = deck_text(f'builder = "file"\npath = "{stacked_plates(tmp_path / "plates.vtu", 4, 3, lift).as_posix()}"',
                     '[[contact]]\ntype = "shells"\nname = "between"\nset = "upper"\nagainst = "lower"\n')
    deck = parse_deck(text)
    model = build_model(deck, build_mesh(deck))
    np.testing.assert_allclose(ToolForces(model, []).gaps(0.0, initial_shape(model)), expected, rtol=0, atol=1e-12)


def test_the_faces_keep_their_initial_thickness_as_the_shell_thins(tmp_path):
    """The plates 0.003 apart, their fibre lengths halved (as a stretched incompressible
    shell thins): the gaps stay 0.003. A contact whose thickness followed the fibre lengths
    would store spring energy no force accounts for (the held valve's creep)."""
    from shellsim.bundles import Shape
    from shellsim.model import build_model

    text = deck_text(f'builder = "file"\npath = "{stacked_plates(tmp_path / "plates.vtu", 4, 3, 0.003).as_posix()}"',
                     '[[contact]]\ntype = "shells"\nname = "between"\nset = "upper"\nagainst = "lower"\n')
    deck = parse_deck(text)
    model = build_model(deck, build_mesh(deck))
    thinned = Shape(x=model.x0.copy(), d=model.d0.copy(), e1=model.e1f0.copy(), h=0.5 * model.h0)
    np.testing.assert_allclose(ToolForces(model, []).gaps(0.0, thinned), 0.003, rtol=0, atol=1e-12)


def touching_plates(tmp_path):
    """(model, the upper plate's nodes, its contact's ToolForces) of two plates built
    touching (4 x 4 under 3 x 3), a contact 'between' them, the springs set to 1 per unit
    mass at dt = 1."""
    from shellsim.loads import calibrate
    from shellsim.model import build_model

    text = deck_text(f'builder = "file"\npath = "{stacked_plates(tmp_path / "plates.vtu", 4, 3).as_posix()}"',
                     '[[contact]]\ntype = "shells"\nname = "between"\nset = "upper"\nagainst = "lower"\n')
    deck = parse_deck(text)
    mesh = build_mesh(deck)
    model = build_model(deck, mesh)
    calibrate(model, np.ones(model.n_nodes), np.ones(model.n_nodes), 1.0)
    return model, mesh.sets["upper"].nodes, ToolForces(model, ["between"])


def upper_moved(model, upper, down: float, slide: float = 0.0):
    """The initial shape with the ``upper`` nodes moved ``down`` along -z and ``slide`` along x."""
    from shellsim.bundles import Shape

    x = model.x0.copy()
    x[upper, 2] -= down
    x[upper, 0] += slide
    return Shape(x=x, d=model.d0.copy(), e1=model.e1f0.copy(), h=model.h0.copy())


def test_the_contact_forces_are_the_derivative_of_the_energy_the_springs_hold(tmp_path):
    """Two plates built touching, then the upper one moved 0.002 into the lower: the
    energy the contact's springs hold (history column between_energy), differenced over
    a move of the upper plate along z, is less the contact force on it, both passes and
    the faces' shares counted (a conservative contact: its stored energy is what its
    forces did). Within the smoothing width too (a move of 5e-6)."""
    model, upper, measures = touching_plates(tmp_path)

    def moved(down: float):
        return upper_moved(model, upper, down)

    for down in (0.002, 5e-6):
        step = 1e-8
        slope = (measures(0.0, moved(down - step))["between_energy"]
                 - measures(0.0, moved(down + step))["between_energy"]) / (2.0 * step)
        force = measures.at_nodes(0.0, moved(down))[upper, 2].sum()
        assert force > 0.0 and slope == pytest.approx(-force, rel=1e-5)


def test_held_pairs_keep_each_node_on_its_face_until_released(tmp_path):
    """The plates 0.002 into each other, their pairs held (as a Newton step's later
    iterations hold them), then the upper plate slid 0.3 along x, past a lower element:
    each contact node keeps the face it touched, and those no longer over it push no
    more; released, the faces are searched again and every upper node pushes."""
    from shellsim.loads import contact_pairs, hold_pairs, pairs_added

    model, upper, measures = touching_plates(tmp_path)

    def pushing(slide: float) -> int:
        forces = measures.at_nodes(0.0, upper_moved(model, upper, 0.002, slide))
        return int(np.count_nonzero(np.linalg.norm(forces[upper], axis=1)))

    assert pushing(0.0) == len(upper)
    before = contact_pairs(model)
    hold_pairs(model, True)
    try:
        assert 0 < pushing(0.3) < len(upper)
        np.testing.assert_array_equal(contact_pairs(model)[0], before[0])
    finally:
        hold_pairs(model, False)
    assert pushing(0.3) == len(upper) and pairs_added(model, before) == 0


def test_a_plate_between_two_others_in_one_self_contact_is_pushed_from_both_sides(tmp_path):
    """Three like plates built stacked, then each moved 0.002 into the next, in one
    self-contact table over all three (as one table over a valve's three leaflets): a
    node of the middle plate touches a face of each of the other two and pushes both, so
    the middle plate, pressed equally from above and below, takes no net force, and the
    top and bottom plates take equal and opposite ones. With one face a node, the
    middle's nodes pushed only one (and this failed)."""
    from shellsim.bundles import Shape
    from shellsim.loads import calibrate
    from shellsim.mesh import Mesh
    from shellsim.model import build_model

    h, overlap = 0.01, 0.002
    plates = []
    for level in range(3):
        plate = build_mesh(parse_deck(deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0',
                                                "[mesh]\ndivisions = { length = 3, width = 3 }\n")))
        plate.x[:, 2] += level * h  # built touching: overlaps at rest would be ignored
        plates.append(plate)
    n, e = plates[0].n_nodes, plates[0].n_elements
    sets = {name: NamedSet("surface", np.arange(level * n, (level + 1) * n),
                           elements=np.arange(level * e, (level + 1) * e))
            for level, name in enumerate(("lower", "middle", "upper"))}
    sets["stack"] = NamedSet("surface", np.arange(3 * n), elements=np.arange(3 * e))
    path = tmp_path / "stack.vtu"
    write_mesh_vtu(Mesh(x=np.vstack([p.x for p in plates]), conn=np.vstack([p.conn + i * n for i, p in enumerate(plates)]),
                        director=np.vstack([p.director for p in plates]), thickness=np.full(3 * n, h), sets=sets), path)
    deck = parse_deck(deck_text(f'builder = "file"\npath = "{path.as_posix()}"',
                                '[[contact]]\ntype = "shells"\nname = "stacked"\nset = "stack"\n'))
    model = build_model(deck, build_mesh(deck))
    calibrate(model, np.ones(model.n_nodes), np.ones(model.n_nodes), 1.0)
    x = model.x0.copy()
    x[:, 2] -= overlap * np.repeat(np.arange(3), n)
    forces = ToolForces(model, ["stacked"]).at_nodes(0.0, Shape(x=x, d=model.d0.copy(), e1=model.e1f0.copy(),
                                                                  h=model.h0.copy()))
    lower, middle, upper = (forces[sets[name].nodes, 2].sum() for name in ("lower", "middle", "upper"))
    assert upper > 0.0 and lower == pytest.approx(-upper, rel=1e-12)
    assert abs(middle) <= 1e-12 * upper


def test_the_contact_forces_on_two_plates_are_action_and_reaction(tmp_path):
    """Every contact force on a node of one plate comes with its opposite on the other's:
    the nodal contact forces (the output field's) sum to zero."""
    run = pressed_plates(tmp_path / "plates.vtu", 0.01, "static")
    s = run.sim.state
    with_contact = ToolForces(run.model, ["between"]).at_nodes(s.t, s.fields.shape)
    assert np.abs(with_contact).max() > 0.0
    np.testing.assert_allclose(with_contact.sum(axis=0), 0.0, atol=1e-12)  # action and reaction


def test_two_flaps_pressed_together_coapt_as_a_cantilever_on_a_wall(tmp_path):
    """A valve's two leaflets closing, quasi-statically: two cantilevers (unit plates,
    h = 0.01, nu = 0, non-matching meshes of 16 and 12 elements along their length L,
    clamped along x = 0) with their facing faces 2 delta apart, pressed toward each other
    by p and solved statically with contact between them. By symmetry each lies on their
    mid-plane as a cantilever pressed on a rigid wall delta away: past p L^4 / (8 D) =
    delta its end lies flat on the wall, lifted over a = (72 D delta / p)^(1/4) from the
    clamp (the lifted part has w(0) = w'(0) = 0, and w = delta, w' = 0 and no moment at
    a), the wall taking the flat part's load and a line force p a / 3 at x = a: a contact
    force p (L - 2 a / 3) per unit width and a coapted length L - a (small deflection
    beam theory, D = E h^3 / 12). Here a = L / 2. Measured: the contact force +8.8e-7,
    the coapted length 0.512 (the contact area counts whole nodes' shares: within half
    an element). The solve (modified Newton, the default) takes 40 load steps of 3 to 24
    iterations (2 to 11 tangents), the longest where contact sets in and spreads; full
    Newton 29 steps, 7 iterations in the median. Without the check that no node passes
    through a face in a step, full Newton reached an equilibrium of crossed flaps in 4
    steps, with 20 times the contact force."""
    E, h, delta, a = 1000.0, 0.01, 0.01, 0.5
    D = E * h**3 / 12
    p = 72 * D * delta / a**4
    plates = stacked_plates(tmp_path / "flaps.vtu", (16, 2), (12, 2), lift=2 * delta, thickness=h)
    text = deck_text(f'builder = "file"\npath = "{plates.as_posix()}"', f'''
[[boundary]]
type = "clamped"
set = "x0"
[[boundary]]
type = "clamped"
set = "upper_x0"
[[load]]
type = "pressure"
set = "lower"
value = {p}
[[load]]
type = "pressure"
set = "upper"
value = {-p}
[[contact]]
type = "shells"
name = "coapted"
set = "upper"
against = "lower"
''').replace("nu = 0.3", "nu = 0.0").replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0')
    run = run_deck(parse_deck(text))
    assert run.history["coapted"][-1] == pytest.approx(p * (1.0 - 2 * a / 3), rel=0.01)
    assert run.history["coapted_area"][-1] == pytest.approx(1.0 - a, abs=0.5 / 12)
    assert len(run.newton) < 60 and max(step.iterations for step in run.newton) <= 30


def test_check_reports_shells_that_overlap_at_rest_with_how_many_how_deep_and_where(tmp_path):
    """The stacked plates 0.002 closer than their faces touching (thickness 0.01): every
    node of each plate overlaps the other's faces at rest (49 of the upper, 81 of the
    lower), by 0.002 (the offset's reach 0.01 less the distance 0.008); ``check`` says so
    with the count, the depth and a node, and that those faces are never pushed against.
    Faces that touch exactly at rest are not reported."""
    mesh = tmp_path / "plates.vtu"
    text = pressed_plates_deck(mesh, 1.0, '[solver]\nmethod = "static"\nend_time = 1.0')
    deck = tmp_path / "deck.toml"
    deck.write_text(text)
    touching = CliRunner().invoke(app, ["check", str(deck)], env={"COLUMNS": "60"})
    assert touching.exit_code == 0 and "overlap faces" not in touching.output, touching.output
    stacked_plates(mesh, 4, 3, lift=-0.002, thickness=H)
    result = CliRunner().invoke(app, ["check", str(deck)], env={"COLUMNS": "60"})
    said = " ".join(result.output.split())
    assert result.exit_code == 0, result.output
    assert re.search(r"contact 'between': 130 node\(s\) overlap faces of the other side at rest, by up to 0\.002 "
                     r"\(node \d+ at [-\d., e]+\): the faces a node overlaps at rest are never pushed against", said), said


def test_the_spacing_of_a_nine_node_quads_nodes_is_the_shorter_of_its_grid_lines():
    """A 4 x 6 element (nodes 2 and 3 apart along r and s): every node's spacing is 2."""
    from shellsim.loads.shell_contact import node_spacing

    x = np.column_stack([2.0 * NODE_RS[:, 0], 3.0 * NODE_RS[:, 1], np.zeros(9)])
    np.testing.assert_array_equal(node_spacing(x, np.arange(9)[None]), np.full(9, 2.0))


@pytest.mark.parametrize("limit", [0.0, 0.4])
def test_a_surface_finer_than_it_is_thick_does_not_touch_itself_at_rest(limit):
    """A flat strip of elements 0.1 long (nodes 0.05 apart) and 0.06 thick in self-contact:
    with its contact thickness the shell's, every node lies within the reach (0.06) of
    the faces next to those that hold it, overlapping them at rest; limited to 0.4 of the
    node spacing (LS-DYNA's single-surface rule), the reach is 0.02 and no node overlaps
    a face, each offset scaled by 0.4 x 0.05 / 0.06."""
    from shellsim.model import build_model

    text = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 0.2', f'''
[mesh]
divisions = {{ length = 10, width = 2 }}
[[contact]]
type = "shells"
name = "strip"
own_surface_limit = {limit}
''').replace("thickness = 0.01", "thickness = 0.06")
    deck = parse_deck(text)
    contact = build_model(deck, build_mesh(deck)).loads.shell_contact
    if limit:
        assert not np.any(contact.initial_depth > 0.0)
        np.testing.assert_allclose(contact.offset, 0.4 * 0.05 / 0.06, rtol=1e-9)
    else:
        assert np.count_nonzero(contact.initial_depth > 0.0) > len(contact.nodes) / 2


def test_a_face_s_search_box_is_grown_by_the_reach_of_its_own_pass(tmp_path):
    """Two strips in one self-contact (nodes 0.05 apart, 0.06 thick, 1 apart): a strip's
    faces, searched by its own nodes, have their boxes grown by those nodes' limited reach
    (0.4 x the spacing: offset 0.4 x 0.05 / 0.06, (0.02 + 0.02) / 2); searched by the other
    strip's nodes, by the whole thickness ((0.06 + 0.06) / 2). Grown by the table's largest,
    every face of a node's own surface near it had its nearest point searched."""
    from shellsim.loads.penalty_law import TOUCHING
    from shellsim.loads.shell_contact import _grid
    from shellsim.mesh import Mesh
    from shellsim.model import build_model

    strips = []
    for level in range(2):
        strip = build_mesh(parse_deck(deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 0.2',
                                                "[mesh]\ndivisions = { length = 10, width = 2 }\n")))
        strip.x[:, 2] += level
        strips.append(strip)
    n, e = strips[0].n_nodes, strips[0].n_elements
    path = tmp_path / "strips.vtu"
    write_mesh_vtu(Mesh(x=np.vstack([s.x for s in strips]), conn=np.vstack([strips[0].conn, strips[1].conn + n]),
                        director=np.vstack([s.director for s in strips]), thickness=np.full(2 * n, 0.06),
                        sets={"strips": NamedSet("surface", np.arange(2 * n), elements=np.arange(2 * e))}), path)
    deck = parse_deck(deck_text(f'builder = "file"\npath = "{path.as_posix()}"',
                                '[[contact]]\ntype = "shells"\nname = "both"\nset = "strips"\n'))
    model = build_model(deck, build_mesh(deck))
    loads = model.loads.shell_contact
    _grid(initial_shape(model), loads, 1.0)
    face_strip = loads.face_elements // e
    node_strip = {int(g): int(loads.nodes[loads.group == g][0] >= n) for g in np.unique(loads.group)}
    own = np.array([node_strip[int(g)] == s for g, s in zip(loads.face_group, face_strip)])
    assert own.any() and not own.all()
    np.testing.assert_allclose(loads.reach[own], 0.02 * (1.0 + TOUCHING), rtol=1e-9)
    np.testing.assert_allclose(loads.reach[~own], 0.06 * (1.0 + TOUCHING), rtol=1e-9)


def test_the_faces_listed_for_each_node_find_the_pairs_the_grid_finds_as_the_shells_slide(tmp_path):
    """Two stacked plates (6 x 6 on 5 x 5, touching) in one self-contact, the upper slid
    sideways in steps from far below the lists' skin to twice it, jittered: at every
    step each contact node takes the face a search of the whole grid takes, with the same
    forces, and the lists are made again only when the motion since they were made
    could have brought a face from outside a list within reach."""
    from shellsim.bundles import Shape
    from shellsim.loads import calibrate
    from shellsim.loads.shell_contact import (SKIN, _at_initial_thickness, _candidates, _contact_forces, _grid,
                                              _pair_forces, _work)
    from shellsim.model import build_model

    path = stacked_plates(tmp_path / "plates.vtu", 6, 5)
    deck = parse_deck(deck_text(f'builder = "file"\npath = "{path.as_posix()}"',
                                '[[contact]]\ntype = "shells"\nname = "both"\nset = "all"\n'))
    model = build_model(deck, build_mesh(deck))
    calibrate(model, np.ones(model.n_nodes), np.ones(model.n_nodes), 1.0)
    loads = model.loads.shell_contact
    upper = np.unique(model.conn[36:])
    rng = np.random.default_rng(1)
    x = model.x0.copy()
    relisted, steps, out = 0, 0, np.empty((10, 3))
    for step in np.geomspace(1e-3, 2.0, 12) * SKIN * 0.01:  # the reach is about the thickness, 0.01
        for _ in range(4):
            x[upper, 0] += step
            x[upper] += rng.uniform(-0.1, 0.1, (len(upper), 3)) * step
            shape = _at_initial_thickness(model, Shape(x=x, d=model.d0.copy(), e1=model.e1f0.copy(), h=model.h0.copy()))
            listed_at = loads.listed_at.copy()
            _contact_forces(model, shape, loads)
            relisted += not np.array_equal(listed_at, loads.listed_at)
            steps += 1
            listed_pairs, listed_forces = loads.touches.copy(), loads.touch_forces.copy()
            grid, work = _grid(shape, loads, 1.0), _work()
            searched = np.array([_candidates(shape, loads, m, grid, work, True) for m in range(len(loads.nodes))])
            np.testing.assert_array_equal(listed_pairs, searched)
            for m in np.flatnonzero(searched >= 0):  # the same forces, to the bit
                _pair_forces(shape.x, shape.h, loads, m, searched[m], out, work)
                np.testing.assert_array_equal(listed_forces[m], out)
    assert (listed_pairs >= 0).sum() > 50
    assert 2 < relisted < steps / 2
