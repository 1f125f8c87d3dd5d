"""The static solver: its tangent against differences of the residual along random
directions (every material path, distorted curved elements, a follower pressure and a
moment), its forward differences against central ones, against the stiffness product at
rest, Newton's quadratic convergence, a step
that cannot converge stopped with a message that says where, arc length through a limit
point, reactions and load factors, and a preload handed to the explicit solver."""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.sparse as sp
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.deck import load_deck, parse_deck
from shellsim.element.tangent import ELEMENT_DOFS
from shellsim.execute import built_run
from shellsim.geometry import build_mesh
from shellsim.model import build_model
from shellsim.solver.equilibrium import Converged, Equilibrium
from shellsim.solver.run import prepare
from shellsim.solver.static import NewtonSolver, NewtonStep
from shellsim.solver.tangent_pattern import free_columns
from shellsim.verify.analytic import sphere_inflation_path

from .conftest import ROOT, deck_text, run_deck

PANEL = """builder = "cylindrical_panel"
radius = 2.0
length = 1.0
angle_deg = 40.0
"""

SUPPORTS = """
[mesh]
divisions = { around = 2, along = 2 }

[[boundary]]
type = "clamped"
set = "y0"

[[boundary]]
type = "symmetry"
set = "phi0"
normal = [1.0, 0.0, 0.0]

[[load]]
type = "pressure"
set = "all"
value = PRESSURE
face = "top"

[[load]]
type = "point_moment"
set = "phi1_y1"
value = [0.0, MOMENT, 0.0]

[[load]]
type = "edge_pressure"
set = "phi1"
value = EDGE
"""
STATIC = '[solver]\nmethod = "static"\nend_time = 1.0'


#: The edge pressure against the face pressure: the edge's follower force about a tenth of
#: the face pressure's on the panel.
EDGE_SHARE = 40.0
#: The fibre lengths held: the tangent leaves out how a node's length follows the stretch
#: of its elements (a coupling beyond the element, through the loads on the faces).
HELD = "thickness_update = false"
#: (material table, section table, pressure, moment): every constitutive path.
PATHS = {
    "small strain, total": ('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0', "", 0.02, 0.01),
    "small strain, incremental": ('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0',
                                  'formulation = "incremental"', 0.02, 0.01),
    "St. Venant-Kirchhoff (technique 1)": ('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0',
                                           f"technique = 1\n{HELD}", 0.02, 0.01),
    "technique 2": ('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0', f"technique = 2\n{HELD}", 0.02,
                    0.01),
    "technique 3": ('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0', f"technique = 3\n{HELD}", 0.02,
                    0.01),
    "neo-Hookean": ('model = "neo_hookean"\nC1 = 200.0\ndensity = 1.0', HELD, 0.02, 0.01),
    "Mooney-Rivlin": ('model = "mooney_rivlin"\nC1 = 150.0\nC2 = 50.0\ndensity = 1.0', HELD, 0.02, 0.01),
    "Guccione": ('model = "guccione"\nC1 = 100.0\nC2 = 8.0\nC3 = 4.0\nC4 = 4.0\ndensity = 1.0\n'
                 'axes = { kind = "cylindrical", axis = [0.0, 1.0, 0.0] }', HELD, 0.02, 0.01),
    "Holzapfel-Gasser-Ogden": ('model = "hgo"\nmu = 100.0\nk1 = 200.0\nk2 = 2.0\nkappa = 0.1\nbeta_deg = 40.0\n'
                               'density = 1.0\naxes = { kind = "cylindrical", axis = [0.0, 1.0, 0.0] }', HELD, 0.02,
                               0.01),
    "Lee-Sacks": ('model = "lee_sacks"\nc0 = 100.0\nc1 = 20.0\nc2 = 4.0\nc3 = 20.0\ndelta = 0.3\nbeta_deg = 30.0\n'
                  'density = 1.0\naxes = { kind = "cylindrical", axis = [0.0, 1.0, 0.0] }', HELD, 0.02, 0.01),
}


def panel_run(material: str, section: str, pressure: float, moment: float, distort: bool = True,
              edge_share: float = EDGE_SHARE):
    """A run of a 2 x 2 curved panel, clamped on one curved edge and symmetric on a
    straight one, its interior nodes moved off their places (distorted elements); the
    free straight edge under ``edge_share`` times the face pressure."""
    loads = SUPPORTS.replace("PRESSURE", repr(pressure)).replace("MOMENT", repr(moment))
    text = deck_text(PANEL, loads.replace("EDGE", repr(edge_share * pressure)))
    text = text.replace('model = "linear_elastic"\nE = 1000.0\nnu = 0.3\ndensity = 1.0', material)
    text = text.replace("thickness = 0.01", "thickness = 0.05\n" + section).replace("[solver]\nend_time = 1.0", STATIC)
    deck = parse_deck(text)
    mesh = build_mesh(deck)
    if distort:
        rng = np.random.default_rng(1)
        inner = np.setdiff1d(np.arange(mesh.n_nodes), np.concatenate([s.nodes for s in mesh.sets.values()
                                                                      if s.kind == "edge"]))
        mesh.x[inner] += 0.04 * rng.standard_normal((len(inner), 3)) * [1, 1, 0.2]
    return prepare(deck, mesh, build_model(deck, mesh))


def residual_after(eq: Equilibrium, move: np.ndarray, t: float) -> np.ndarray:
    """The free residual with the state moved by ``move`` (then moved back)."""
    saved = Converged(eq.sim)
    eq.move(move)
    eq.evaluate(t)
    r = eq.residual()[:eq.unknowns.n_free].copy()
    saved.restore(eq.sim)
    return r


@pytest.mark.parametrize(("path", "limit"), [(path, 1e-6) for path in PATHS] + [
    (path + ", lengths following", 1e-6) for path in ("technique 2", "Guccione")])
def test_tangent_matches_differences_of_the_residual(path, limit):
    """K v against central differences of the residual along random directions v (all
    unknowns at once, rotations included), at a strained state away from equilibrium, the
    elements' part by central differences too (the forward ones the solver forms are
    checked against these below): to 1e-6 with the fibre lengths held (measured 2e-10 to
    3e-8), and with them following the stretch, the coupling the tangent leaves out
    (measured 5e-8 and 4e-7; without the edge pressure, whose force scales with the fibre
    length)."""
    eq, t = strained(path)
    k = eq.tangent(central=True).toarray()
    rng = np.random.default_rng(8)
    size = eq.unknowns.size
    for _ in range(3):
        v = rng.standard_normal(size) * np.where(_is_rotation(eq), 1.0, 0.3)
        h = 1e-6
        derivative = (residual_after(eq, h * v, t) - residual_after(eq, -h * v, t)) / (2 * h)
        error = np.linalg.norm(k @ v + derivative) / np.linalg.norm(derivative)
        assert error <= limit, (path, error)


@pytest.mark.parametrize("deck", ["panel", "decks/stability/large_strain_sheet.toml"])
def test_every_element_entry_lands_where_a_plain_assembly_puts_it(deck):
    """The tangent's sparse pattern, worked out node by node, against scipy's assembly of
    the same element blocks entry by entry: a clamped panel with a symmetry plane (turned
    node frames), and a sheet with prescribed translations (known columns after the free)."""
    run = panel_run(*PATHS["small strain, total"]) if deck == "panel" else built_run(load_deck(ROOT / deck), ROOT)
    eq = Equilibrium(run.sim)
    u, conn = eq.unknowns, run.sim.model.conn
    k = np.random.default_rng(2).standard_normal((len(conn), ELEMENT_DOFS, ELEMENT_DOFS))
    dofs = u.index[conn].reshape(len(conn), -1)
    rows = np.broadcast_to(dofs[:, :, None], k.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], k.shape).ravel()
    used = (rows >= 0) & (rows < u.n_free) & (cols >= 0)
    plain = sp.coo_matrix((k.ravel()[used], (rows[used], cols[used])), shape=(u.n_free, u.size)).tocsc()
    ours = eq.pattern.assemble(k)
    assert u.n_known > 0 or deck == "panel"
    assert ours.nnz == plain.nnz and ours.has_sorted_indices
    assert abs(ours - plain).max() <= 1e-12 * abs(plain).max()
    # the free columns as the factors take them: the tangent's own arrays, no copy
    free = free_columns(ours, u.n_free)
    assert np.shares_memory(free.data, ours.data) and np.shares_memory(free.indices, ours.indices)
    assert abs(free - plain[:, :u.n_free]).max() <= 1e-12 * abs(plain).max()


@pytest.mark.parametrize("path", PATHS)
def test_forward_differences_match_central_ones(path):
    """The elements' tangent the solver forms, by forward differences (half the
    evaluations), against central differences at the same strained state: within 1e-6
    relative over the whole matrix (measured 4e-8 to 5e-7, the exponential laws highest)."""
    eq, _ = strained(path)
    forward, central = eq.tangent().toarray(), eq.tangent(central=True).toarray()
    assert np.linalg.norm(forward - central) <= 1e-6 * np.linalg.norm(central)


def strained(path: str) -> tuple[Equilibrium, float]:
    """The panel of ``path`` (a PATHS key, with ", lengths following" for the fibre lengths
    following the stretch) evaluated at load time t = 1 in a strained state: random moves
    of about a thickness and 0.1 rad from the converged one. Returns (equilibrium, t)."""
    material, section, pressure, moment = PATHS[path.removesuffix(", lengths following")]
    following = "following" in path  # the edge pressure scales with the fibre length: left out with it
    run = panel_run(material, section.replace(HELD, "") if following else section, pressure, moment,
                    edge_share=0.0 if following else EDGE_SHARE)
    eq = Equilibrium(run.sim)
    rng = np.random.default_rng(7)
    eq.move(rng.standard_normal(eq.unknowns.size) * np.where(_is_rotation(eq), 0.1, 0.03))
    eq.evaluate(1.0)
    return eq, 1.0


def _is_rotation(eq: Equilibrium) -> np.ndarray:
    """(size,) True for the unknowns that are rotations."""
    kind = np.zeros(eq.unknowns.size, dtype=bool)
    index = eq.unknowns.index
    kind[index[:, 3:][index[:, 3:] >= 0]] = True
    return kind


@pytest.mark.parametrize("path", ["small strain, total", "neo-Hookean", "Guccione"])
def test_tangent_at_rest_is_the_stiffness_product(path):
    """At the undeformed, unstressed state the tangent is the material stiffness K_L that
    the critical-step estimate's product applies (no load: no load stiffness)."""
    material, section, _, _ = PATHS[path]
    run = panel_run(material, section, 0.0, 0.0)
    eq = Equilibrium(run.sim)
    eq.evaluate(0.0)
    k = eq.tangent().toarray()
    model, s = run.model, run.sim.state
    rng = np.random.default_rng(3)
    v = rng.standard_normal(eq.unknowns.size)
    local = eq.unknowns.scatter(v)
    vu = np.einsum("nij,nj->ni", eq.unknowns.frames, local[:, :3])
    f, fr = np.zeros_like(vu), np.zeros((model.n_nodes, 2))
    run.sim.compiled.stiffness(model.structure, s.fields.shape, s.stress, vu, np.ascontiguousarray(local[:, 3:]), f, fr,
                               run.sim.workspace.parts)
    product = eq.unknowns.gather(eq.unknowns.to_local(f, fr))[:eq.unknowns.n_free]
    assert np.linalg.norm(k @ v - product) <= 1e-6 * np.linalg.norm(product)


def test_newton_converges_quadratically():
    """A curved panel under a pressure and a moment large enough to turn it well out of
    the linear range, in one load step: once near, each iteration squares the residual."""
    run = panel_run(*PATHS["neo-Hookean"][:2], 0.01, 0.003, distort=False)  # 0.5 rad, 2 thicknesses
    newton = NewtonSolver(run)
    newton.settings = newton.settings.model_copy(update={"newton": "full"})
    norms = []
    eq = newton.eq
    original = eq.residual
    eq.residual = lambda: _recorded(original(), norms, eq)
    newton.step(1.0)
    rates = [np.log(b) / np.log(a) for a, b in zip(norms, norms[1:]) if 1e-13 < b < a < 1e-2]
    assert len(norms) >= 4 and rates, norms
    assert min(rates) >= 1.7, (norms, rates)


def test_modified_newton_reaches_full_newtons_equilibrium_with_fewer_tangents():
    """The same panel in three load steps, by full and by modified Newton: the same
    equilibrium (positions and directors within 1e-6 of the largest displacement), the
    modified one forming fewer tangents than it takes iterations and than full Newton."""
    solved = {}
    for method in ("full", "modified"):
        run = panel_run(*PATHS["neo-Hookean"][:2], 0.01, 0.003)
        newton = NewtonSolver(run)
        newton.settings = newton.settings.model_copy(update={"newton": method})
        for t in (1 / 3, 2 / 3, 1.0):
            iterations, tangents, _ = newton.step(t)
            newton.commit(NewtonStep(t=t, load_time=t, iterations=iterations, tangents=tangents, residual=0.0,
                                     cutbacks=0))
            run.sim.state.t = t
        s = run.sim.state
        solved[method] = (s.x.copy(), s.d.copy(), sum(step.tangents for step in run.newton),
                          sum(step.iterations for step in run.newton), np.abs(s.x - run.model.x0).max())
    (x_full, d_full, tangents_full, _, moved), (x, d, tangents, iterations, _) = solved["full"], solved["modified"]
    assert np.abs(x - x_full).max() <= 1e-6 * moved and np.abs(d - d_full).max() <= 1e-6
    assert tangents < iterations and tangents < tangents_full, (tangents, iterations, tangents_full)


def _recorded(residual, norms, eq):
    norms.append(np.linalg.norm(residual[:eq.unknowns.n_free]) / max(eq.force_scale(), 1e-300))
    return residual


def burst_tube(tmp_path, solver: str, method: str = "static") -> tuple[int, str]:
    """A neo-Hookean tube (Test 9's) inflated far beyond its limit pressure by ``method``,
    its [solver] table's line after ``end_time`` given: the run's exit code and what it
    said."""
    text = (ROOT / "decks" / "verification" / "test09_aorta_static.toml").read_text()
    text = re.sub(r"\[material\]\n[^\[]*\[[^\]]*\] }\n", '[material]\nmodel = "neo_hookean"\nC1 = 1.0e4\ndensity = 1050.0\n',
                  text)
    text = text.replace("value = 18.66e3", "value = 10.0e3").replace('end_time = 0.16\n', f'end_time = 0.16\n{solver}\n')
    text = text[:text.index("[[reference]]")].replace('method = "static"', f'method = "{method}"')
    deck = tmp_path / "burst.toml"
    deck.write_text(text)
    result = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    return result.exit_code, " ".join(result.output.split())


def test_a_step_that_cannot_converge_is_stopped_with_where(tmp_path):
    """The burst tube: no equilibrium exists past the limit pressure, so load control
    cannot pass it, the steps are cut back to the smallest and the run stops with exit
    code 3, the load time, the residual and the node, the samples before it kept."""
    code, said = burst_tube(tmp_path, "static = { increments = 4, min_increment = 0.01, max_iterations = 10 }")
    assert code == 3, said
    assert "the static solve did not converge" in said and "% of solver.end_time" in said
    assert "largest residual force is at node" in said
    assert "solver.static.control = \"arc_length\" follows the path over it" in said  # a limit point: load control stops
    history = (tmp_path / "out" / "history.csv").read_text().splitlines()
    assert len(history) >= 3  # the header, t = 0 and the steps before the limit point


def test_an_implicit_step_that_cannot_converge_names_the_implicit_keys(tmp_path):
    """The same tube solved implicitly with one Newton iteration a step allowed: its
    steps are cut to the smallest and the message speaks of the implicit time step and
    its own keys, not of load control's."""
    code, said = burst_tube(tmp_path, "implicit = { increments = 4, min_increment = 0.01, max_iterations = 1 }",
                            method="implicit")
    assert code == 3, said
    assert "the implicit time step did not converge" in said and "solver.implicit.min_increment" in said
    assert "solver.static" not in said


def _history(run, name: str) -> np.ndarray:
    return np.asarray(run.history[name])


def test_arc_length_follows_a_balloon_over_its_pressure_maximum():
    """A neo-Hookean balloon past the top of its pressure-radius curve, where load control
    stops: the path's pressure at every step's inner radius is the exact sphere's
    (sphere_inflation_path) within 1%, and the path goes well beyond the maximum (the
    pressure falls by more than 10% of it while the radius keeps growing)."""
    deck = parse_deck((ROOT / "decks" / "verification" / "balloon_limit_point_arc_length.toml").read_text())
    run = run_deck(deck)
    assert run.status == "completed"
    radius, pressure = _history(run, "inner_radius")[1:], 1e3 * _history(run, "load_factor_ramp")[1:]
    exact = sphere_inflation_path(radius, 0.010, 0.0001, 1e4)
    assert np.abs(pressure / exact - 1).max() <= 0.01
    top = int(np.argmax(pressure))
    assert 0 < top < len(pressure) - 1 and pressure[-1] < 0.9 * pressure[top]
    assert np.all(np.diff(radius) > 0)  # one way along the path: no step went back


def test_sphere_inflation_path_meets_the_thin_membrane_formula():
    """The exact thick sphere against the thin-membrane balloon, P = 4 C1 (H/R) (1/l - 1/l^7)
    (l = r/R at mid-wall), as the wall thins: their difference falls like H/R."""
    for H in (1e-3, 1e-4):
        stretch = np.linspace(1.05, 2.0, 6)
        mid = 0.010 + H / 2
        inner = np.cbrt((stretch * mid) ** 3 - (mid**3 - 0.010**3))
        exact = sphere_inflation_path(inner, 0.010, H, 1.0)
        thin = 4 * (H / mid) * (1 / stretch - stretch**-7.0)
        assert np.abs(exact / thin - 1).max() <= 2 * H / 0.010


def test_the_reaction_balances_the_load_and_the_load_factor_is_recorded():
    """Test 2's cantilever solved statically: the clamp's reaction equals the dead load
    on the beam (28.5 upward) at every step, and the history's load factor of the static
    ramp is the load time's share of the span."""
    text = (ROOT / "decks" / "verification" / "test02_cantilever_uniform_load_3_static.toml").read_text()
    text = text.replace("[[reference]]", '''[[output.probe]]
name = "clamp_reaction"
quantity = "reaction"
set = "x0"
component = "z"

[[reference]]''')
    run = run_deck(parse_deck(text))
    factor = _history(run, "load_factor")
    assert np.allclose(factor, np.asarray(run.times) / run.deck.solver.end_time)
    assert np.allclose(_history(run, "clamp_reaction"), 28.5 * factor, rtol=1e-6, atol=1e-9)


def _preloaded_aorta(tmp_path, end_time: float) -> str:
    """Test 9's aorta inflated statically to 18.66 kPa at t = 0.14 (preload), then held
    explicitly to ``end_time``."""
    text = (ROOT / "decks" / "verification" / "test09_aorta_static.toml").read_text()
    text = text.replace('method = "static"\nend_time = 0.16', f"end_time = {end_time}\npreload = 0.14")
    return text[:text.index("[[reference]]")]


def test_a_preload_hands_its_equilibrium_to_the_explicit_run_without_a_jump(tmp_path):
    """Test 9's aorta solved statically to 18.66 kPa, then integrated explicitly with the
    pressure held: the explicit phase starts from the equilibrium at rest, so nothing
    moves: radius, wall thickness and stress stay within 1e-4 of their change over the
    preload, and the kinetic energy stays 1e-6 below the work it would take to undo it."""
    run = run_deck(parse_deck(_preloaded_aorta(tmp_path, 0.15)))
    assert run.status == "completed" and run.newton and run.sim.state.steps > 100
    times = np.asarray(run.times)
    handover = int(np.flatnonzero(np.isclose(times, 0.14))[-1])
    assert handover < len(times) - 10  # the explicit phase sampled after it
    for name in ("inner_radius", "wall_thickness", "stress_xx"):
        values = _history(run, name)
        change = abs(values[handover] - values[0])
        assert np.abs(values[handover:] - values[handover]).max() <= 1e-4 * change, name
    kinetic = np.asarray(run.energies)[handover:, 1]
    strain_work = 18.66e3 * np.pi * 0.01**2 * 0.04 * (_history(run, "inner_radius")[handover] / 0.01 - 1)
    assert kinetic.max() <= 1e-6 * strain_work
    assert np.allclose(_history(run, "load_factor_ramp")[handover:], 1.0)


def test_preload_and_arc_length_settings_that_cannot_work_are_refused(tmp_path):
    """A preload at or past the end, a preload on a static or implicit run, and arc-length
    control with a prescribed motion are deck errors naming the key."""
    aorta = _preloaded_aorta(tmp_path, 0.16)
    cases = {
        "late": (aorta.replace("preload = 0.14", "preload = 0.2"), "must come before end_time"),
        "static": (aorta.replace("preload = 0.14", 'preload = 0.14\nmethod = "static"'),
                   "'preload' is for explicit runs"),
        "implicit": (aorta.replace("preload = 0.14", 'preload = 0.14\nmethod = "implicit"'),
                     "'preload' is for explicit runs"),
        "prescribed": ((ROOT / "decks" / "verification" / "test02_cantilever_uniform_load_3_static.toml").read_text()
                       .replace("static = { increments = 4 }", 'static = { control = "arc_length" }')
                       .replace("[[load]]", '[[boundary]]\ntype = "prescribed"\nset = "tip"\ntranslation = "z"\n'
                                            'value = -1.0\n\n[[load]]'), "prescribe a motion"),
    }
    for name, (text, said) in cases.items():
        deck = tmp_path / f"{name}.toml"
        deck.write_text(text)
        result = CliRunner().invoke(app, ["check", str(deck)])
        assert result.exit_code == 2, (name, result.output)
        assert said in " ".join(result.output.split()), (name, result.output)
