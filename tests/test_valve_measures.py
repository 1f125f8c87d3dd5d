"""Valve measures against what they must read: the area and widest opening of a square
hole in a plate, the opening between the aortic valve builder's leaflets (set by their
thickness, as a solid's shadow), the coaptation of two plates pressed together, the
peak principal stress of a strip in uniaxial tension and of a cantilever's bending away
from its clamp; the deck table's names checked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.mesh import NamedSet
from shellsim.measures.valve import Valve, fill_triangles, largest_principal, resolve_valve

from .conftest import PLATE_THICKNESS, ROLLERS, deck_text, pressed_plates, prepared, problems_of, run_deck

PLATE = 'builder = "rectangle"\nlength = 1.0\nwidth = 1.0'


def _rim(mesh) -> NamedSet:
    """The rectangle builder's boundary as one edge set."""
    return NamedSet("edge", np.unique(np.concatenate([mesh.sets[k].nodes for k in ("x0", "x1", "y0", "y1")])))


@pytest.mark.parametrize("shift, inside", [(0.0, 100), (0.3, 100), (0.7, 100), (0.5, 121)])
def test_a_pixel_is_filled_when_its_centre_lies_in_a_triangle(shift, inside):
    """Two triangles making a square of side 10 pixels hold 100 pixel centres wherever the
    square sits against the pixel grid, but where its sides run through centres: a centre
    on an edge is inside (11 x 11), so triangles sharing an edge leave no pixel between
    them. A sliver of no area holds none."""
    square = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]) + 2.0 + shift
    pixels = np.zeros((20, 20), dtype=bool)
    fill_triangles(pixels, np.array([square[[0, 1, 2]], square[[0, 2, 3]]]))
    assert pixels.sum() == inside
    sliver = np.zeros((20, 20), dtype=bool)
    fill_triangles(sliver, np.array([[[1.5, 1.5], [5.5, 5.5], [9.5, 9.5]]]))
    assert not sliver.any()


def test_a_square_hole_in_a_plate_is_the_orifice_and_its_side_the_widest_opening():
    """A unit plate of 4 x 4 elements with its middle 2 x 2 left out, seen along its
    normal inside its rim: the orifice is the hole, 0.25, to half a pixel along its edge
    (the raster 1000 pixels across), and the widest opening the hole's side, 0.5, to a
    pixel."""
    deck = parse_deck(deck_text(PLATE, "[mesh]\ndivisions = { length = 4, width = 4 }\n"))
    run = prepared(deck)
    run.mesh.sets["rim"] = _rim(run.mesh)
    centres = run.model.x0[run.model.conn[:, 8]]
    kept = np.flatnonzero(np.abs(centres[:, :2] - 0.5).max(axis=1) > 0.25)
    assert len(kept) == 12
    run.mesh.sets["holed"] = NamedSet("surface", np.unique(run.model.conn[kept]), elements=kept)
    measures = resolve_valve(Valve(leaflets="holed", annulus="rim", resolution=1000), run.mesh, run.model, 1.0)
    s = run.sim.state
    open_pixels, pixel = measures.opening(s.x, s.d, s.h, run.model.conn[kept])
    assert open_pixels.sum() * pixel**2 == pytest.approx(0.25, abs=0.5 * pixel * 2.0)  # half a pixel along the edge
    assert measures(run.sim)["regurgitant_gap"] == pytest.approx(0.5, abs=pixel)


VALVE = '''builder = "aortic_valve"
gap = 0.55'''
VALVE_OUTPUT = '''
[output.valve]
annulus = "attachment"
resolution = 2000
'''


@pytest.mark.parametrize("thickness", [0.386, 0.5, 0.6, 0.7])
def test_the_valve_builder_s_leaflets_leave_an_opening_their_thickness_narrows(thickness):
    """The builder's leaflets, their coaptation bands' mid-surfaces 0.55 apart, each free
    edge's middle gap / sqrt(3) from the axis with its director toward it: seen along the
    axis, the opening between them is widest at the centre, a disc to the three middles'
    faces, 2 gap / sqrt(3) - h across (to two pixels of 2000 across the annulus). As h
    reaches the gap the slits between the bands close, and at 2 gap / sqrt(3) (0.635) the
    centre: it is the solids' shadow that closes the orifice, not the mid-surfaces'."""
    deck = parse_deck(deck_text(VALVE, VALVE_OUTPUT).replace("thickness = 0.01", f"thickness = {thickness}"))
    run = prepared(deck)
    measures = run.measure("valve")(run.sim)
    pixel = 2.0 * 12.0 / 2000  # the annulus is the root's base, 24 across
    centre = 2 * 0.55 / math.sqrt(3) - thickness
    if centre > 0.0:
        assert measures["regurgitant_gap"] == pytest.approx(centre, abs=2 * pixel)
        assert measures["orifice_area"] > 0.0
    else:
        assert measures["orifice_area"] == 0.0 and measures["regurgitant_gap"] == 0.0
    assert measures["coaptation_area"] == 0.0 and measures["coaptation_height"] == 0.0


def test_two_plates_pressed_together_coapt_over_one_plate_s_area_one_thickness_high(tmp_path):
    """The contact patch test's plates (a 3 x 3 plate pressed by p onto a 4 x 4 one, every
    node of both touching): the coaptation area is one plate's, 1.0 (each pair of
    coapting surfaces once), and the coaptation height along their normal the
    mid-surfaces' separation, the plates' thickness H, within the penalty's give (1e-3 H)."""
    run = pressed_plates(tmp_path / "plates.vtu", 0.01, "static")
    run.mesh.sets["rim"] = _rim(run.mesh)
    measures = resolve_valve(Valve(annulus="rim"), run.mesh, run.model, 1.0)(run.sim)
    assert measures["coaptation_area"] == pytest.approx(1.0, rel=1e-12)
    assert measures["coaptation_height"] == pytest.approx(PLATE_THICKNESS, rel=1e-3)


def test_a_strip_in_uniaxial_tension_peaks_at_the_pulling_stress():
    """A 2 x 1 strip on rollers along two edges, pulled by an edge traction s on the third
    (linear elastic, strains of 1e-6): every point carries the uniaxial stress s, so the
    peak principal stress is s (to the strain's share) and the orifice (its rim the
    pulled edge, no inside) is nothing."""
    s = 1e-3
    deck = parse_deck(deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', f'''
[mesh]
divisions = {{ length = 2, width = 2 }}
{ROLLERS}
[[load]]
type = "edge_pressure"
set = "x1"
value = {-s}
[output.valve]
annulus = "x1"
''').replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0'))
    run = run_deck(deck)
    measures = run.measure("valve")(run.sim)
    assert measures["peak_principal_stress"] == pytest.approx(s, rel=1e-4)
    assert measures["orifice_area"] == 0.0


def test_a_cantilever_s_peak_stress_away_from_its_clamp_is_the_beam_s_there():
    """A 2 x 1 strip (4 x 2 elements, h = 0.01, nu = 0) clamped along x = 0, its annulus,
    bent by an edge force q across its free end: the bending stress is 12 q (L - x) z / h^3
    (a beam: with nu = 0 the clamp holds no anticlastic curvature back). Its peak is at the
    points nearest the clamp; clear of the annulus by half its radius (the mean distance of
    its nodes from their centre, 0.3), at the first in-plane points past 0.15, x = 0.25,
    each element's middle row, in the outermost thickness layer."""
    q, h, length = 1e-6, 0.01, 2.0
    deck = parse_deck(deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', f'''
[mesh]
divisions = {{ length = 4, width = 2 }}
[[boundary]]
type = "clamped"
set = "x0"
[[load]]
type = "edge_force"
set = "x1"
value = [0.0, 0.0, {q}]
[output.valve]
annulus = "x0"
stress_clearance = 0.5
''').replace("nu = 0.3", "nu = 0.0").replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0'))
    run = run_deck(deck)
    outermost = np.abs(run.model.rule.tz).max() * h / 2.0
    measures = run.measure("valve")(run.sim)
    assert measures["peak_principal_stress_away"] == pytest.approx(12.0 * q * (length - 0.25) * outermost / h**3, rel=1e-3)
    gauss = 0.25 * (1.0 - math.sqrt(0.6))  # the points nearest the clamp
    assert measures["peak_principal_stress"] == pytest.approx(12.0 * q * (length - gauss) * outermost / h**3, rel=1e-3)


@pytest.mark.parametrize("table, expected", [
    ('annulus = "rim"', "output.valve.annulus: unknown set 'rim'"),
    ('annulus = "all"', "output.valve.annulus: set 'all' is a surface set; expected a edge or point set"),
    ('annulus = "attachment"\nleaflets = "free_edge"', "output.valve.leaflets: set 'free_edge' is a edge set"),
    ('annulus = "attachment"\naxis = [0.0, 0.0, 0.0]', "axis = [0.0, 0.0, 0.0] has no direction"),
])
def test_a_valve_table_naming_what_the_scene_lacks_is_refused(table, expected):
    assert expected in problems_of(deck_text(VALVE, f"[output.valve]\n{table}\n"))


def test_a_probe_named_like_a_valve_measure_is_refused():
    probe = '[[output.probe]]\nname = "orifice_area"\nquantity = "displacement"\nset = "centre_1"\ncomponent = "z"\n'
    assert ("output.probe[0].name: 'orifice_area' is already a history column, a valve measure's (output.valve)"
            in problems_of(deck_text(VALVE, probe + VALVE_OUTPUT)))


def test_the_largest_principal_value_is_eigvalsh_s_largest():
    """Random symmetric tensors and the degenerate ones (isotropic, two equal values
    either way): the closed form agrees with LAPACK's eigenvalues to round-off."""
    tensors = np.random.default_rng(1).normal(size=(50, 3, 3))
    tensors = np.concatenate([tensors + tensors.transpose(0, 2, 1),
                              [np.diag([2.0, 2.0, 2.0]), np.diag([3.0, 1.0, 1.0]), np.diag([1.0, 3.0, 3.0])]])
    np.testing.assert_allclose(largest_principal(tensors), np.linalg.eigvalsh(tensors)[:, -1], rtol=0, atol=1e-12)


def test_a_state_with_no_numbers_measures_nothing_rather_than_failing():
    """A run breaking down reaches the history sample before its stability check: the
    measures are nan then, and the check names the breakdown."""
    run = prepared(parse_deck(deck_text(VALVE, VALVE_OUTPUT)))
    run.sim.state.x[0] = np.nan
    assert all(math.isnan(value) for value in run.measure("valve")(run.sim).values())
