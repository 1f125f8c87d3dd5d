"""What a static path passes and where it goes: the hinged roof's snap-through traced by
arc length against Sze, Liu & Lo's curve on two meshes, its limit points and a straight
strip's bifurcations found from the tangent's pivots, arc length through curves that
hold and end, landing on output times, and the works of a static solve against the
exact stored energy."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.solver.explicit import EXTERNAL, INTERNAL
from shellsim.solver.stability import describe
from shellsim.verify.analytic import sphere_inflation_path
from shellsim.verify.check import check

from .conftest import ROOT, run_deck

#: Sze, Liu & Lo (2004) section 3.8, the isotropic hinged roof (h = 12.7): the crown's
#: deflection -W_C and the load as a share of P_max = 3000 along the path (their Abaqus
#: S4R 16 x 16 curve, as tabulated in zanoni-mbdyn/MBDyn tests/plates/sze2004/sze38/
#: sze38_ref_a.dat). -W_C grows monotonically along the path, so the load is a function of it.
SZE_ROOF = np.array([
    (0.000, 0.0000), (0.693, 0.0877), (1.638, 0.1980), (3.087, 0.3473), (4.477, 0.4686), (5.802, 0.5647),
    (7.057, 0.6381), (8.237, 0.6908), (9.339, 0.7246), (10.358, 0.7412), (11.293, 0.7421), (12.141, 0.7286),
    (12.903, 0.7023), (13.583, 0.6649), (14.188, 0.6182), (14.728, 0.5643), (15.217, 0.5055), (15.676, 0.4442),
    (16.125, 0.3830), (16.590, 0.3245), (17.094, 0.2717), (17.657, 0.2272), (18.299, 0.1940), (19.028, 0.1750),
    (19.852, 0.1729), (20.771, 0.1905), (21.780, 0.2303), (22.875, 0.2950), (24.049, 0.3871), (24.663, 0.4443),
    (25.293, 0.5093), (25.940, 0.5826), (26.601, 0.6644)])


def _deck(name: str, replacements: dict[str, str] | None = None):
    text = (ROOT / "decks" / "verification" / f"{name}.toml").read_text()
    for old, new in (replacements or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    return parse_deck(text)


@pytest.mark.parametrize("mesh", ["4x4", "8x8"])
def test_arc_length_traces_the_hinged_roof_through_its_snap_on_sze_s_curve(mesh):
    """The roof's whole path, over the first limit point, down to the lowest load and up
    again: the deck's references are met; at every step's crown deflection the load is
    Sze et al.'s within 1% of P_max; the deflection only grows (no step went back along
    the path); both limit points are reported between the steps that bracket Sze's
    0.7421 and 0.1729."""
    run = run_deck(_deck(f"hinged_roof_snap_{mesh}"))
    assert run.status == "completed"
    times = np.asarray(run.times)
    assert all(check(ref, times, np.asarray(run.history[ref.probe]))["passed"] for ref in run.deck.reference)
    deflection = -np.asarray(run.history["crown_deflection"])
    load = np.asarray(run.history["load_factor_ramp"])
    assert np.all(np.diff(deflection) > 0.0)
    assert deflection[-1] > 24.0  # well onto the rising branch after the snap
    expected = np.interp(deflection, SZE_ROOF[:, 0], SZE_ROOF[:, 1])
    assert np.abs(load - expected).max() <= 0.01
    events = run.stability.events()
    assert [e["kind"] for e in events] == ["limit point", "limit point"]
    top, bottom = events
    assert (top["negative_pivots_from"], top["negative_pivots_to"]) == (0, 1)
    assert max(top["load_time_from"], top["load_time_to"]) == pytest.approx(0.7421, rel=0.02)
    assert min(bottom["load_time_from"], bottom["load_time_to"]) == pytest.approx(0.1729, rel=0.05)


STRIP = """[meta]
title = "a straight strip compressed past its Euler load"
units = "consistent"

[geometry]
builder = "rectangle"
length = 10.0
width = 1.0

[mesh]
divisions = { length = 8, width = 1 }

[material]
model = "linear_elastic"
E = 1.2e6
nu = 0.0
density = 1.0e-6

[section]
thickness = 0.2

[[boundary]]
type = "clamped"
set = "x0"

[[load]]
type = "edge_force"
set = "x1"
value = [-LOAD, 0.0, 0.0]

[solver]
method = "static"
end_time = 1.0
static = { increments = 10, control = "CONTROL" }
"""
#: The clamped-free strip's Euler loads: (2n - 1)^2 pi^2 EI / (4 L^2), EI = E b h^3 / 12.
EULER = np.pi**2 * 1.2e6 * 0.2**3 / 12 / (4 * 10.0**2)


@pytest.mark.parametrize("control", ["load", "arc_length"])
def test_a_straight_strip_past_its_euler_loads_reports_each_bifurcation(control):
    """A perfectly straight cantilever strip compressed to 10.5 times its Euler load
    stays straight (the path is the unstable trivial one): the run reports a bifurcation
    between the steps that bracket the first Euler load (0.0952 of the end load) and
    another bracketing the second (9 times it, 0.857), with 1 and then 2 negative pivots."""
    deck = parse_deck(STRIP.replace("LOAD", repr(10.5 * EULER)).replace("CONTROL", control))
    run = run_deck(deck)
    assert run.status == "completed"
    events = run.stability.events()
    assert [e["kind"] for e in events] == ["bifurcation", "bifurcation"]
    for event, mode, pivots in zip(events, (1, 9), (1, 2)):
        assert event["load_time_from"] < mode / 10.5 <= event["load_time_to"]
        assert event["negative_pivots_to"] == pivots


def test_stability_checks_can_be_left_out_of_load_control():
    """check_stability = false: the strip past its Euler loads reports nothing, and its
    load steps form no tangent beyond the first step's."""
    deck = parse_deck(STRIP.replace("LOAD", repr(10.5 * EULER)).replace('control = "CONTROL"',
                                                                        'control = "load", check_stability = false'))
    run = run_deck(deck)
    assert run.status == "completed" and run.stability.events() == []
    assert len(run.stability.observations) == 1  # the start's, which the first step's Newton uses


HELD_RAMP = """
[curves.ramp]
t = [0.0, 0.5, 0.7, 0.8]
value = [0.0, 1.0, 1.0, 0.5]

[output]
times = [0.25, 0.6]
"""


def test_arc_length_lands_on_output_times_and_knots_and_holds_where_the_curve_does():
    """Test 2's static cantilever under a curve that ramps, holds, unloads to half and
    ends: arc length lands on every output time and knot, moves through the holds with
    nothing to solve, and ends at the end time with the deflection load control finds
    at the same half load (which the unloading reaches on an elastic path)."""
    control = {"static = { increments = 4 }": 'static = { increments = 4, control = "arc_length" }',
               "follower = false": 'follower = false\ncurve = "ramp"'}
    run = run_deck(_deck("test02_cantilever_uniform_load_3_static", control | {"[solver]": HELD_RAMP + "[solver]"}))
    assert run.status == "completed"
    times = np.asarray(run.times)
    for landing in (0.25, 0.5, 0.6, 0.7, 0.8, 1.0):
        assert np.isclose(times, landing, rtol=0.0, atol=1e-12).any(), landing
    assert np.all(np.diff(times) > 0.0)
    half = run_deck(_deck("test02_cantilever_uniform_load_3_static", {"value = -2.85": "value = -1.425"}))
    assert run.history["tip_deflection"][-1] == pytest.approx(half.history["tip_deflection"][-1], rel=1e-6)
    held = np.flatnonzero((times > 0.5) & (times <= 0.7))
    assert all(run.newton[i - 1].iterations == 0 for i in held)  # nothing to solve while the load holds


def test_arc_length_gives_every_output_time_a_frame_and_stays_on_the_balloon_s_path():
    """The balloon with a frame every 0.01 of the clock, over its pressure maximum (0.2467)
    and down the far side: every output time has a frame of its own at its time, the
    inner radius grows at every step (a load step onto an output time past the maximum
    once turned the balloon inside out, -9.4 mm, and reported a jump), and the largest
    pressure is the deck's reference."""
    run = run_deck(_deck("balloon_limit_point_arc_length", {"times = [0.1, 0.2, 0.25]": "interval = 0.01"}))
    assert run.status == "completed"
    marks = np.append(np.arange(1, 29) * 0.01, 0.2867)
    frames = np.asarray(run.frame_times[1:])
    assert len(frames) == len(marks) and np.allclose(frames, marks, rtol=0.0, atol=1e-9)
    assert np.all(np.diff(run.history["inner_radius"]) > 0.0)
    assert [e["kind"] for e in run.stability.events()] == ["limit point"]
    assert max(run.history["load_factor_ramp"]) == pytest.approx(0.2466586, rel=0.01)


def test_a_path_that_comes_back_to_zero_load_ends_there_completed():
    """The thin hinged roof (h = 6.35, a quarter of P = 1000 at the crown) snaps back so
    far that its path returns to zero load; the ramp holds below load time 0, so the path
    ends there: the run is completed with every step converged, its last frame at that
    state, and it says where it ended and why, short of the end time."""
    run = run_deck(_deck("hinged_roof_snap_4x4", {"thickness = 12.7": "thickness = 6.35", "-750.0": "-250.0",
                                                  "end_time = 1.8": "end_time = 4.0"}))
    assert run.status == "completed"
    assert run.newton[-1].load_time == 0.0 and all(step.cutbacks == 0 for step in run.newton)
    assert run.frame_times[-1] == run.times[-1] < 4.0
    kinds = [e["kind"] for e in run.stability.events()]
    assert kinds[0] == "limit point" and kinds[-1] == "unloaded"
    assert "the run ends there, short of solver.end_time = 4" in describe(run.stability.events()[-1])


def test_a_static_run_s_works_are_the_balloon_s_stored_energy():
    """The balloon over its pressure maximum: the static works are no longer 0. The
    internal work at the last step equals the exact sphere's stored energy, the pressure's
    work on the cavity, int p dV over the path to the last inner radius (an eighth of the
    sphere), within 1%, the order of h/R of the shell's pressure itself; the external work
    equals it to the solve's tolerance."""
    run = run_deck(_deck("balloon_limit_point_arc_length"))
    radius = np.asarray(run.history["inner_radius"])[-1]
    radii = np.linspace(0.010, radius, 400)
    pressure = sphere_inflation_path(radii, 0.010, 0.0001, 1e4)
    stored = np.trapezoid(pressure * 4.0 * np.pi * radii**2, radii) / 8.0
    internal, external = run.energies[-1][INTERNAL], run.energies[-1][EXTERNAL]
    assert internal == pytest.approx(stored, rel=0.01)
    assert external == pytest.approx(internal, rel=1e-6)


def test_load_control_jumping_over_the_roof_s_snap_says_so():
    """The 4 x 4 roof by load steps to P_max: past the first limit point no equilibrium is
    near, and a step lands on the far branch after the snap. The run reports that jump,
    between load times that bracket Sze's limit load, and ends on Sze's far branch: the
    crown's deflection at P_max within 0.5% of their curve's (28.876, between their points
    at 0.9643 and 1.0835 P_max)."""
    run = run_deck(_deck("hinged_roof_snap_4x4", {'control = "arc_length", ': "", "end_time = 1.8": "end_time = 1.0"}))
    assert run.status == "completed"
    jumps = [e for e in run.stability.events() if e["kind"] == "jump"]
    assert len(jumps) == 1
    assert jumps[0]["load_time_from"] <= 0.7421 * 1.02 and jumps[0]["load_time_to"] >= 0.7421
    far = np.interp(1.0, [0.9643, 1.0835], [28.663, 29.374])  # Sze's last two points, past the table above
    assert -run.history["crown_deflection"][-1] == pytest.approx(far, rel=0.005)


def test_load_steps_grow_back_after_a_cut_even_where_every_step_forms_many_tangents():
    """Load control whose Newton solver cuts the second step to a quarter, and then forms
    8 tangents at every step whatever its length (a thin plate's linear convergence did
    so, and its steps stayed at 1/256 of the first for the rest of the run): the length
    grows by half after every second uncut step, back to the first step's, and the run
    ends at its end time."""
    from shellsim.execute import built_run
    from shellsim.solver import static
    from shellsim.solver.run import Listener

    run = built_run(_deck("test02_cantilever_uniform_load_3_static", {"increments = 4": "increments = 10"}),
                    ROOT / "decks" / "verification")
    tried: list[float] = []

    class Cutting:
        """The solver's stepping, as a plate that needs 8 tangents a step lets it go."""
        settings = run.deck.solver.static

        def observe(self):
            pass

        def reach(self, landing, length):
            cut = len(tried) == 1
            length = length * static.CUT if cut else length
            target = min(landing, run.sim.state.t + length)
            tried.append(target - run.sim.state.t)
            return static.NewtonStep(t=target, load_time=target, iterations=16, tangents=8, residual=1e-7,
                                     cutbacks=int(cut)), length

        def commit(self, step):
            run.newton.append(step)

    static.load_steps(run, Cutting(), Listener(), run.deck.solver.end_time)
    first = run.deck.solver.end_time / 10
    assert run.sim.state.t == pytest.approx(run.deck.solver.end_time)
    assert tried[1] == pytest.approx(first * static.CUT)
    grown = [b / a for a, b in zip(tried[1:], tried[2:]) if b / a > 1.0 + 1e-9]
    assert grown and all(ratio == pytest.approx(static.GROW) or ratio < static.GROW for ratio in grown)
    assert max(tried[2:]) == pytest.approx(first)
    assert len(tried) < 20
