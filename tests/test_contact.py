"""Contact with rigid tools: the penalty's push against the closed-form geometry of each
tool, a plate dropped on a plane that bounces back to its height with the energy kept,
a thin ring squeezed between two plates against the classical ring solution, and the
deck's word on a tool it cannot use."""

from __future__ import annotations

import json

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.errors import DeckError
from shellsim.geometry import build_mesh
from shellsim.loads import calibrate, step_share
from shellsim.model import build_model
from shellsim.solver.explicit import EXTERNAL, INTERNAL, KINETIC

from .conftest import deck_text, initial_external_forces, initial_shape, run_deck

PLATE = 'builder = "rectangle"\nlength = 1.0\nwidth = 1.0'


def tool_forces(tool: str, lift: float = 0.0, thickness: float = 0.02):
    """(f (n, 3), g (n, 3), x (n, 3), model) of a flat 2 x 2 plate at z = ``lift`` against
    ``tool`` (a [[contact]] table's keys), the springs set to 1 per unit mass at dt = 1."""
    text = deck_text(PLATE, f'[mesh]\ndivisions = {{ length = 2, width = 2 }}\n[[contact]]\ntype = "rigid_tool"\n'
                            f'name = "tool"\n{tool}\n').replace("thickness = 0.01", f"thickness = {thickness}")
    deck = parse_deck(text)
    mesh = build_mesh(deck)
    mesh.x[:, 2] += lift
    model = build_model(deck, mesh)
    calibrate(model, np.ones(model.n_nodes), np.ones(model.n_nodes), 1.0)
    f, g = initial_external_forces(model)
    return f, g, model.x0, model


def test_a_plane_pushes_each_face_point_below_it_out_by_the_spring_times_the_depth():
    """The plate's bottom face at z = -0.01 - 0.005 under a plane through z = 0 facing +z:
    every node is pushed up by k times the depth 0.015 (k = 0.1 / (1 + (h/2)^2) here),
    and the push at the bottom face turns the director by its lever arm -h/2."""
    f, g, x, model = tool_forces('shape = "plane"\nnormal = [0.0, 0.0, 1.0]', lift=-0.005)
    k = 0.1 / (1.0 + 0.01**2)
    np.testing.assert_allclose(f[:, 2], k * 0.015, rtol=1e-12)
    np.testing.assert_allclose(f[:, :2], 0.0, atol=1e-15)
    np.testing.assert_allclose(g[:, 2], -0.01 * k * 0.015, rtol=1e-12)


@pytest.mark.parametrize(("shape", "centre", "axis"), [("sphere", [0.5, 0.5, -0.9], None),
                                                        ("cylinder", [0.0, 0.5, -0.9], [1.0, 0.0, 0.0])])
def test_a_sphere_and_a_cylinder_push_along_their_radius_by_the_depth(shape, centre, axis):
    """A tool of radius 0.95 under the plate, its bottom face touching: the face points
    inside it are pushed out along the tool's radius, by k times R minus their distance;
    those outside feel nothing."""
    keys = f'shape = "{shape}"\nradius = 0.95\npoint = {centre}\nfaces = "bottom"' + (f"\naxis = {axis}" if axis else "")
    f, _, x, model = tool_forces(keys, thickness=0.02)
    k = 0.1 / (1.0 + 0.01**2)
    bottom = x - 0.01 * model.d0
    off = bottom - centre
    if axis is not None:
        off -= np.outer(off @ axis, axis)
    distance = np.linalg.norm(off, axis=1)
    inside = distance < 0.95
    assert inside.sum() >= 3 and (~inside).sum() >= 3
    expected = (k * (0.95 - distance))[:, None] * off / distance[:, None]
    np.testing.assert_allclose(f[inside], expected[inside], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(f[~inside], 0.0, atol=1e-15)


def test_the_gap_to_a_tool_is_the_clearance_of_the_nearest_face_and_its_springs_hold_k_gap_squared_over_two():
    """The plate 0.1 above a plane through z = 0 (h = 0.02): every node's gap is its bottom
    face's height, 0.1 - h/2, and the springs hold nothing; 0.005 below it, the overlap
    -0.015 as a negative gap, and each node's spring k 0.015^2 / 2 and the k w^2 / 6 its
    smoothing over the width w = TOUCHING h/2 adds (its push is k d past w)."""
    from shellsim.loads import ToolForces
    from shellsim.loads.penalty_law import TOUCHING

    k = 0.1 / (1.0 + 0.01**2)
    for lift, expected in ((0.1, 0.09), (-0.005, -0.015)):
        _, _, _, model = tool_forces('shape = "plane"\nnormal = [0.0, 0.0, 1.0]', lift=lift)
        shape = initial_shape(model)
        np.testing.assert_allclose(ToolForces(model, []).gaps(0.0, shape), expected, rtol=1e-12)
        stored = ToolForces(model, ["tool"])(0.0, shape)["tool_energy"]
        smoothing = k * (TOUCHING * 0.01) ** 2 / 6 if expected < 0.0 else 0.0
        assert stored == pytest.approx(model.n_nodes * (0.5 * k * min(expected, 0.0) ** 2 + smoothing), rel=1e-12,
                                       abs=1e-300)


def test_the_critical_step_falls_by_the_stated_factor():
    _, _, _, model = tool_forces('shape = "plane"\nnormal = [0.0, 0.0, 1.0]\npenalty = 0.5')
    assert step_share(model) == pytest.approx(1.0 / np.sqrt(1.0 + 0.5 / 4.0), rel=1e-15)


def test_a_plate_dropped_on_a_plane_bounces_back_to_its_height_keeping_its_energy():
    """A free plate 0.09 above a rigid plane falls under gravity, bounces and rises again:
    frictionless and elastic, the contact gives back what it took, so the plate returns to
    within 1% of its drop height (a ballistic closed form) and the energy balance
    (internal + kinetic - external work, gravity's and the contact's) stays within 1% of
    the largest kinetic energy. Measured: the peak after the bounce is 0.12% of the drop
    short of the start, the balance within 4e-7 of the largest kinetic energy."""
    text = deck_text(PLATE, '''
[mesh]
divisions = { length = 2, width = 2 }
points = { centre = [0.5, 0.5, 0.0] }
[[load]]
type = "body_force"
value = [0.0, 0.0, -9.81]
[[contact]]
type = "rigid_tool"
name = "floor"
shape = "plane"
point = [0.0, 0.0, -0.1]
normal = [0.0, 0.0, 1.0]
[[output.probe]]
name = "height"
quantity = "displacement"
set = "centre"
component = "z"
''').replace("E = 1000.0", "E = 1.0e4").replace("thickness = 0.01", "thickness = 0.02")
    text = text.replace("end_time = 1.0", "end_time = 0.30")
    run = run_deck(parse_deck(text))
    height = np.asarray(run.history["height"])
    times = np.asarray(run.times)
    lowest = int(np.argmin(height))
    assert height[lowest] == pytest.approx(-0.09, abs=2e-3)  # the bottom face reached the floor
    assert np.max(run.history["floor"]) > 0.0 and run.history["floor"][-1] == 0.0
    after = height[lowest:]
    assert after.max() == pytest.approx(0.0, abs=0.01 * 0.09), (after.max(), times[lowest + np.argmax(after)])
    energies = np.asarray(run.energies)
    balance = energies[:, INTERNAL] + energies[:, KINETIC] - energies[:, EXTERNAL]
    assert np.abs(balance).max() <= 0.01 * energies[:, KINETIC].max()


def ring_between_plates(tool: str, solver: str, h: float = 0.1, around: int = 8, E: float = 1.2e6) -> str:
    """The deck of a ring (R = 10, length 1, nu = 0; a quarter, its symmetry planes held,
    ``around`` elements over it) under a rigid plate on its top named 'plate' (``tool``:
    its [[contact]] keys past the set), the top's displacement probed as 'top', solved by
    the ``solver`` table."""
    return deck_text(f'builder = "tube"\ninner_radius = {RING_RADIUS - h / 2}\nlength = 1.0', f'''
[mesh]
divisions = {{ around = {around}, axial = 1 }}
[[boundary]]
type = "symmetry"
set = "sym_x"
normal = [1.0, 0.0, 0.0]
[[boundary]]
type = "symmetry"
set = "sym_y"
normal = [0.0, 1.0, 0.0]
[[boundary]]
type = "symmetry"
set = "z0"
normal = [0.0, 0.0, 1.0]
[[contact]]
type = "rigid_tool"
name = "plate"
set = "wall"
{tool}
[[output.probe]]
name = "top"
quantity = "displacement"
set = "z0_y"
component = "y"
''').replace("E = 1000.0\nnu = 0.3", f"E = {E}\nnu = 0.0").replace("thickness = 0.01", f"thickness = {h}").replace(
        "[solver]\nend_time = 1.0", solver)


#: The rings' radius.
RING_RADIUS = 10.0


def plane_above(h: float) -> str:
    """A rigid plane touching the top of a ring of thickness h, facing it."""
    return f'shape = "plane"\npoint = [0.0, {RING_RADIUS + h / 2}, 0.0]\nnormal = [0.0, -1.0, 0.0]'


def crushed_against_elastica(run, h: float, E: float = 1.2e6):
    """(approach (m,), the plate's force per unit length over the elastica's (m,)) of a
    ring run of :func:`ring_between_plates` at its samples past 5% of the radius."""
    from shellsim.verify.elastica import load_at, load_path

    approach = -2.0 * np.asarray(run.history["top"])  # of the mid-surfaces, both plates
    load = 2.0 * np.asarray(run.history["plate"])  # the quarter carries half the plate's load, per unit length
    measured = approach > 0.05 * RING_RADIUS
    path = load_path(20, approach.max() / RING_RADIUS + 0.05)
    return approach[measured], load[measured] / load_at(approach[measured], RING_RADIUS, E * h**3 / 12, path)


@pytest.mark.parametrize("plate", ["plane", "surface"])
def test_a_ring_squeezed_between_two_plates_meets_the_thin_ring_solution(plate, tmp_path):
    """A thin ring (R = 10, h = 0.1, nu = 0, a quarter with its symmetry planes) pressed by
    a plate on its top, solved statically: the change of the loaded diameter is
    (pi/4 - 2/pi) P R^3 / (E I) per unit length (Timoshenko, Strength of Materials I,
    curved bars; Roark's Formulas, Table 9.2 case 1), P the plate's force per unit
    length, at small deflection. Measured on 8 quadratic elements over the quarter (4 and
    16 give the same to 1e-5): +0.17% at a diameter change of 0.2% of R, +0.05% at
    0.04%, +0.78% at 1%: what is left is the geometric nonlinearity the linear solution
    leaves out, vanishing with the deflection. The plate is the analytic plane or the
    same plane as two triangles read from an STL file, moved by the static ramp: both
    meet the solution alike."""
    h, E = 0.1, 1.2e6
    if plate == "plane":
        tool = plane_above(h)
    else:  # its triangles facing -y, the ring's side
        import meshio

        corners = np.array([[-2.0, 0.0, -1.0], [-2.0, 0.0, 2.0], [12.0, 0.0, 2.0], [12.0, 0.0, -1.0]])
        meshio.write_points_cells(tmp_path / "plate.stl", corners, [("triangle", np.array([[0, 2, 1], [0, 3, 2]]))])
        tool = (f'shape = "surface"\nfile = "{(tmp_path / "plate.stl").as_posix()}"\n'
                f'point = [0.0, {RING_RADIUS + h / 2}, 0.0]')
    solver = '[solver]\nmethod = "static"\nend_time = 1.0\nstatic = { newton = "full" }'
    run = run_deck(parse_deck(ring_between_plates(f"{tool}\nmotion = [0.0, -0.01, 0.0]", solver, h=h, E=E)))
    diameter_change = -2.0 * run.history["top"][-1]
    load = 2.0 * run.history["plate"][-1]  # the quarter carries half the plate's load, per unit length
    expected = (np.pi / 4 - 2 / np.pi) * load * RING_RADIUS**3 / (E * h**3 / 12)
    assert 0.0 < diameter_change < 0.003 * RING_RADIUS
    assert diameter_change / expected == pytest.approx(1.0, abs=0.005)


def test_the_elastica_reference_tends_to_the_thin_ring_solution_as_the_load_vanishes():
    """The elastica of :mod:`shellsim.verify.elastica` under a small load P (R = EI = 1)
    is the linear thin ring's: an approach of (pi/4 - 2/pi) P, which it exceeds by a
    geometric nonlinearity proportional to the load (2.3e-3, 2.3e-4, 2.3e-5 of it at
    P = 0.02, 0.002, 0.0002); and its interpolation, at an approach of 0.2%, within 0.2%."""
    from shellsim.verify.elastica import load_at, point_phase

    excess = [point_phase(p)[0] / ((np.pi / 4 - 2 / np.pi) * 2 * p) - 1.0 for p in (1e-2, 1e-3, 1e-4)]
    assert excess[0] > 0.0 and excess[1] == pytest.approx(excess[0] / 10, rel=0.05)
    assert excess[2] == pytest.approx(excess[0] / 100, rel=0.05)
    assert 2e-3 / ((np.pi / 4 - 2 / np.pi) * load_at(2e-3, 1.0, 1.0)) == pytest.approx(1.0, abs=2e-3)


def test_a_ring_crushed_to_half_its_diameter_follows_the_elastica_through_its_flat_phase():
    """The ring of the test above (16 quadratic elements over the quarter) crushed
    statically until the plates have approached by 52% of its diameter: past 28% the ring
    lies flat along the plates over a growing length. The plates' force per unit length
    against their approach is the inextensible elastica's
    (:mod:`shellsim.verify.elastica`, shooting on Frisch-Fay's equations) at every load
    step, the flat phase included. Measured: within 0.01% up to the flat phase, 0.34% at
    most after it (the flat zone's edge moving from node to node); with a kinked penalty
    (push -k gap, no smoothing) load control stopped at 36% of the diameter."""
    from shellsim.verify.elastica import flat_phase_start

    h = 0.1
    solver = '[solver]\nmethod = "static"\nend_time = 1.0\nstatic = { newton = "full", increments = 20 }'
    run = run_deck(parse_deck(ring_between_plates(f"{plane_above(h)}\nmotion = [0.0, -5.2, 0.0]", solver, h=h,
                                                  around=16)))
    approach, ratio = crushed_against_elastica(run, h)
    assert run.times[-1] == 1.0 and approach[-1] > RING_RADIUS  # half the diameter, and on
    assert (approach > flat_phase_start() * RING_RADIUS).sum() >= 10  # well into the flat phase
    assert ratio == pytest.approx(1.0, abs=0.005)


def test_a_ring_crushed_by_a_moving_plate_comes_to_rest_explicitly_on_the_elastica():
    """The ring, thickened to h = 0.5 (R / h = 20), crushed explicitly by the plate moving
    down a quarter of the diameter over 4 s (about 2.7 periods of its slowest mode) and
    then held, with kinetic damping ([solver.relaxation]): the velocities are reset only
    once the plate has stopped, as a reset while it moves stops the nodes it pushes and
    it runs into them (with resets all along, this ring folded 9 elements just after the
    push). The ring comes to rest with the plates' force on the elastica's at
    its approach: measured +0.01% at 52% of the diameter, at rest 0.19 s after the plate
    stopped, 8 resets."""
    h = 0.5
    solver = """[solver]
end_time = 8.0
[solver.relaxation]
residual = 1e-4
[curves.push]
t = [0.0, 4.0, 8.0]
value = [0.0, 1.0, 1.0]
interpolate = "smooth"
"""
    run = run_deck(parse_deck(ring_between_plates(f'{plane_above(h)}\nmotion = [0.0, -2.6, 0.0]\ncurve = "push"',
                                                  solver, h=h, around=16)))
    relaxed = run.relaxing.record(run.sim)
    assert relaxed["relaxed_at"] is not None and relaxed["held_from"] == 4.0 and relaxed["resets"] >= 1
    approach, ratio = crushed_against_elastica(run, h)
    assert approach[-1] == pytest.approx(0.52 * RING_RADIUS, abs=0.01 * RING_RADIUS)
    assert ratio[-1] == pytest.approx(1.0, abs=0.003)


@pytest.mark.parametrize(("keys", "expected"), [
    ('shape = "sphere"', "shape = 'sphere' takes radius; missing radius"),
    ('shape = "plane"\nnormal = [0.0, 0.0, 1.0]\nradius = 1.0', "radius is not for it"),
    ('shape = "cylinder"\nradius = 1.0\naxis = [0.0, 0.0, 0.0]', "axis = [0.0, 0.0, 0.0] has no direction"),
    ('shape = "plane"\nnormal = [0.0, 0.0, 1.0]\nset = "x0"', "contact[0].set: set 'x0' is a edge set"),
    ('shape = "plane"\nnormal = [0.0, 0.0, 1.0]\ncurve = "push"', "contact[0].curve: unknown curve 'push'"),
])
def test_a_tool_the_scene_cannot_use_is_named_in_the_deck(keys, expected):
    text = deck_text(PLATE, f'[[contact]]\ntype = "rigid_tool"\nname = "tool"\n{keys}\n')
    with pytest.raises(DeckError) as caught:
        parse_deck(text)
    assert expected in str(caught.value)


def test_check_names_each_tool_with_its_cost(tmp_path):
    from typer.testing import CliRunner

    from shellsim.cli import app

    deck = tmp_path / "tool.toml"
    deck.write_text(deck_text(PLATE, '[[contact]]\ntype = "rigid_tool"\nname = "punch"\nshape = "sphere"\n'
                                     'radius = 0.3\npoint = [0.5, 0.5, -0.4]\nmotion = [0.0, 0.0, 0.2]\n'))
    checked = CliRunner().invoke(app, ["check", str(deck)])
    said = " ".join(checked.output.replace("│", " ").split())  # the summary table's cells, unwrapped
    assert checked.exit_code == 0, checked.output
    assert "'punch': rigid sphere of radius 0.3 at [0.5, 0.5, -0.4], the shell outside, moving by [0.0, 0.0, 0.2]" in said
    assert "penalty 0.1, the critical step x 0.988 (" in said and " nodes)" in said


def test_a_plate_pressed_on_a_plane_takes_the_pressure_everywhere(tmp_path):
    """A distorted 4 x 4 plate lying on a rigid plane, pushed onto it by a pressure p on its
    top face (in-plane motion held), solved statically: equilibrium puts p on every node
    (a uniform state the consistent loads and the mass-proportional springs both carry
    exactly: the plate sinks evenly and stays flat), so the contact pressure field is p
    at every point of the frame and the tool's force is p A (the contact patch test's
    uniform state, against a rigid plane; the issue asks for 1% and 0.5%). Measured: both
    to 3e-15, one load step of 4 iterations."""
    import meshio
    from typer.testing import CliRunner

    from shellsim.cli import app

    p = 2.0e3
    deck = tmp_path / "pressed.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0\n', f'''
[mesh]
divisions = {{ length = 4, width = 4 }}
boundaries_y0 = [0.0, 0.2, 0.45, 0.7, 1.0]
boundaries_y1 = [0.0, 0.3, 0.5, 0.8, 1.0]
[[boundary]]
type = "fixed"
set = "all"
translations = ["x", "y"]
[[load]]
type = "pressure"
value = {p}
face = "top"
[[contact]]
type = "rigid_tool"
name = "floor"
shape = "plane"
point = [0.0, 0.0, -0.01]
normal = [0.0, 0.0, 1.0]
[output]
fields = ["displacement", "contact_pressure", "contact_gap"]
formats = ["vtu"]
''').replace("thickness = 0.01", "thickness = 0.02").replace("end_time = 1.0", 'method = "static"\nend_time = 1.0'))
    ran = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert ran.exit_code == 0, ran.output
    (last,) = sorted((tmp_path / "out" / "frames").glob("*.vtu"))[-1:]
    frame = meshio.read(last).point_data
    np.testing.assert_allclose(frame["contact_pressure"], p, rtol=1e-9)
    # the gap field: the bottom face started on the plane, so its overlap is how far the
    # plate sank (the penalty's give; the thickness is kept)
    assert np.all(frame["contact_gap"] < 0.0)
    np.testing.assert_allclose(frame["contact_gap"], frame["displacement"][:, 2], rtol=1e-9)
    import csv

    rows = list(csv.DictReader((tmp_path / "out" / "history.csv").open()))
    assert float(rows[-1]["floor"]) == pytest.approx(p * 1.0, rel=1e-9)
    assert float(rows[-1]["floor_area"]) == pytest.approx(1.0, rel=1e-12)  # every node touches: the plate's area
    contact = json.loads((tmp_path / "out" / "summary.json").read_text())["contact"]
    assert contact["us_per_evaluation"] > 0.0 and "share_of_step" not in contact  # a static solve has no steps
