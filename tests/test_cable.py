"""Cables (chordae tendineae, ``[[cable]]``): the 1D laws against their closed forms to
large stretch on the static path, no compression carried, the exact elastic catenary,
the tangent against differences of the forces, and the deck's checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from .conftest import deck_text, problems_of, run_deck

#: A plate 1 x 1 held along x = 0, the cable's anchor (the middle of the edge x = 1) held
#: in place: the cable's pull reaches no shell, the plate only gives the scene its step.
PLATE = 'builder = "rectangle"\nlength = 1.0\nwidth = 1.0'
ANCHOR = '''
[mesh]
divisions = { length = 1, width = 1 }
points = { anchor = [1.0, 0.5, 0.0] }
[[boundary]]
type = "clamped"
set = "x0"
[[boundary]]
type = "fixed"
set = "anchor"
translations = ["x", "y", "z"]
'''
AREA, DENSITY = 1e-4, 1000.0


def cable_table(law: str, tip, segments: int = 1, extra: str = "") -> str:
    return f'''
[[cable]]
name = "chord"
set = "anchor"
tip = {list(tip)}
segments = {segments}
area = {AREA}
density = {DENSITY}
law = {law}
{extra}
'''


#: Each law's nominal stress P(lambda) written out here, independently of the code, and
#: the tip force that takes it to a large stretch.
LAWS = {
    "linear": ('{ model = "linear", E = 1.0e6 }', lambda s: 1.0e6 * (s - 1.0), 150.0),
    "neo_hookean": ('{ model = "neo_hookean", mu = 1.0e6 }', lambda s: 1.0e6 * (s - s ** -2), 250.0),
    "ogden": ('{ model = "ogden", mu = 1.0e6, alpha = 5.0 }',
              lambda s: 2.0e6 / 5.0 * (s ** 4 - s ** -3.5), 250.0),
    # three terms as Abaqus writes them, one of negative exponent (mu alpha > 0)
    "ogden_three_terms": ('{ model = "ogden", mu = [2.0e5, 5.0e4, -1.0e5], alpha = [8.0, 3.0, -2.0] }',
                          lambda s: sum(2.0 * m / a * (s ** (a - 1.0) - s ** (-a / 2.0 - 1.0))
                                        for m, a in ((2.0e5, 8.0), (5.0e4, 3.0), (-1.0e5, -2.0))), 250.0),
    "exponential": ('{ model = "exponential", a = 1.0e5, b = 0.5 }',
                    lambda s: 1.0e5 * math.exp(0.5 * (s * s + 2.0 / s - 3.0)) * (s - s ** -2), 250.0),
}


@pytest.mark.parametrize("name", list(LAWS))
def test_a_pulled_cable_stretches_as_its_law_says_to_large_stretch(name):
    """A cable of length 1 from the held anchor, its tip pulled along it by a force F (held
    across it: a string at rest has no lateral stiffness), solved statically: the tip's
    stretch solves A P(lambda) = F for the law written out above (closed form for the
    linear law, a scalar root otherwise), to 0.1%. The forces take the cable to stretches
    of 2.5 (linear), 2.64 (neo-Hooke), 1.59 (Ogden, alpha 5), 1.48 (three Ogden terms) and
    2.62 (exponential)."""
    from shellsim.deck import parse_deck

    law, stress, force = LAWS[name]
    text = deck_text(PLATE, ANCHOR + cable_table(law, (2.0, 0.5, 0.0)) + f'''
[[load]]
type = "point_force"
set = "chord_tip"
value = [{force}, 0.0, 0.0]
[[boundary]]
type = "fixed"
set = "chord_tip"
translations = ["y", "z"]
''').replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0\nstatic = { increments = 20 }')
    run = run_deck(parse_deck(text))
    tip = run.mesh.sets["chord_tip"].nodes[0]
    stretch = run.sim.state.x[tip, 0] - 1.0
    expected = brentq(lambda s: AREA * stress(s) - force, 1.0 + 1e-12, 10.0)
    assert expected > 1.5
    assert stretch == pytest.approx(expected, rel=1e-3)


def test_an_ogden_law_s_terms_of_one_exponent_act_as_one_and_its_slope_is_its_derivative():
    """Abaqus writes a one-term Ogden chord as three terms of one exponent: the law merges
    them, its stress then that of the one term of their summed mu to the last bit, while
    a law of distinct terms meets the sum written out here to 1e-13 from lambda = 1 to 3
    and its slope the stress's central difference to 1e-7; each term must stiffen in
    tension (mu alpha > 0), and six terms at most."""
    from shellsim.loads.cable_laws import Ogden, code_and_parameters, nominal_stress

    def law(mu, alpha):
        return code_and_parameters(Ogden(model="ogden", mu=mu, alpha=alpha))

    stretches = np.linspace(1.0, 3.0, 41)
    (c3, p3), (c1, p1) = law([0.1, 0.2, 0.3], [12.0, 12.0, 12.0]), law(0.1 + 0.2 + 0.3, 12.0)
    assert [nominal_stress(c3, p3, s) for s in stretches] == [nominal_stress(c1, p1, s) for s in stretches]
    terms = ((2.0e5, 8.0), (5.0e4, 3.0), (-1.0e5, -2.0))
    code, params = law([m for m, _ in terms], [a for _, a in terms])
    for s in stretches:
        p, dp = nominal_stress(code, params, s)
        assert p == pytest.approx(sum(2 * m / a * (s ** (a - 1) - s ** (-a / 2 - 1)) for m, a in terms), rel=1e-13,
                                  abs=1e-9)
        if s > 1.0:
            step = 1e-6 * s
            difference = (nominal_stress(code, params, s + step)[0] - nominal_stress(code, params, s - step)[0]) / (2 * step)
            assert dp == pytest.approx(difference, rel=1e-7)
    chord = '{{ model = "ogden", mu = {}, alpha = {} }}'
    assert "term 2: mu = -1, alpha = 3; each term needs mu * alpha > 0" in problems_of(
        deck_text(PLATE, ANCHOR + cable_table(chord.format("[1.0, -1.0]", "[2.0, 3.0]"), (2.0, 0.5, 0.0))))
    assert "1 to 6 terms" in problems_of(
        deck_text(PLATE, ANCHOR + cable_table(chord.format([1.0] * 7, [2.0] * 7), (2.0, 0.5, 0.0))))
    assert "1 to 6 terms" in problems_of(
        deck_text(PLATE, ANCHOR + cable_table(chord.format("[1.0, 1.0]", "[2.0]"), (2.0, 0.5, 0.0))))


def test_a_pushed_cable_carries_no_compression():
    """The tip pushed towards the anchor by a constant force F: a cable shorter than its
    rest length carries nothing, so the tip (its mass the cable's half, rho A L / 2) moves
    as a free body, x = F t^2 / (2 m), which central differences integrate exactly; and
    the cable's tension stays 0 (nothing reaches the anchor's shell)."""
    from shellsim.deck import parse_deck

    force, end = 0.05, 1.0
    text = deck_text(PLATE, ANCHOR + cable_table('{ model = "neo_hookean", mu = 1.0e6 }', (2.0, 0.5, 0.0)) + f'''
[[load]]
type = "point_force"
set = "chord_tip"
value = [{-force}, 0.0, 0.0]
''').replace("end_time = 1.0", f"end_time = {end}")
    run = run_deck(parse_deck(text))
    tip = run.mesh.sets["chord_tip"].nodes[0]
    mass = DENSITY * AREA * 1.0 / 2.0
    moved = 2.0 - run.sim.state.x[tip, 0]
    assert 0.1 < moved < 0.9  # well into compression, short of the anchor
    assert moved == pytest.approx(force * end ** 2 / (2.0 * mass), rel=1e-9)


def elastic_catenary(span: float, rest: float, weight: float, stiffness: float, s: np.ndarray):
    """The exact elastic catenary (Irvine 1981, Cable Structures, Eqs 2.10-2.11): a cable
    of unstretched length ``rest``, weight per unstretched length ``weight`` and axial
    stiffness EA ``stiffness``, hung between two supports at one height ``span`` apart,
    tension T = EA (ds/ds0 - 1). Returns (x, z, T) (k,) at the unstretched arc lengths s
    (k,), from the left support, z downwards negative."""
    vertical = weight * rest / 2.0  # each support carries half the weight

    def x_at(h, s):
        return h * s / stiffness + h / weight * (np.arcsinh(vertical / h) - np.arcsinh((vertical - weight * s) / h))

    horizontal = brentq(lambda h: x_at(h, rest) - span, 1e-9 * weight * rest, 1e6 * weight * rest)
    z = -(weight * s / stiffness * (vertical / weight - s / 2.0)
          + horizontal / weight * (np.hypot(1.0, vertical / horizontal) - np.hypot(1.0, (vertical - weight * s) / horizontal)))
    return x_at(horizontal, s), z, np.hypot(horizontal, vertical - weight * s)


GRAVITY, STIFFNESS = 9.81, 1.0e6 * AREA


def hanging_cable_deck(segments: int) -> str:
    """A slack cable (rest length 1.2 times the span 1) between the held anchor and its
    held tip, in ``segments`` elements, hanging under its own weight and brought to rest
    by damping (linear law, EA = 100 N, weight 9.81 N/m: 1.2% elastic stretch)."""
    return deck_text(PLATE, ANCHOR + cable_table('{ model = "linear", E = 1.0e6 }', (2.0, 0.5, 0.0), segments,
                                                 f'rest_length = 1.2\ngravity = [0.0, 0.0, {-GRAVITY}]') + '''
[[boundary]]
type = "fixed"
set = "chord_tip"
translations = ["x", "y", "z"]
''').replace("[solver]\nend_time = 1.0", "[solver]\nend_time = 6.0\ndamping = 10.0")


def hanging_cable_errors(segments: int, solver: str = "") -> tuple[float, float]:
    """The cable of :func:`hanging_cable_deck` at rest against Irvine's exact elastic
    catenary: (the midspan sag's relative error, the largest horizontal error of a node
    over the sag); ``solver``: more [solver] keys."""
    from shellsim.deck import parse_deck

    run = run_deck(parse_deck(hanging_cable_deck(segments).replace("damping = 10.0", f"damping = 10.0\n{solver}")))
    x = run.sim.state.x
    assert np.abs(run.sim.state.v).max() < 1e-6  # at rest
    chord = np.setdiff1d(run.mesh.sets["chord"].nodes, run.mesh.sets["anchor"].nodes)
    interior = chord[chord != run.mesh.sets["chord_tip"].nodes[0]]  # in order from the anchor
    s = 1.2 * np.arange(1, segments) / segments
    exact_x, exact_z = elastic_catenary(1.0, 1.2, DENSITY * AREA * GRAVITY, STIFFNESS, s)[:2]
    middle = segments // 2 - 1
    return abs(x[interior[middle], 2] / exact_z[middle] - 1.0), np.abs(x[interior, 0] - 1.0 - exact_x).max() / abs(
        exact_z[middle])


def test_a_hanging_cable_takes_the_exact_elastic_catenary():
    """The hanging cable of :func:`hanging_cable_errors` converges to the exact elastic
    catenary as the square of its segments' length: the midspan sag within 0.1% with 32
    segments, its error 16 times smaller than with 8 (measured: 8.1e-3, 5.0e-4; the
    horizontal positions within 2.2e-3 and 1.4e-4 of the sag)."""
    coarse, fine = hanging_cable_errors(8), hanging_cable_errors(32)
    assert fine[0] < 1e-3
    assert 14.0 < coarse[0] / fine[0] < 18.0
    assert coarse[1] < coarse[0] and fine[1] < fine[0]


def test_mass_scaling_takes_the_cables_step_to_its_target_with_the_shell_s():
    """The hanging cable in 32 segments: its elements' own critical step bounds the
    scene's. Mass scaling multiplies every mass, the cables' too, by (target / step)^2, so
    their own step grows with the rest and the step becomes the target, as in a scene
    without cables (it stayed at the cables' unscaled step)."""
    from shellsim.deck import parse_deck

    def deck(end: str) -> str:
        return hanging_cable_deck(32).replace("end_time = 6.0", f"end_time = {end}")

    plain = run_deck(parse_deck(deck("1e-3")))
    first = plain.dt_history[0][2]
    target = 4.0 * float(first)
    scaled = run_deck(parse_deck(deck(f"4e-3\nmass_scaling = {{ step = {target!r} }}")))
    assert scaled.sim.mass_factor == pytest.approx(16.0, rel=1e-12)
    assert scaled.dt_history[1][2] == pytest.approx(target, rel=1e-3)  # to the estimate's tolerance (it was 8% short)


def test_min_step_makes_only_the_cable_s_quicker_elements_heavier_to_it():
    """A chord of 4 elements of length 0.25 (E = 1e6, rho = 1000: each element's own
    step L sqrt(rho / E) = 7.9e-3): with ``min_step`` 0.02, above it, each is made heavier
    by (0.02 / 7.9e-3)^2 = 6.4 and the cables' critical step is 0.02; with 1e-3, below it,
    nothing changes (Abaqus' variable mass scaling TYPE=BELOW MIN). A multi-term Ogden
    law's line in ``check`` lists its terms."""
    from shellsim.bundles import Shape
    from shellsim.deck import parse_deck
    from shellsim.geometry import build_mesh
    from shellsim.loads.cable import critical_step
    from shellsim.model import build_model

    def cables(extra: str):
        deck = parse_deck(deck_text(PLATE, ANCHOR + cable_table('{ model = "linear", E = 1.0e6 }', (2.0, 0.5, 0.0),
                                                                  4, extra)))
        model = build_model(deck, build_mesh(deck))
        return model, deck

    own = 0.25 * math.sqrt(DENSITY / 1.0e6)
    plain, _ = cables("")
    heavy, deck = cables("min_step = 0.02")
    light, _ = cables("min_step = 1e-3")
    shape = Shape(x=heavy.x0, d=heavy.d0, e1=heavy.e1f0, h=heavy.h0)
    np.testing.assert_allclose(heavy.loads.cable.density, DENSITY * (0.02 / own) ** 2, rtol=1e-12)
    assert critical_step(shape, heavy.loads.cable) == pytest.approx(0.02, rel=1e-12)
    assert critical_step(shape, plain.loads.cable) == pytest.approx(own, rel=1e-12)
    np.testing.assert_array_equal(light.loads.cable.density, plain.loads.cable.density)
    assert "made heavier" in deck.cable[0].summary
    ogden = parse_deck(deck_text(PLATE, ANCHOR + cable_table(LAWS["ogden_three_terms"][0], (2.0, 0.5, 0.0))))
    assert "mu=[200000, 50000, -100000], alpha=[8, 3, -2]" in ogden.cable[0].summary


def test_min_step_is_held_as_the_cable_stiffens():
    """A chord of a stiffening (exponential) law made heavier at rest to its min_step:
    stretched 30% its elements' own step falls below it, and holding it makes them heavier
    again until each is min_step (the cables' step is then min_step); back at rest they
    are not made lighter, and an element already slower is left alone."""
    from shellsim.bundles import Shape
    from shellsim.deck import parse_deck
    from shellsim.geometry import build_mesh
    from shellsim.loads.cable import _own_step, critical_step, hold_min_step
    from shellsim.model import build_model

    deck = parse_deck(deck_text(PLATE, ANCHOR + cable_table('{ model = "exponential", a = 1.0e5, b = 5.0 }',
                                                              (2.0, 0.5, 0.0), 4, "min_step = 0.02")))
    model = build_model(deck, build_mesh(deck))
    cables = model.loads.cable
    rest = Shape(x=model.x0, d=model.d0, e1=model.e1f0, h=model.h0)
    stretched = rest._replace(x=1.3 * model.x0)
    assert critical_step(rest, cables) == pytest.approx(0.02, rel=1e-12)
    assert critical_step(stretched, cables) < 0.9 * 0.02
    at_rest = cables.density.copy()
    hold_min_step(stretched, cables)
    assert np.all(cables.density > at_rest)
    e = np.empty(3)
    np.testing.assert_allclose([_own_step(stretched.x, cables, k, e) for k in range(len(at_rest))], 0.02, rtol=1e-12)
    held = cables.density.copy()
    hold_min_step(rest, cables)
    np.testing.assert_array_equal(cables.density, held)


def test_the_cable_tangent_is_the_derivative_of_its_forces():
    """The couplings' blocks of a stretched, turned cable against central differences of
    its forces (the exact tangent, to the differences' truncation)."""
    from shellsim.deck import parse_deck
    from shellsim.geometry import build_mesh
    from shellsim.loads import LoadTangents, external_forces
    from shellsim.model import build_model

    from .conftest import initial_shape

    text = deck_text(PLATE, ANCHOR + cable_table('{ model = "exponential", a = 1.0e5, b = 0.5 }', (1.6, 1.2, 0.4),
                                                 extra="rest_length = 0.7"))
    deck = parse_deck(text)
    model = build_model(deck, build_mesh(deck))
    shape = initial_shape(model)
    nodes, blocks = LoadTangents(model).couplings(0.0, shape, 1e-7)
    assert len(nodes) == 1
    n = model.n_nodes
    f, fr, g = np.zeros((n, 3)), np.zeros((n, 2)), np.zeros((n, 3))
    step = 1e-6
    for column in range(6):
        node, axis = nodes[0, column // 3], column % 3
        moved = []
        for sign in (1.0, -1.0):
            shape.x[node, axis] += sign * step
            external_forces(0.0, model, shape, f, fr, g)
            moved.append(np.concatenate([f[nodes[0, 0]], f[nodes[0, 1]]]))
            shape.x[node, axis] -= sign * step
        difference = (moved[0] - moved[1]) / (2.0 * step)
        np.testing.assert_allclose(blocks[0, :6, column], difference, rtol=1e-6, atol=1e-6 * np.abs(blocks).max())
    assert np.all(blocks[0, 6:] == 0.0) and np.all(blocks[0, :, 6:] == 0.0)


def test_cable_decks_that_cannot_work_are_refused():
    """A cable whose added set names clash, one that names no set of the geometry, and a
    chord of several segments on the static path are each refused with a message naming
    the key."""
    law = '{ model = "linear", E = 1.0 }'
    clash = problems_of(deck_text(PLATE, ANCHOR.replace("anchor = ", "chord_tip = [0.0, 0.0, 0.0], anchor = ")
                                  + cable_table(law, (2.0, 0.5, 0.0))))
    assert "cable[0].name: 'chord' adds the set 'chord_tip'" in clash
    unknown = problems_of(deck_text(PLATE, ANCHOR + cable_table(law, (2.0, 0.5, 0.0)).replace('set = "anchor"',
                                                                                              'set = "ancor"')))
    assert "cable[0].set: unknown set 'ancor'; did you mean 'anchor'?" in unknown
    static = problems_of(deck_text(PLATE, ANCHOR + cable_table(law, (2.0, 0.5, 0.0), segments=4)).replace(
        "[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0'))
    assert "cable[0].segments = 4" in static


def test_the_cables_series_carries_their_tension_and_motion(tmp_path):
    """A run writes the cables beside the shells (cables.xdmf, cables.pvd: line cells on
    their nodes) with each element's tension and stretch and the nodes' displacement. The
    hanging cable's tensions at rest, 16 segments, against the exact catenary's tension at
    each element's middle: within 0.2% (measured: 0.11%); the stretch is 1 + T / EA with the
    written tension; the displacement takes the tip nowhere and the middle down by the sag."""
    import meshio

    from shellsim.deck import load_deck
    from shellsim.execute import run_scene

    source = tmp_path / "hanging.toml"
    source.write_text(hanging_cable_deck(16).replace("damping = 10.0", "damping = 10.0\n[output]\ninterval = 3.0\n"
                                                                         'formats = ["xdmf", "vtu"]'))
    (tmp_path / "out").mkdir()
    run, _ = run_scene(load_deck(source), source, tmp_path / "out")
    assert run.status == "completed"
    s = 1.2 * (np.arange(16) + 0.5) / 16
    tension = elastic_catenary(1.0, 1.2, DENSITY * AREA * GRAVITY, STIFFNESS, s)[2]
    with meshio.xdmf.TimeSeriesReader(tmp_path / "out" / "cables.xdmf") as reader:
        points, cells = reader.read_points_cells()
        frames = [reader.read_data(k) for k in range(reader.num_steps)]
    assert [t for t, _, _ in frames] == [0.0, 3.0, 6.0]
    last = meshio.read(tmp_path / "out" / "cables_frames" / "cables_0002.vtu")
    for point_data, cell_data, lines in ((frames[-1][1], frames[-1][2], cells[0].data),
                                         (last.point_data, last.cell_data, last.cells[0].data)):
        ends = points[lines]
        order = np.argsort(ends[:, :, 0].mean(axis=1))  # from the anchor along the span
        np.testing.assert_allclose(cell_data["tension"][0][order], tension, rtol=2e-3)
        np.testing.assert_allclose(cell_data["stretch"][0], 1.0 + cell_data["tension"][0] / STIFFNESS, rtol=1e-12)
        moved = point_data["displacement"]
        assert np.abs(moved[np.argmax(points[:, 0])]).max() == 0.0  # the held tip
        assert moved[:, 2].min() < -0.29  # the sag, about 0.298


def test_renders_draw_the_cables(tmp_path):
    """A field render of a run with cables draws them in their colour where they hang
    (pixels of CABLE_COLOUR below the plate, none once the cables' series is gone), and
    the mesh picture draws them too."""
    import imageio.v3 as iio

    from shellsim.deck import load_deck
    from shellsim.execute import run_scene
    from shellsim.geometry import build_mesh
    from shellsim.output.render import CABLE_COLOUR, render_field, render_mesh

    source = tmp_path / "hanging.toml"
    source.write_text(hanging_cable_deck(8).replace("end_time = 6.0", "end_time = 1.0"))
    out = tmp_path / "out"
    out.mkdir()
    run_scene(load_deck(source), source, out)
    colour = np.array([int(CABLE_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])

    def cable_pixels(picture) -> int:
        return int(np.all(np.abs(iio.imread(picture)[..., :3].astype(int) - colour) <= 8, axis=-1).sum())

    with_cables = render_field(out, "displacement", view="front")[0]
    drawn = cable_pixels(with_cables)
    for name in ("cables.xdmf", "cables.h5"):
        (out / name).unlink()
    without = render_field(out, "displacement", view="front", out_dir=tmp_path / "bare")[0]
    assert drawn > 100 and cable_pixels(without) == 0
    render_mesh(build_mesh(load_deck(source)), tmp_path / "mesh.png")
    assert cable_pixels(tmp_path / "mesh.png") > 100
