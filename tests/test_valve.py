"""The aortic valve builder: three leaflets with positive Jacobians and the declared sets,
checked against the geometry it is built to: commissures on the root at radius Rc and the
valve's height, nadirs at the base radius, free edges of the length their two straight
branches give (2 Rc for a closed valve, gap 0), neighbours' coaptation bands the gap
apart, the three leaflets alike by a third of a turn, directors toward the aorta and
fibre vectors along the free edge; and the valve closing under diastolic pressure with
contact between its leaflets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.errors import DeckError
from shellsim.geometry import build_mesh
from shellsim.loads import ToolForces
from shellsim.mesh import jacobian_determinants
from shellsim.solver.explicit import EXTERNAL

from .conftest import deck_text, run_deck

RC, RB, H, CC, GAP = 10.0, 12.0, 14.0, 2.0, 0.5  # the builder's defaults


def valve_deck(geometry: str = "", divisions: str = "around = 8, belly = 4, coaptation = 2"):
    return parse_deck(deck_text(f'builder = "aortic_valve"\n{geometry}', f"[mesh]\ndivisions = {{ {divisions} }}\n")
                      .replace("thickness = 0.01", "thickness = 0.2"))


@pytest.fixture(scope="module")
def valve():
    deck = valve_deck()
    return deck, build_mesh(deck)


def _leaflet_centre(k: int) -> np.ndarray:
    angle = math.radians(90.0 + 120.0 * k)
    return np.array([math.cos(angle), math.sin(angle), 0.0])


def _turned(x: np.ndarray, turns: int) -> np.ndarray:
    angle = 2.0 * math.pi / 3.0 * turns
    c, s = math.cos(angle), math.sin(angle)
    return x @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def test_the_valve_meshes_with_positive_jacobians_and_its_declared_sets(valve):
    deck, mesh = valve
    assert np.all(jacobian_determinants(mesh, 3, 2) > 0)
    assert set(mesh.sets) == set(deck.geometry.sets()) | {"all"}
    assert len(mesh.conn) == 3 * 8 * (4 + 2)


def test_commissures_nadirs_and_free_edge_middles_lie_where_the_geometry_puts_them(valve):
    """The free edges' ends on the root (radius Rc, height H), their middles gap / 2 /
    cos 30 from the axis at height H, the attachments' lowest points at the base radius
    on z = 0, and no node outside the root."""
    _, mesh = valve
    x = mesh.x
    for k in range(3):
        free = x[mesh.sets[f"free_edge_{k + 1}"].nodes]
        radius = np.hypot(free[:, 0], free[:, 1])
        np.testing.assert_allclose(free[:, 2], H, atol=1e-12)
        assert radius.max() == pytest.approx(RC, abs=1e-12)
        centre = x[mesh.sets[f"centre_{k + 1}"].nodes[0]]
        assert np.hypot(centre[0], centre[1]) == pytest.approx(GAP / 2 / math.cos(math.pi / 6), rel=1e-12)
        assert centre[:2] @ _leaflet_centre(k)[:2] > 0.0  # on its own leaflet's side of the axis
        nadir = x[mesh.sets[f"nadir_{k + 1}"].nodes[0]]
        np.testing.assert_allclose(nadir, RB * _leaflet_centre(k), atol=1e-12)
    assert np.hypot(x[:, 0], x[:, 1]).max() <= RB * (1 + 1e-12)


@pytest.mark.parametrize("gap", [GAP, 1e-4])
def test_each_free_edge_is_two_straight_branches_and_tends_to_twice_the_commissure_radius(gap):
    """Each free edge runs straight from a commissure to its middle and on to the other:
    its length is 2 (sqrt(Rc^2 - (gap/2)^2) - gap / (4 cos 30)), 2 Rc as the gap closes
    (the free edge of a closed leaflet spans commissure, centre, commissure)."""
    deck = valve_deck(f"gap = {gap}")
    mesh = build_mesh(deck)
    half = gap / 2
    expected = 2.0 * (math.sqrt(RC**2 - half**2) - half / (2.0 * math.cos(math.pi / 6)))
    for k in range(3):
        free = mesh.x[mesh.sets[f"free_edge_{k + 1}"].nodes]
        centre = mesh.x[mesh.sets[f"centre_{k + 1}"].nodes[0]]
        ends = free[np.argsort(np.linalg.norm(free - centre, axis=1))[-2:]]
        # every node on one of the two segments centre-end
        for end in ends:
            on = free[np.abs(np.cross(free - centre, end - centre)).max(axis=1) < 1e-9 * RC]
            assert len(on) == 8 // 2 * 2 + 1
        assert sum(np.linalg.norm(end - centre) for end in ends) == pytest.approx(expected, rel=1e-12)
    if gap < 1e-3:
        assert expected == pytest.approx(2 * RC, rel=1e-5)


def test_neighbouring_coaptation_bands_hang_upright_the_gap_apart(valve):
    """The band under each free edge is vertical, and each half of it is gap / 2 from the
    plane between its leaflet and the neighbour: neighbours start the gap apart."""
    _, mesh = valve
    x = mesh.x
    band = x[:, 2] >= H - CC - 1e-9
    for k in range(3):
        leaflet = np.zeros(len(x), dtype=bool)
        leaflet[mesh.sets[f"leaflet_{k + 1}"].nodes] = True
        for sign in (-1.0, 1.0):  # the planes at the commissures 60 degrees either side
            angle = math.radians(90.0 + 120.0 * k + sign * 60.0)
            normal = np.array([-math.sin(angle), math.cos(angle), 0.0])
            toward = math.radians(90.0 + 120.0 * k + sign * 90.0)  # that commissure's side of the middle
            side = leaflet & band & (x[:, :2] @ [math.cos(toward), math.sin(toward)] > -1e-9 * RC)
            assert side.sum() >= 3 * (8 // 2)
            np.testing.assert_allclose(np.abs(x[side] @ normal), GAP / 2, rtol=1e-9)


def test_the_three_leaflets_are_alike_by_a_third_of_a_turn(valve):
    _, mesh = valve
    first = mesh.x[mesh.sets["leaflet_1"].nodes]
    for k in (1, 2):
        other = mesh.x[mesh.sets[f"leaflet_{k + 1}"].nodes]
        turned = _turned(first, k)
        nearest = np.linalg.norm(turned[:, None] - other[None], axis=2).min(axis=1)
        assert nearest.max() < 1e-9 * RC


def test_directors_face_the_aorta_and_fibre_vectors_run_along_the_free_edge(valve):
    """Directors point up and out toward each leaflet's own sinus (the aortic side, where
    diastolic pressure acts); the cell vectors ``along_free_edge`` of the elements at the
    free edge are parallel to their branch of it."""
    _, mesh = valve
    for k in range(3):
        nodes = mesh.sets[f"leaflet_{k + 1}"].nodes
        assert np.all(mesh.director[nodes] @ (_leaflet_centre(k) + [0.0, 0.0, 1.0]) > 0.0)
        nadir = mesh.sets[f"nadir_{k + 1}"].nodes[0]
        assert mesh.director[nadir, 2] > 0.99  # the belly leaves the root flat
    along = mesh.cell_vectors["along_free_edge"]
    np.testing.assert_allclose(np.linalg.norm(along, axis=1), 1.0, rtol=1e-12)
    free = np.isin(mesh.conn, mesh.sets["free_edge"].nodes).sum(axis=1) == 3
    for element in np.flatnonzero(free):
        ends = mesh.x[np.intersect1d(mesh.conn[element], mesh.sets["free_edge"].nodes)]
        branch = ends[np.argmax(np.linalg.norm(ends - ends[0], axis=1))] - ends[0]
        assert abs(along[element] @ branch) / np.linalg.norm(branch) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize(("geometry", "divisions", "expected"), [
    ("height = 2.0", "around = 8, belly = 4, coaptation = 2", "height = 2 must exceed coaptation_height"),
    ("gap = 10.0", "around = 8, belly = 4, coaptation = 2", "gap = 10 must be smaller than commissure_radius"),
    ("", "around = 7, belly = 4, coaptation = 2", "mesh.divisions.around: must be even"),
])
def test_a_valve_that_cannot_be_built_is_refused_with_the_key_named(geometry, divisions, expected):
    with pytest.raises(DeckError, match=expected):
        valve_deck(geometry, divisions)


CLOSING = """
[[boundary]]
type = "clamped"
set = "attachment"

[[load]]
type = "pressure"
set = "all"
value = 0.010666
face = "top"

[solver]
method = "static"
end_time = 1.0
static = { increments = 20 }
""" + "".join(f"""
[[contact]]
type = "shells"
name = "leaflets_{a}{b}"
set = "leaflet_{a}"
against = "leaflet_{b}"
""" for a, b in ((1, 2), (2, 3), (3, 1)))


@pytest.fixture(scope="module")
def closed_by_pairs():
    """(run, deck) of :func:`_closed` with a contact table per pair (:data:`CLOSING`)."""
    return _closed(CLOSING)


def test_the_valve_closes_under_diastolic_pressure_its_free_edges_meeting(closed_by_pairs):
    """The builder's valve (h = 0.5, the leaflets 0.55 apart, 72 elements), clamped along
    its attachments, closed statically by 80 mmHg (0.010666 MPa) on the aortic faces with
    contact between each pair of leaflets: the solve converges; every free-edge node off
    the commissure posts touches its neighbour (gap <= 0: the valve is shut along its
    free edges) and none has gone a quarter of a thickness into it; the three pairs take
    the same contact force (the valve's threefold symmetry). The leaflets' law only sets
    how far they sag: linear elastic E = 2 MPa here. Measured: 23 load steps, 136
    iterations; gaps -0.098 h (the middles, pressed by two neighbours) to -0.031 h; each
    pair's force 0.5895 N to 1e-10, its coaptation area 57.4 mm^2."""
    run, deck = closed_by_pairs
    assert run.status == "completed" and len(run.newton) < 60
    _assert_shut_and_alike(run, deck)


def test_one_self_contact_table_over_the_three_leaflets_closes_the_valve_as_the_pairs_do(closed_by_pairs):
    """The same valve with one self-contact table over all three leaflets instead of a
    table per pair: each leaflet's nodes are tested against each leaflet's faces, so a
    middle node, where the three meet, pushes both neighbours' faces, as with a table per
    pair. The solve converges to the same shut valve: the total contact force and every
    node's gap those of the pairs. (With one face a node the middle flipped between its
    two neighbours' from iteration to iteration, and the solve stalled.) Measured: 23 load
    steps, 137 iterations; the force the pairs' to 3e-11, every node where theirs to 7e-9 mm."""
    single = CLOSING.split("[[contact]]")[0] + '[[contact]]\ntype = "shells"\nname = "leaflets"\nset = "all"\n'
    run, deck = _closed(single)
    assert run.status == "completed" and len(run.newton) < 60
    _assert_shut(run, deck)
    pairs, _ = closed_by_pairs
    total = sum(pairs.history[f"leaflets_{pair}"][-1] for pair in ("12", "23", "31"))
    assert run.history["leaflets"][-1] == pytest.approx(total, rel=1e-6)
    np.testing.assert_allclose(run.sim.state.x, pairs.sim.state.x, rtol=0.0, atol=1e-6 * RC)


def test_the_valve_slams_shut_in_an_explicit_run_keeping_its_energy():
    """The same valve closed dynamically, undamped: 80 mmHg ramped on smoothly in 0.04 s
    (the physiological rate: Labrosse et al. 2010, via the thesis' Test 9) and held to
    0.06 s. Shut along the free edges as statically, the pairs alike, and the energy
    balance (internal + kinetic - external work) within 1% of the external work: the
    penalty springs give back what they take. Measured: 7,387 steps, balance 3.3e-6 of
    the external work, kinetic energy 5e-5 of the internal at the end, gaps -0.100 to
    -0.029 h, each pair's force 0.5893 N (0.5895 statically)."""
    explicit = (CLOSING.replace('method = "static"\nend_time = 1.0\nstatic = { increments = 20 }', "end_time = 0.06")
                .replace('face = "top"', 'face = "top"\ncurve = "diastole"')
                + '\n[curves.diastole]\nt = [0.0, 0.04, 0.06]\nvalue = [0.0, 1.0, 1.0]\ninterpolate = "smooth"\n')
    run, deck = _closed(explicit)
    assert run.status == "completed"
    _assert_shut_and_alike(run, deck)
    energy = run.sim.state.energy
    assert abs(run.balance_error) < 0.01 * energy[EXTERNAL]


def _closed(tables: str):
    """(run, deck): the builder's valve (h = 0.5, leaflets 0.55 apart, linear elastic
    E = 2 MPa) with ``tables`` (supports, load, solver, contact) run."""
    deck = parse_deck(deck_text('builder = "aortic_valve"\ngap = 0.55', tables)
                      .replace("thickness = 0.01", "thickness = 0.5")
                      .replace('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0',
                               'model = "linear_elastic"\nE = 2.0\nnu = 0.45\ndensity = 1.1e-9')
                      .replace("[solver]\nend_time = 1.0\n", ""))
    return run_deck(deck), deck


def _assert_shut_and_alike(run, deck) -> None:
    """:func:`_assert_shut`, and the three pairs take the same force."""
    _assert_shut(run, deck)
    forces = [run.history[f"leaflets_{pair}"][-1] for pair in ("12", "23", "31")]
    assert forces[0] > 0.0 and forces == pytest.approx([forces[0]] * 3, rel=1e-6)


def _assert_shut(run, deck) -> None:
    """Every free-edge node off the commissure posts touches its neighbour, and none has
    gone a quarter of a thickness deep."""
    h, state = 0.5, run.sim.state
    gaps = ToolForces(run.model, []).gaps(state.t, state.fields.shape)
    mesh = build_mesh(deck)
    posts = np.hypot(mesh.x[:, 0], mesh.x[:, 1]) > RC - 1e-9
    free = np.setdiff1d(mesh.sets["free_edge"].nodes, np.flatnonzero(posts))
    assert len(free) == 3 * (2 * 8 + 1 - 2)  # the free edges' nodes, the posts' ends left out
    assert np.all(gaps[free] <= 0.0) and np.nanmin(gaps) > -0.25 * h, (gaps[free] / h)
