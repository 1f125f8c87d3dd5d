"""Decks: every shipped deck validates; every kind of mistake gives a message that names
the key, the value and what was expected; no input ever ends in a traceback."""

from __future__ import annotations

import copy
import tomllib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shellsim.deck import deck_from_data, load_deck, parse_deck
from shellsim.curve_tables import knot_interval
from shellsim.deck.curves import Curve
from shellsim.errors import DeckError

from .conftest import DECKS, deck_text, problems_of

RECTANGLE = 'builder = "rectangle"\nlength = 2.0\nwidth = 1.0'


@pytest.mark.parametrize("path", DECKS, ids=lambda p: p.name)
def test_every_shipped_deck_validates(path):
    deck = load_deck(path)
    assert deck.meta.title


@pytest.mark.parametrize(
    "text, expected",
    [
        pytest.param(deck_text(RECTANGLE).replace("E = 1000.0", 'E = "1000"'),
                     ["material.E", "got '1000'", "expected a valid number"], id="wrong type"),
        pytest.param(deck_text(RECTANGLE).replace("E = 1000.0", "Ee = 1000.0"),
                     ["material.Ee", "unknown key 'Ee'", "did you mean 'E'", "material.E", "missing"],
                     id="unknown key"),
        pytest.param(deck_text(RECTANGLE).replace("thickness = 0.01", "points_through_thickness = 2"),
                     ["section.thickness", "missing required value"], id="missing required value"),
        pytest.param(deck_text(RECTANGLE).replace("thickness = 0.01", "thickness = -0.01"),
                     ["section.thickness", "got -0.01", "greater than 0"], id="negative thickness"),
        pytest.param(deck_text(RECTANGLE, '[[boundary]]\ntype = "clamped"\nset = "x_0"\n'),
                     ["boundary[0].set", "unknown set 'x_0'", "did you mean 'x0'"], id="unknown named set"),
        pytest.param(deck_text(RECTANGLE, '[[output.probe]]\nname = "u"\nquantity = "displacement"\n'
                                          'set = "x1y1"\ncomponent = "along"\n'),
                     ["output.probe[0]", "'direction' is needed with component = 'along'"], id="along without direction"),
        pytest.param(deck_text(RECTANGLE, '[[output.probe]]\nname = "u"\nquantity = "displacement"\n'
                                          'set = "x1y1"\ncomponent = "radial"\naxis = [0.0, 0.0, 0.0]\n'),
                     ["output.probe[0]", "axis = [0.0, 0.0, 0.0] has no direction"], id="probe axis of zero length"),
        pytest.param(deck_text(RECTANGLE).replace("nu = 0.3", "nu = 0.5"),
                     ["material.nu", "got 0.5", "got 0.5: a compressible model needs -1 < nu < 0.5"], id="nu >= 0.5"),
        pytest.param(deck_text(RECTANGLE, "[curves.ramp]\nt = [0.0, 2.0, 1.0]\nvalue = [0.0, 1.0, 1.0]\n"),
                     ["curves.ramp.t", "strictly increasing", "t[2] = 1.0"], id="curve not increasing in time"),
        pytest.param(deck_text(RECTANGLE) + "\n[output\ninterval = 0.1\n",
                     ["not valid TOML", "line"], id="bad TOML"),
        pytest.param(deck_text('builder = "rectangel"\nlength = 2.0\nwidth = 1.0'),
                     ["geometry.builder", "got 'rectangel'", "did you mean 'rectangle'"], id="unknown builder"),
        pytest.param(deck_text(RECTANGLE, '[[load]]\ntype = "pressure"\nvalue = 1.0\ncurve = "rmap"\n'
                                          "[curves.ramp]\nt = [0.0, 1.0]\nvalue = [0.0, 1.0]\n"),
                     ["load[0].curve", "unknown curve 'rmap'", "did you mean 'ramp'"], id="unknown curve"),
        pytest.param(deck_text(RECTANGLE, '[[load]]\ntype = "pressure"\nset = "x0"\nvalue = 1.0\n'),
                     ["load[0].set", "'x0' is a edge set", "expected a surface set"], id="set of the wrong kind"),
        pytest.param(deck_text(RECTANGLE).replace(
            'model = "linear_elastic"\nE = 1000.0\nnu = 0.3', 'model = "mooney_rivlin"\nC1 = 1.0\nC2 = 0.5\nk = 100.0'),
                     ["material.k", "no bulk modulus is needed"], id="bulk modulus for an incompressible model"),
        pytest.param(deck_text(RECTANGLE, "[mesh]\ndivisions = { length = 2, axial = 3 }\n"),
                     ["mesh.divisions.axial", "no division 'axial'", "length, width"], id="division of another builder"),
        pytest.param(deck_text(RECTANGLE, '[[reference]]\nquantity = "w"\nprobe = "tip"\nexpected = 1.0\n'
                                          'tolerance_percent = 1.0\nsource = "closed form"\n'),
                     ["reference[0].probe", "unknown probe 'tip'"], id="reference to a missing probe"),
        pytest.param(deck_text(RECTANGLE, '[mesh]\nboundaries_y0 = [0.0, 0.2, 0.5, 1.0]\n'),
                     ["mesh.boundaries_y0", "4 boundaries for divisions.length = 2; expected 3"],
                     id="irregular boundaries of the wrong count"),
    ],
)
def test_broken_deck_names_the_key(text, expected):
    message = problems_of(text)
    for fragment in expected:
        assert fragment in message, f"{fragment!r} not in:\n{message}"


def test_messages_give_the_line_of_the_offending_key():
    text = deck_text(RECTANGLE).replace("nu = 0.3", "nu = 0.7")
    line = text.splitlines().index("nu = 0.7") + 1
    assert f"material.nu (line {line})" in problems_of(text)


def test_every_problem_is_reported_at_once():
    text = deck_text(RECTANGLE).replace("nu = 0.3", "nu = 0.7").replace("end_time = 1.0", "end_time = 0.0")
    message = problems_of(text)
    assert "2 problems" in message and "material.nu" in message and "solver.end_time" in message


def test_a_deck_states_only_what_its_scene_needs():
    deck = parse_deck(deck_text(RECTANGLE))
    assert deck.mesh.divisions == {"length": 2, "width": 2}
    assert deck.section.points_through_thickness == 2
    assert deck.solver.mass == "M2" and deck.solver.damping == 0.0
    assert deck.section.technique is None and not deck.thickness_update


def test_hyperelastic_material_defaults_to_technique_1():
    text = deck_text(RECTANGLE).replace(
        'model = "linear_elastic"\nE = 1000.0\nnu = 0.3', 'model = "neo_hookean"\nC1 = 1.0')
    deck = parse_deck(text)
    assert deck.section.technique == 1 and deck.thickness_update


def test_missing_deck_file_is_a_deck_error(tmp_path):
    with pytest.raises(DeckError, match="file not found"):
        load_deck(tmp_path / "nowhere.toml")


@pytest.mark.parametrize(
    "interpolate, times, expected",
    [
        ("linear", [-1.0, 0.0, 0.5, 1.0, 1.5, 2.0, 3.0], [0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0]),
        ("step", [0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 0.0, 2.0, 2.0, 2.0]),
        ("smooth", [0.0, 0.25, 0.5, 1.0], [0.0, 2.0 * (3 * 0.25**2 - 2 * 0.25**3), 1.0, 2.0]),
        # Abaqus' SMOOTH STEP (Analysis User's Guide, 'Amplitude curves'): A0 + (A1 - A0) xi^3 (10 - 15 xi + 6 xi^2)
        ("smooth_step", [0.0, 0.25, 0.5, 1.0], [0.0, 2.0 * 0.25**3 * (10 - 15 * 0.25 + 6 * 0.25**2), 1.0, 2.0]),
    ],
)
def test_curves_interpolate_as_documented(interpolate, times, expected):
    curve = Curve(t=[0.0, 1.0, 2.0], value=[0.0, 2.0, 2.0], interpolate=interpolate)
    np.testing.assert_allclose(curve(np.array(times)), expected)
    assert curve(times[1]) == pytest.approx(expected[1])


def test_a_time_inside_a_long_table_falls_in_the_knot_interval_numpy_finds():
    """The compiled bisection against np.searchsorted's last knot at or before the time,
    on tables of up to 40 knots with repeated ones (a jump) and times on the knots."""
    rng = np.random.default_rng(3)
    for size in (2, 3, 7, 40):
        t = np.sort(np.round(rng.uniform(0.0, 10.0, size), 1))
        t[0], t[-1] = -1.0, 11.0
        for time in np.concatenate([rng.uniform(-0.99, 10.99, 50), t[1:-1]]):
            assert knot_interval(t, float(time)) == np.searchsorted(t, time, side="right") - 1


def test_linear_extrapolation_continues_the_end_segments():
    curve = Curve(t=[0.0, 1.0], value=[1.0, 3.0], extrapolate="linear")
    np.testing.assert_allclose(curve(np.array([-1.0, 2.0])), [-1.0, 5.0])


WAVEFORM = """# aortic pressure, one beat
time_ms, pressure_mmHg
0, 80
100, 118
300, 120
500, 95
800, 80
"""


def _waveform_deck(tmp_path, curve: str) -> str:
    (tmp_path / "beat.csv").write_text(WAVEFORM)
    deck = deck_text(RECTANGLE, '[[boundary]]\ntype = "clamped"\nset = "x0"\n[[load]]\ntype = "pressure"\n'
                                'set = "all"\nvalue = 133.322\ncurve = "beat"\n[curves.beat]\n' + curve)
    (tmp_path / "deck.toml").write_text(deck)
    return str(tmp_path / "deck.toml")


def test_a_waveform_from_a_csv_file_repeats_in_the_decks_units(tmp_path):
    """A beat in ms and mmHg, repeated three times into an SI deck: the table's points
    land at their scaled times in every cycle, in between it interpolates, after the last
    cycle it holds; the resolved deck holds the table itself and loads to the same curve."""
    from shellsim.deck.resolved import resolved_text

    deck = load_deck(_waveform_deck(tmp_path, 'file = "beat.csv"\ntime_scale = 0.001\nrepeat = 3\n'))
    curve = deck.curves["beat"]
    beat = np.array([[0, 80], [0.1, 118], [0.3, 120], [0.5, 95], [0.8, 80]])
    for cycle in range(3):
        np.testing.assert_allclose(curve(beat[:, 0] + 0.8 * cycle), beat[:, 1])
    assert curve(0.8 + 0.05) == pytest.approx(99.0) and curve(5.0) == 80.0
    assert len(curve.table()[0]) == 13  # the cycles share their end points
    again = parse_deck(resolved_text(deck, tmp_path / "deck.toml", "test")).curves["beat"]
    assert again.file is None
    np.testing.assert_array_equal(again.table()[0], curve.table()[0])


def test_a_period_longer_than_the_table_leaves_a_gap_it_interpolates(tmp_path):
    curve = Curve(t=[0.0, 0.5], value=[0.0, 1.0], repeat=2, period=1.0)
    np.testing.assert_allclose(curve(np.array([0.5, 0.75, 1.0, 1.5, 2.0])), [1.0, 0.5, 0.0, 1.0, 1.0])


@pytest.mark.parametrize(("text", "rows"), [
    ("time;pressure\n0,0;80,0\n0,1;118,5\n", [(0.0, 80.0), (0.1, 118.5)]),  # decimal commas, ';' between
    ("time\tpressure\n0,0\t80\n0,25\t95,5\n", [(0.0, 80.0), (0.25, 95.5)]),  # decimal commas, tabs between
    ("\ufefftime,pressure\n0,80\n0.5,95\n", [(0.0, 80.0), (0.5, 95.0)]),  # Excel's CSV UTF-8: a byte-order mark
    ("\ufeff0,80\n0.5,95\n", [(0.0, 80.0), (0.5, 95.0)]),  # a mark before the first data row keeps it
    ("0 80\n0.5   95  # end\n", [(0.0, 80.0), (0.5, 95.0)]),  # spaces, a trailing comment
])
def test_a_waveform_file_is_read_in_the_ways_spreadsheets_write_it(tmp_path, text, rows):
    from shellsim.deck.curves import read_table

    path = tmp_path / "beat.csv"
    path.write_bytes(text.encode("utf-8"))
    t, value = read_table(path)
    assert list(zip(t, value)) == rows


@pytest.mark.parametrize(("csv", "expected"), [
    ("t,p\nnan,80\n1,90\n", ["beat.csv' line 2", "expected finite numbers", "nan,80"]),
    ("t,p\n0,80\n1,inf\n", ["beat.csv' line 3", "expected finite numbers"]),
    ("0,5 80,0\n", ["holds no (time, value) rows"]),  # spaces between, decimal commas: not guessed
])
def test_a_waveform_row_that_is_not_two_finite_numbers_is_named(tmp_path, csv, expected):
    path = _waveform_deck(tmp_path, 'file = "beat.csv"\n')
    (tmp_path / "beat.csv").write_text(csv)
    with pytest.raises(DeckError) as caught:
        load_deck(path)
    for part in expected:
        assert part in str(caught.value), str(caught.value)


def test_a_waveform_that_is_a_pipe_or_too_long_is_refused_without_reading_it(tmp_path):
    import os

    path = _waveform_deck(tmp_path, 'file = "pipe.csv"\n')
    os.mkfifo(tmp_path / "pipe.csv")  # reading it would wait for a writer forever
    with pytest.raises(DeckError, match="pipe.csv' is not a regular file"):
        load_deck(path)
    with pytest.raises(DeckError, match="'repeat' = 100000000 cycles of 2 points"):
        parse_deck(deck_text(RECTANGLE, '[curves.c]\nt = [0.0, 1.0]\nvalue = [0.0, 1.0]\nrepeat = 100000000\n'))


@pytest.mark.parametrize(("curve", "csv", "expected"), [
    ('file = "gone.csv"\n', None, ["curves.beat.file", "gone.csv' not found"]),
    ('file = "beat.csv"\n', "t,p\n0,1\n1,2\n1,3\n", ["beat.csv' line 4", "strictly increasing", "1 follows 1"]),
    ('file = "beat.csv"\n', "t,p\n0,1\n1,abc\n", ["beat.csv' line 3", "expected a time and a value", "1,abc"]),
    ('file = "beat.csv"\n', "t,p\n", ["beat.csv' holds no (time, value) rows"]),
    ('file = "beat.csv"\nt = [0.0, 1.0]\n', None, ["curves.beat", "either as 't' and 'value' or as 'file'"]),
    ('file = "beat.csv"\nperiod = 0.5\n', None, ["curves.beat.file", "'period' = 0.5 is shorter", "800"]),
    ('t = [0.0, 1.0]\n', None, ["curves.beat", "needs 't' and 'value'"]),
])
def test_a_waveform_that_cannot_be_used_names_the_file_line_and_key(tmp_path, curve, csv, expected):
    path = _waveform_deck(tmp_path, curve)
    if csv is not None:
        (tmp_path / "beat.csv").write_text(csv)
    with pytest.raises(DeckError) as caught:
        load_deck(path)
    for part in expected:
        assert part in str(caught.value), str(caught.value)


# --- no input ever ends in a traceback -------------------------------------------------

VALID = tomllib.loads(deck_text(
    RECTANGLE,
    '[[boundary]]\ntype = "clamped"\nset = "x0"\n'
    '[[load]]\ntype = "edge_force"\nset = "x1"\nvalue = [0.0, 0.0, 1.0]\ncurve = "ramp"\n'
    "[curves.ramp]\nt = [0.0, 1.0]\nvalue = [0.0, 1.0]\n"
    '[[output.probe]]\nname = "tip"\nquantity = "displacement"\nset = "x1y1"\ncomponent = "z"\n',
))

scalars = st.one_of(
    st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=True),
    st.text(max_size=12), st.sampled_from(["rectangle", "tube", "guccione", "x0", "all", "M1", "ramp"]),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=8,
)


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, prefix + (i,))


PATHS = [p for p in _paths(VALID) if p]


@st.composite
def mutated_decks(draw):
    data = copy.deepcopy(VALID)
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(PATHS))
        parent = data
        try:
            for step in path[:-1]:
                parent = parent[step]
            action = draw(st.sampled_from(["replace", "delete", "add"]))
            if action == "replace":
                parent[path[-1]] = draw(values)
            elif action == "delete" and isinstance(parent, dict):
                parent.pop(path[-1], None)
            elif isinstance(parent, dict):
                parent[draw(st.text(max_size=8))] = draw(values)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed this path
    return data


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated_decks())
def test_random_decks_validate_or_fail_with_a_deck_error(data):
    try:
        deck_from_data(data, name="random.toml")
    except DeckError as error:
        assert error.problems and all(isinstance(p, str) and p for p in error.problems)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=200))
def test_random_text_never_escapes_as_anything_but_a_deck_error(text):
    try:
        parse_deck(deck_text(RECTANGLE) + "\n" + text, name="random.toml")
    except DeckError:
        pass


def test_the_deck_reference_is_current():
    from shellsim.deck.reference_doc import deck_reference

    from .conftest import ROOT

    assert (ROOT / "docs" / "decks.md").read_text() == deck_reference(), (
        "docs/decks.md is stale: python -m shellsim.deck.reference_doc > docs/decks.md")


def test_a_mesh_point_named_all_is_refused():
    """'all' is the set of every element: a [mesh] point by that name would change what
    every table naming 'all' acts on."""
    from .conftest import CLAMPED_PLATE

    text = deck_text(*CLAMPED_PLATE).replace("[[boundary]]", "[mesh]\npoints = { all = [0.0, 0.0, 0.0] }\n\n[[boundary]]", 1)
    assert "mesh.points.all: the geometry already has a set named 'all' (every element)" in problems_of(text)
