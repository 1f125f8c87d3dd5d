"""The explicit solver: energy balance, a step above the critical one caught with a clear
message (and the results so far kept), the reference measures, and Test 1 against its
analytic reference."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.sparse.linalg import eigsh
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.deck import parse_deck
from shellsim.deck.schema import Reference
from shellsim.errors import NumericalError
from shellsim.solver.explicit import DAMPED, EXTERNAL, INTERNAL
from shellsim.study.jobs import variant_deck
from shellsim.verify.check import check, first_peak

from .conftest import ROOT, deck_text, prepared, run_deck

PLATE = ROOT / "decks" / "verification" / "test01_plate_step_2x2.toml"


@pytest.fixture(scope="module", params=["total", "incremental"])
def plate_run(request):
    """Test 1 in the total (Eq 3.1) and the incremental (Eq 3.2) formulation."""
    text = PLATE.read_text().replace("[section]", f'[section]\nformulation = "{request.param}"', 1)
    return run_deck(parse_deck(text, name=PLATE.name, base_dir=PLATE.parent))


def test_undamped_run_conserves_energy(plate_run):
    e = plate_run.sim.state.energy
    assert e[EXTERNAL] > 0
    assert abs(plate_run.balance_error) < 0.01 * e[EXTERNAL]


def test_plate_step_response_matches_the_mindlin_reference(plate_run):
    """Test 1 (benchmarks 1A): amplitude within 2% of the Mindlin static deflection and
    first peak within 2% of half the first Mindlin period."""
    times = np.asarray(plate_run.times)
    for reference in plate_run.deck.reference:
        result = check(reference, times, np.asarray(plate_run.history[reference.probe]))
        assert result["passed"], result


def test_a_steady_critical_step_is_refreshed_ever_less_often_up_to_the_decks_interval(plate_run):
    """The plate's critical step barely moves, so the intervals between estimates double
    from 5 steps up to dt_update_every (at the start, after each, and one more when the
    steps end on one)."""
    steps = plate_run.sim.state.steps
    every = plate_run.deck.solver.dt_update_every
    interval, at, estimates = 5, 0, 1
    while at + interval <= steps:
        at, estimates, interval = at + interval, estimates + 1, min(2 * interval, every)
    assert len(plate_run.dt_history) == estimates
    assert all(dt < crit for _, crit, dt in plate_run.dt_history)


def critical_step(thickness: float, mass: str) -> float:
    deck = variant_deck(ROOT / "decks" / "verification" / "test02_cantilever_uniform_load_3.toml",
                        {"section.thickness": thickness, "solver.mass": mass})
    return prepared(deck).sim.critical_time_step()


def test_m1_rotary_inertia_keeps_the_step_of_a_thin_shell():
    """M2's rotary inertia rho h^3 / 12 against the shear stiffness kappa G h makes the
    critical step fall with the thickness (t/L from 1e-3 to 1e-4: ten times); M1's floor
    A / 8 per unit mass (thesis 3.14.1) keeps it at the membrane's, whatever the thickness."""
    m2 = critical_step(0.01, "M2") / critical_step(0.001, "M2")
    m1 = critical_step(0.01, "M1") / critical_step(0.001, "M1")
    assert m2 == pytest.approx(10.0, rel=0.05)
    assert m1 == pytest.approx(1.0, abs=1e-3)


def test_a_critical_step_estimate_over_budget_errs_on_the_safe_side(monkeypatch):
    """The first Lanczos run has PRODUCTS stiffness products; past them the coarse
    tolerance takes over and its bound is no smaller than the converged one (a shorter
    step, never a longer one). A 6 x 6 bench plate with a budget of 10 forces the fallback."""
    from shellsim.solver import timestep

    deck = parse_deck((ROOT / "decks" / "bench" / "plate_step.toml").read_text()
                      .replace("length = 2, width = 2", "length = 6, width = 6"))
    sim = prepared(deck).sim
    converged, _ = timestep.largest_eigenvalue(sim)
    products = []
    monkeypatch.setattr(timestep, "PRODUCTS", 10)
    monkeypatch.setattr(timestep, "eigsh", lambda *a, **k: products.append(k["tol"]) or eigsh(*a, **k))
    bounded, _ = timestep.largest_eigenvalue(sim)
    assert products == [timestep.TOLERANCE, timestep.COARSE_TOLERANCE]
    assert converged * (1 - timestep.TOLERANCE) <= bounded <= converged * (1 + 10 * timestep.COARSE_TOLERANCE)


def test_a_degenerate_operator_is_a_message_not_an_arpack_error():
    """No stiffness at all (every product zero: ARPACK cannot start), a stiffness that is
    no number (a shape degenerated in a run: it was a traceback from the Lanczos
    iteration's tridiagonal solver) and masses that are no number each end in
    NumericalError saying what is degenerate and what to check."""
    from shellsim.solver import timestep

    sim = prepared(parse_deck(PLATE.read_text())).sim
    sim.update_masses()
    zero = sim.compiled._replace(stiffness=lambda *args: [a.fill(0.0) for a in args[5:7]])
    sim.compiled = zero
    with pytest.raises(NumericalError, match=r"could not be estimated at t = 0: .*check the magnitudes of material.E"):
        timestep.largest_eigenvalue(sim)
    sim.compiled = zero._replace(stiffness=lambda *args: [a.fill(np.nan) for a in args[5:7]])
    for start in (None, np.ones(5 * len(sim.state.mt))):  # ARPACK's first estimate, and a later one's Lanczos
        with pytest.raises(NumericalError, match=r"broke down at t = 0: the stiffness at its shape is no longer a number"):
            timestep.largest_eigenvalue(sim, start)
    sim.state.mt[3] = np.nan
    with pytest.raises(NumericalError, match=r"lumped masses of 1 nodes \(first, counting from 1: \[4\]\)"):
        timestep.largest_eigenvalue(sim)


def test_a_step_above_the_critical_one_is_stopped_with_a_clear_message():
    """The message says where the motion broke down (the nodes without a number, or the
    fastest one, and where it was at rest) and that the step was above the critical one."""
    deck = parse_deck(PLATE.read_text().replace("[solver]\n", "[solver]\ndt_safety_factor = 0.8\n"))
    with pytest.raises(NumericalError, match=r"unstable.*(no longer have a number for a position or velocity|the "
                                             r"fastest node moves at [-+.e\d]+): node \d+, at \([^)]+\) at rest.*"
                                             r"dt_safety_factor = 0.8 < 1"):
        run_deck(deck)


def test_a_scene_that_waits_unloaded_is_not_taken_for_unstable():
    """The closing valve's coarse variant, explicit, with its pressure held off for its
    first 2 ms: the built leaflets move by round-off alone, energies of 1e-32 with no
    external work to measure them by, which is no instability (it was taken for one after
    16 steps); the balance is not judged, nor shown, until the energies outgrow round-off."""
    waiting = {"mesh.divisions": {"around": 8, "belly": 4, "coaptation": 2}, "solver.end_time": 0.002,
               "solver.method": "explicit", "solver.damping": 300.0,
               "curves.diastole.t": [0.0, 0.01, 0.05], "curves.diastole.value": [0.0, 0.0, 1.0]}
    run = run_deck(variant_deck(ROOT / "decks" / "valves" / "aortic_valve_closing.toml", waiting))
    assert run.status == "completed" and run.sim.state.steps > 100
    assert run.balance_share() is None


def test_an_unstable_run_keeps_what_it_wrote(tmp_path):
    deck = tmp_path / "unstable.toml"
    deck.write_text(PLATE.read_text().replace("[solver]\n", "[solver]\ndt_safety_factor = 0.8\n"))
    result = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 3
    assert "unstable" in result.output and "Traceback" not in result.output
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "unstable" and "dt_safety_factor" in summary["message"]
    rows = (tmp_path / "out" / "history.csv").read_text().splitlines()
    assert len(rows) > 2 and rows[0].startswith("time,dt,")


def test_run_writes_a_summary_with_the_reference_checks(tmp_path):
    result = CliRunner().invoke(app, ["run", str(PLATE), "--out", str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("deck", "elements", "nodes", "dofs", "steps", "sim_time", "wall_time_s",
                "us_per_element_step", "dt", "energy", "features", "reference"):
        assert key in summary
    assert summary["status"] == "completed" and summary["sim_time"] == pytest.approx(1.6e-3)
    assert {"min", "mean", "max"} <= set(summary["dt"])
    assert {"internal", "kinetic", "external_work", "balance_error"} <= set(summary["energy"])
    assert "dead_pressure" in summary["features"]["used"] and "hyperelastic" in summary["features"]["left_out"]
    assert all(r["passed"] for r in summary["reference"])


def test_first_peak_of_a_step_response_ignores_ripples():
    t = np.linspace(0.0, 3.0, 3001)
    omega = np.pi  # peak at t = 1
    signal = 1 - np.cos(omega * t) + 0.004 * np.sin(37 * t)  # a ripple shifts the maximum
    peak_time, peak = first_peak(t, signal)
    assert peak_time == pytest.approx(1.0, abs=2e-3)
    assert peak == pytest.approx(2.0, abs=0.01)


def test_reference_measures_and_tolerances():
    t = np.linspace(0.0, 1.0, 11)
    values = 2 * t
    ref = dict(quantity="q", probe="p", source="closed form", expected=1.0)
    assert check(Reference(**ref, measure="at_time", time=0.5, tolerance_percent=0.1), t, values)["passed"]
    assert not check(Reference(**ref, measure="final", tolerance_percent=10.0), t, values)["passed"]
    assert check(Reference(**ref | {"expected": 2.05}, measure="max", tolerance=0.1), t, values)["passed"]


FOLDING = deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', """
[[boundary]]
type = "clamped"
set = "x0"

[[boundary]]
type = "prescribed"
set = "x1y1"
translation = "x"
value = -1.5
curve = "ramp"

[[boundary]]
type = "prescribed"
set = "x1y1"
translation = "y"
value = -1.5
curve = "ramp"

[curves.ramp]
t = [0.0, 1.0]
value = [0.0, 1.0]
""")


@pytest.mark.parametrize(("mass", "state", "lowest"), [
    ("M1", "has folded over: its volume ratio", 0.0),
    ("M2", "is distorted beyond what its lumped masses bear: the masses of its node(s) 6 are no longer positive", 0.25),
])
def test_a_folding_element_is_named_as_the_cause_and_its_frame_kept(tmp_path, mass, state, lowest):
    """The corner node of a 2 x 2 plate is driven diagonally through its element (number 4,
    centred at (0.75, 0.75)): the run must blame that element, not the time step, and keep
    the breaking state as the series' last frame. With M1 masses (positive until it folds)
    the element folds over; M2's row sums on the current shape turn negative at its corner
    node 6 first (its shape functions are negative over part of it), where the critical
    step, estimated every step by then, stops the run."""
    import meshio

    deck = tmp_path / "fold.toml"
    deck.write_text(FOLDING.replace("[solver]\n", f'[solver]\nmass = "{mass}"\n'))
    result = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 3, result.output
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    message = summary["message"]
    assert f"element 4 (counting from 1) at (0.75, 0.75, 0) {state}" in message
    assert "refine the mesh around that element" in message and "dt_safety_factor" not in message
    assert summary["element_quality"]["lowest"]["element"] == 4
    assert summary["element_quality"]["lowest"]["ratio"] <= lowest
    reader = meshio.xdmf.TimeSeriesReader(tmp_path / "out" / "results.xdmf")
    assert reader.num_steps == summary["frames"] >= 2
    reader.read_points_cells()
    last_time, _, _ = reader.read_data(reader.num_steps - 1)
    assert last_time == pytest.approx(summary["breaking_frame_time"]) == pytest.approx(summary["sim_time"])


def test_the_worst_element_of_an_undistorted_run_keeps_its_volume(plate_run):
    """Small bending of a plate barely changes any element's volume: the watch reads 1."""
    assert plate_run.lowest is not None and abs(plate_run.lowest.ratio - 1.0) < 1e-3


def test_the_supports_pay_the_damping_of_the_motion_they_prescribe():
    """The stability suite's sheet lifted rigidly out of its plane by a prescribed motion
    of every node, with mass-proportional damping: no strain, so the supports' work is
    the kinetic energy plus the damping's work, which the reaction's damping force
    (c m v on each prescribed translation) pays. Without it the balance would be off by
    the damping's whole work; what is left (3e-4) is the supports' inertia summed over
    the half-step velocities, first order in the step."""
    sheet = (ROOT / "decks" / "stability" / "large_strain_sheet.toml").read_text()
    text = (sheet.replace('set = "x1"\ntranslation = "x"\nvalue = 0.023', 'set = "all"\ntranslation = "z"\nvalue = 0.005')
            .replace("end_time = 0.25", "end_time = 0.05").replace("t = [0.0, 0.2]", "t = [0.0, 0.05]"))
    assert 'set = "all"' in text and "end_time = 0.05" in text and "t = [0.0, 0.05]" in text
    run = run_deck(parse_deck(text))
    e = run.sim.state.energy
    assert e[DAMPED] > 0.1 * e[EXTERNAL] > 0.0  # the damping takes a good share
    assert abs(e[INTERNAL]) < 1e-9 * e[EXTERNAL]
    assert abs(run.balance_error) < 1e-3 * e[EXTERNAL]
