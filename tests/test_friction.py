"""Coulomb friction of contacts, against the closed form of a block on a floor: a plate
resting on a rigid plane, or on a clamped plate, under gravity g and then a sideways
body force a slides at the acceleration a - mu g when a > mu g and stays put when
a < mu g (the friction caps at mu times the contact force and holds below it); a moving
floor drags it up to its own speed; friction's work is mu times the weight times the
slide, and the energy balance closes with it; so too in implicit time steps; a static deck
with friction is refused, and so is an implicit one with a rigid tool's."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from shellsim.bench import stacked_plates
from shellsim.cli import app
from shellsim.deck import parse_deck
from shellsim.errors import DeckError
from shellsim.solver.explicit import EXTERNAL, FRICTION, INTERNAL, KINETIC

from .conftest import deck_text, run_deck

MU, G = 0.3, 9.81  # the friction coefficient, gravity
#: gravity is ramped on smoothly until SETTLED (so that the contact springs hardly ring
#: about the weight), the pull acts from then on, to the run's end T
SETTLED, T = 0.1, 0.4
LOADS = f'''
[[load]]
type = "body_force"
{{on}}value = [0.0, 0.0, {-G}]
curve = "settle"
[[load]]
type = "body_force"
{{on}}value = [{{pull}}, 0.0, 0.0]
curve = "pull"
[curves.settle]
t = [0.0, {SETTLED}]
value = [0.0, 1.0]
interpolate = "smooth"
[curves.pull]
t = [0.0, {SETTLED}]
value = [0.0, 1.0]
interpolate = "step"
[[output.probe]]
name = "slide"
quantity = "displacement"
set = "centre"
component = "x"
'''


def on_a_plane(pull: float) -> str:
    """A free 2 x 2 plate (h = 0.02) whose bottom face rests on a rigid plane, under
    gravity and the sideways body force ``pull``."""
    return deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', f'''
[mesh]
divisions = {{ length = 2, width = 2 }}
points = {{ centre = [0.5, 0.5, 0.0] }}
[[contact]]
type = "rigid_tool"
name = "floor"
shape = "plane"
point = [0.0, 0.0, -0.01]
normal = [0.0, 0.0, 1.0]
friction = {MU}
''' + LOADS.format(on="", pull=pull)).replace("thickness = 0.01", "thickness = 0.02")


def on_a_plate(pull: float, tmp_path) -> str:
    """A free 3 x 3 plate resting on a clamped 4 x 4 one (h = 0.01, their faces touching),
    under gravity and the sideways body force ``pull``."""
    return deck_text(f'builder = "file"\npath = "{stacked_plates(tmp_path / "plates.vtu", 4, 3).as_posix()}"', f'''
[mesh]
points = {{ centre = [0.5, 0.5, 0.01] }}
[[boundary]]
type = "clamped"
set = "lower"
[[contact]]
type = "shells"
name = "floor"
set = "upper"
against = "lower"
friction = {MU}
''' + LOADS.format(on='set = "upper"\n', pull=pull))


@pytest.mark.parametrize("floor", ["plane", "plate"])
@pytest.mark.parametrize("pull", [2.0 * MU * G, 0.5 * MU * G])
def test_a_plate_pulled_along_a_floor_slides_at_the_pull_less_friction_or_stays(floor, pull, tmp_path):
    """Pulled by a = 2 mu g the plate slides by (a - mu g) t^2 / 2 in the time t the pull
    acts, within 1%; pulled by a = mu g / 2 it sticks, moving less than 2% of what it
    would slide without friction. Measured (plane, plate): the slide +0.64% and +0.83%
    (the friction reaches mu N only once the slip outruns the stick damper's speed, a
    few a dt_c); the sticking plate 1.7% and 0.68%: the regularisation lets it creep at
    the speed the pull gives the contact's mass in a critical step (4.0 and 3.2 a dt_c
    here, the rest of the masses the contact moves counted). Sliding, friction takes mu
    m g times the slide out of the plate (the floor stands still), within 1% (measured:
    -0.39% and -0.42%: below mu N while the slip is slower than the stick damper's
    speed); the energy balance (internal + kinetic + friction - external work) stays
    within 1% of the largest kinetic energy."""
    text = on_a_plane(pull) if floor == "plane" else on_a_plate(pull, tmp_path)
    run = run_deck(parse_deck(text.replace("end_time = 1.0", f"end_time = {T}")))
    slide = run.history["slide"][-1]
    energies = np.asarray(run.energies)
    if pull > MU * G:
        assert slide == pytest.approx(0.5 * (pull - MU * G) * (T - SETTLED) ** 2, rel=0.01)
        weight = 1.0 * 1.0 * (0.02 if floor == "plane" else 0.01) * G  # density 1, unit plate, h
        assert energies[-1, FRICTION] == pytest.approx(MU * weight * slide, rel=0.01)
    else:
        assert abs(slide) < 0.02 * 0.5 * pull * (T - SETTLED) ** 2
    balance = energies[:, INTERNAL] + energies[:, KINETIC] + energies[:, FRICTION] - energies[:, EXTERNAL]
    assert np.abs(balance).max() <= 0.01 * energies[:, KINETIC].max()


@pytest.mark.parametrize("pull", [2.0 * MU * G, 0.5 * MU * G])
def test_implicit_steps_slide_and_stick_a_plate_on_a_plate_as_the_closed_form_says(pull, tmp_path):
    """The plate on the clamped plate again, in 160 implicit time steps (HHT, the
    friction opposing each iterate's Newmark velocities, its derivative in the tangent):
    the same bounds as the explicit loop's. Measured: the slide +0.43% (80 steps: +5.0%,
    320: -0.37%: the pull's jump falls inside a step), the sticking plate 0.20% of the
    free slide, friction's work -0.19% of mu m g times the slide. Sliding, the balance
    stays within 1% of the largest kinetic energy (measured: 0.02%: alpha's damping of the
    springs' ringing as the plate settles, 4.4e-7, which the balance does not count,
    against friction's 3.9e-3); sticking, that damping is all there is to see."""
    text = on_a_plate(pull, tmp_path).replace(
        "end_time = 1.0", f'method = "implicit"\nend_time = {T}\nimplicit = {{ increments = 160 }}')
    run = run_deck(parse_deck(text))
    slide = run.history["slide"][-1]
    energies = np.asarray(run.energies)
    if pull > MU * G:
        assert slide == pytest.approx(0.5 * (pull - MU * G) * (T - SETTLED) ** 2, rel=0.01)
        assert energies[-1, FRICTION] == pytest.approx(MU * 0.01 * G * slide, rel=0.01)
        balance = energies[:, INTERNAL] + energies[:, KINETIC] + energies[:, FRICTION] - energies[:, EXTERNAL]
        assert np.abs(balance).max() <= 0.01 * energies[:, KINETIC].max()
    else:
        assert abs(slide) < 0.02 * 0.5 * pull * (T - SETTLED) ** 2


def test_a_plate_on_a_moving_belt_is_dragged_up_to_its_speed(tmp_path):
    """The rigid plane under the resting plate starts moving along itself at V (a belt):
    friction drags the plate at mu g until it runs with the belt, so after t it has
    moved by V t - V^2 / (2 mu g), within 1% (measured: -0.06%). Run as a user runs it:
    summary.json tells what the contact cost, a share of the step, and the history has
    friction's work: the belt's drag puts in the plate's kinetic energy (the work is its
    negative, within 1%)."""
    speed = 0.3
    text = on_a_plane(0.0).replace("friction = ", 'motion = [1.0, 0.0, 0.0]\ncurve = "belt"\nfriction = ') + f"""
[curves.belt]
t = [{SETTLED}, {T}]
value = [0.0, {speed * (T - SETTLED)}]
"""
    deck = tmp_path / "belt.toml"
    deck.write_text(text.replace("end_time = 1.0", f"end_time = {T}"))
    ran = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert ran.exit_code == 0, ran.output
    rows = list(csv.DictReader((tmp_path / "out" / "history.csv").open()))
    moving = T - SETTLED
    assert float(rows[-1]["slide"]) == pytest.approx(speed * moving - speed**2 / (2.0 * MU * G), rel=0.01)
    assert float(rows[-1]["friction_work"]) == pytest.approx(-float(rows[-1]["kinetic_energy"]), rel=0.01)
    contact = json.loads((tmp_path / "out" / "summary.json").read_text())["contact"]
    assert contact["us_per_evaluation"] > 0.0 and contact["share_of_step"] > 0.0  # timed: no bound the load could break


def test_friction_on_a_static_solve_is_refused_with_the_key_named():
    text = on_a_plane(1.0).replace("end_time = 1.0", 'method = "static"\nend_time = 1.0')
    with pytest.raises(DeckError, match=r"contact\[0\]\.friction = 0\.3: .* a static solve has none"):
        parse_deck(text)


def test_a_rigid_tools_friction_on_an_implicit_solve_is_refused_with_the_key_named():
    """An implicit step takes the friction between shells, whose derivative it has; a
    rigid tool's is refused, not ignored."""
    text = on_a_plane(1.0).replace("end_time = 1.0", 'method = "implicit"\nend_time = 1.0')
    with pytest.raises(DeckError, match=r"contact\[0\]\.friction = 0\.3: .* not on a 'rigid_tool' contact"):
        parse_deck(text)


def test_mass_scaling_calibrates_the_contact_springs_on_the_scaled_masses(tmp_path):
    """The pressed plates with friction, every mass scaled to four times the first step:
    the contact springs are set again on the scaled masses and the scaled structure's
    step, so their stiffness stays what it was (k = s m / dt^2: the factors cancel) while
    friction's sticking impulse, m / dt, is the scaled nodes' (it was the unscaled ones',
    1 / sqrt(16) of it)."""
    from .conftest import pressed_plates_deck, prepared

    def deck(solver: str):
        return parse_deck(pressed_plates_deck(tmp_path / "plates.vtu", 0.01, solver, more="friction = 0.3"))

    plain = prepared(deck("[solver]\nend_time = 1e-3\ndamping = 50.0"))
    structure = float(plain.sim.critical_time_step())  # the shell's own, at rest
    scaled = run_deck(deck(f"[solver]\nend_time = 1e-3\ndamping = 50.0\nmass_scaling = {{ step = {4.0 * structure!r} }}"))
    contact = next(b for b in scaled.model.loads if b is not None and hasattr(b, "face_inverse_mass"))
    s = scaled.sim.state
    np.testing.assert_allclose(contact.inverse_mass, 1.0 / s.mt[contact.nodes], rtol=1e-12)
    assert scaled.sim.mass_factor > 10.0
    critical = np.sqrt(contact.penalty / contact.spring)  # the step the springs were set for
    np.testing.assert_allclose(critical, structure * np.sqrt(scaled.sim.mass_factor), rtol=1e-3)
