"""The lumen volume (``[output.lumen]``) against closed forms: a capped quarter tube at
rest, its inner and mid faces, converging under refinement at the order of the
interpolated circle; an inflated tube held at its ends against the inner radius its probe
reads; a rigid turn about the axis leaving it as it is; the deck table's names checked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.measures.lumen import resolve

from .conftest import deck_text, prepared, problems_of, run_deck

R_INNER, LENGTH, THICKNESS = 1.0, 3.0, 0.2


def _capped_tube(around: int, face: str) -> tuple[float, float]:
    """(measured, exact) lumen volume of a capped quarter tube at rest, bounded by its
    ``face``: a quarter cylinder of the face's radius r and LENGTH with an eighth of a
    sphere, pi r^2 LENGTH / 4 + pi r^3 / 6."""
    geometry = f'builder = "tube"\ninner_radius = {R_INNER}\nlength = {LENGTH}\ncap = "hemisphere"'
    text = deck_text(geometry, f"[mesh]\ndivisions = {{ around = {around}, axial = {2 * around} }}\n"
                     f'[output.lumen]\nface = "{face}"\n').replace("thickness = 0.01", f"thickness = {THICKNESS}")
    run = prepared(parse_deck(text))
    state = run.sim.state
    r = R_INNER + {"bottom": 0.0, "mid": 0.5 * THICKNESS}[face]
    return resolve(run.deck, run.mesh, run.model)(state.x, state.d, state.h), math.pi * r**2 * LENGTH / 4 + math.pi * r**3 / 6


@pytest.mark.parametrize("face", ["bottom", "mid"])
def test_a_capped_tube_s_lumen_converges_to_the_closed_form_at_the_interpolated_circle_s_order(face):
    """The faces are biquadratic through points on the circle and the sphere, so the
    volume's error falls at least 8x per halving of the elements (about 16x: h^4) and
    is below 1e-5 of the volume with 8 elements over the quarter."""
    errors = [abs(measured / exact - 1.0) for measured, exact in (_capped_tube(n, face) for n in (2, 4, 8))]
    assert errors[0] / errors[1] > 8.0 and errors[1] / errors[2] > 8.0
    assert errors[2] < 1e-5


def test_an_inflated_tube_held_at_its_ends_encloses_the_cylinder_of_its_inner_radius():
    """A quarter tube under inner pressure, held axially at both ends (a plane-strain
    ring), stays a cylinder: its lumen is pi r^2 L / 4 with r the inner radius its probe
    reads, at every sample, to the interpolated circle's 1e-5 at 8 elements over the
    quarter (the first test), while the volume grows by several percent."""
    geometry = f'builder = "tube"\ninner_radius = {R_INNER}\nlength = {LENGTH}'
    tables = "\n".join(f'[[boundary]]\ntype = "symmetry"\nset = "{s}"\nnormal = {n}\n' for s, n in
                       [("sym_x", "[1.0, 0.0, 0.0]"), ("sym_y", "[0.0, 1.0, 0.0]"), ("z0", "[0.0, 0.0, 1.0]"),
                        ("end", "[0.0, 0.0, 1.0]")])
    text = deck_text(geometry, f'''[mesh]
divisions = {{ around = 8, axial = 2 }}
{tables}
[[load]]
type = "pressure"
value = 10.0
face = "bottom"
curve = "ramp"

[curves.ramp]
t = [0.0, 1.0]
value = [0.0, 1.0]

[output]
interval = 0.25

[output.lumen]

[[output.probe]]
name = "inner_radius"
quantity = "position"
set = "z0_x"
component = "x"
face = "bottom"
''').replace("thickness = 0.01", f"thickness = {THICKNESS}").replace("end_time = 1.0", 'end_time = 1.0\nmethod = "static"')
    run = run_deck(parse_deck(text))
    volume, radius = np.asarray(run.history["lumen_volume"]), np.asarray(run.history["inner_radius"])
    assert len(volume) >= 5
    np.testing.assert_allclose(volume, math.pi * radius**2 * LENGTH / 4, rtol=1e-5)
    assert volume[-1] / volume[0] > 1.03
    record = run.measure("lumen").record(run, 0.0)
    assert record["initial"] == volume[0] and record["final"] == volume[-1]
    assert record["largest_over_initial"] == pytest.approx(volume.max() / volume[0], rel=1e-15)


def test_turning_the_tube_about_its_axis_leaves_its_lumen_as_it_is():
    """A rigid turn of the scene about the axis moves every face point and keeps the volume."""
    geometry = f'builder = "tube"\ninner_radius = {R_INNER}\nlength = {LENGTH}'
    run = prepared(parse_deck(deck_text(geometry, "[mesh]\ndivisions = { around = 4, axial = 2 }\n[output.lumen]\n")))
    state, lumen = run.sim.state, resolve(run.deck, run.mesh, run.model)
    angle = 0.7
    turn = np.array([[math.cos(angle), -math.sin(angle), 0.0], [math.sin(angle), math.cos(angle), 0.0], [0, 0, 1.0]])
    still = lumen(state.x, state.d, state.h)
    assert lumen(state.x @ turn.T, state.d @ turn.T, state.h) == pytest.approx(still, rel=1e-13)
    assert still > 0.0


def test_the_lumen_s_wall_is_a_surface_set_and_its_axis_a_direction():
    geometry = f'builder = "tube"\ninner_radius = {R_INNER}\nlength = {LENGTH}'
    assert "output.lumen.wall: set 'z0' is a edge set; expected a surface set here" in problems_of(
        deck_text(geometry, '[output.lumen]\nwall = "z0"\n'))
    assert "output.lumen.wall: unknown set 'wal'" in problems_of(deck_text(geometry, '[output.lumen]\nwall = "wal"\n'))
    assert "axis" in problems_of(deck_text(geometry, "[output.lumen]\naxis = [0.0, 0.0, 0.0]\n"))
