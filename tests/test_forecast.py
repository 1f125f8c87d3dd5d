"""The forecast: the explicit steps a run takes to land on its output times, the
estimates its schedule makes, and the critical step followed under the loads by a static
rehearsal; a Newton path's steps rehearsed; checked against closed forms and against the
run itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.solver.outlook import NEWTON_PACE, explicit_schedule, forecast, newton_steps
from shellsim.solver import rehearsal
from shellsim.solver.rehearsal import critical_steps_under_load

from .conftest import CLAMPED_PLATE, ROOT, deck_text, prepared, run_deck


def _deck(solver: str, output: str):
    """The clamped plate with these ``[solver]`` and ``[output]`` keys."""
    return parse_deck(deck_text(*CLAMPED_PLATE).replace("[solver]\nend_time = 1.0", f"[solver]\n{solver}")
                      + f"\n[output]\n{output}\n")


def test_a_landing_one_and_a_half_steps_on_takes_two_and_steps_that_hold_double_the_estimates_apart():
    deck = _deck("end_time = 1.0\ndt_update_every = 100", "interval = 0.015")
    dt = 0.01  # 1.5 steps to each of 66 landings, then 1 step to the end at 1.0
    schedule = explicit_schedule(deck, np.zeros(1), np.full(1, dt))
    assert schedule["steps"] == 66 * 2 + 1
    # estimates after 5, 15, 35, 75 steps (intervals 5, 10, 20, 40), the next at 155 > 133
    assert schedule["estimates"] == 4


def test_a_step_halving_over_the_run_takes_the_integral_of_its_inverse():
    """dt(t) = a (1 - t / 2T) over [0, T] takes int dt / dt(t) = 2 ln 2 T / a steps."""
    deck = _deck("end_time = 1.0", "interval = 1.0")
    a = 1e-4
    schedule = explicit_schedule(deck, np.array([0.0, 1.0]), np.array([a, a / 2]))
    assert schedule["steps"] == math.ceil(2 * math.log(2) / a)


def test_a_step_that_changes_is_estimated_as_often_as_its_change_asks():
    """A step falling by the same share each step, dt_n = dt_0 exp(-r n), at 2x safety:
    each estimate may let ln(dt) move by a quarter of ln 2 (MARGIN_SHARE), so the interval
    doubles from 5 steps (estimates at 5, 15, ..., 635) until it reaches (ln 2 / 4) / r,
    here 640 steps, and stays there."""
    n_total, dt0 = 20000, 1e-4
    r = math.log(2) / 4 / 640
    n = np.linspace(0.0, n_total, 2001)
    times, dts = dt0 * (1 - np.exp(-r * n)) / r, dt0 * np.exp(-r * n)
    deck = _deck(f"end_time = {float(times[-1])!r}\ndt_safety_factor = 2.0\ndt_update_every = 100000",
                 f"interval = {float(times[-1])!r}")
    schedule = explicit_schedule(deck, times, dts)
    assert schedule["steps"] == pytest.approx(n_total, rel=1e-3)
    assert schedule["estimates"] == pytest.approx(7 + (n_total - 636) / 640, rel=0.05)
    steady = explicit_schedule(deck, np.zeros(1), np.full(1, dt0))
    assert steady["estimates"] < 20  # doubling from 5 steps, unbounded: log2 of the steps


STRETCHED = (ROOT / "decks" / "stability" / "large_strain_sheet.toml").read_text().replace(
    "end_time = 0.25", "end_time = 0.05").replace("t = [0.0, 0.2]", "t = [0.0, 0.04]").replace(
    "value = 0.023", "value = 0.01")


def test_the_rehearsal_follows_a_stretched_sheets_step_as_it_falls_and_the_run_takes_as_many_steps(monkeypatch):
    """A Mooney-Rivlin sheet stretched to twice its length: its elements lengthen, thin and
    stiffen, and the critical step falls; the forecast that follows it under the load
    counts the run's steps to within 5% (at the step at rest it counted a quarter fewer).
    The rehearsal has no time limit here, so a busy machine cannot cut it short."""
    monkeypatch.setattr(rehearsal, "REHEARSAL_SECONDS", math.inf)
    deck = parse_deck(STRETCHED)
    run = prepared(deck)
    times, critical = critical_steps_under_load(deck, run.mesh, run.model)
    assert times[0] == 0.0 and times[-1] == pytest.approx(0.05)
    assert critical[-1] < 0.8 * critical[0]
    ahead = forecast(deck, run.mesh, run.model)
    taken = run_deck(deck).sim.state.steps
    assert ahead["steps"] == pytest.approx(taken, rel=0.05)
    assert ahead["loaded"]["critical"] == pytest.approx(critical.min())


def test_a_rehearsal_that_cannot_solve_its_loads_statically_keeps_the_start_and_never_raises():
    """A plate with no support has no static equilibrium: the rehearsal ends at the start,
    and the forecast holds the step at rest."""
    geometry, clamped_and_pressed = CLAMPED_PLATE
    deck = parse_deck(deck_text(geometry, clamped_and_pressed[clamped_and_pressed.index("[[load]]"):]))
    run = prepared(deck)
    times, critical = critical_steps_under_load(deck, run.mesh, run.model)
    assert list(times) == [0.0] and len(critical) == 1


def test_a_rehearsal_out_of_time_keeps_the_start():
    deck = parse_deck(STRETCHED)
    run = prepared(deck)
    times, critical = critical_steps_under_load(deck, run.mesh, run.model, seconds=0.0)
    assert list(times) == [0.0] and len(critical) == 1  # the start


def test_a_state_whose_step_cannot_be_estimated_ends_the_rehearsal_before_it(monkeypatch):
    """The stretched sheet with the step's estimate failing at its second state, as at a
    state whose forces overflow (scipy: 'array must not contain infs or NaNs'): the
    rehearsal keeps the start alone, a time for each step (a time without its step had
    stopped check with 'fp and xp are not of the same length')."""
    monkeypatch.setattr(rehearsal, "REHEARSAL_SECONDS", math.inf)
    estimates = iter([False, True])

    def failing(*args):
        if next(estimates, True):
            raise ValueError("array must not contain infs or NaNs")
        return real(*args)

    real = rehearsal.stable_step
    monkeypatch.setattr(rehearsal, "stable_step", failing)
    deck = parse_deck(STRETCHED)
    run = prepared(deck)
    times, critical = critical_steps_under_load(deck, run.mesh, run.model)
    assert list(times) == [0.0] and len(critical) == 1


ROLLUP_STATIC = ROOT / "decks" / "verification" / "test04_strip_rollup_static.toml"


def test_a_static_solve_rehearsed_to_its_end_is_forecast_as_the_run_takes_it(monkeypatch):
    """The strip rolled up statically takes 15 iterations and 8 tangents a load step,
    twice and eight times what the shipped decks' pace counts: rehearsed to its end, the
    forecast is the run's own steps, iterations and tangents (a deterministic solve). No
    time limit here, so a busy machine cannot cut the rehearsal short."""
    monkeypatch.setattr(rehearsal, "REHEARSAL_SECONDS", math.inf)
    deck = parse_deck(ROLLUP_STATIC.read_text())
    run = prepared(deck, ROLLUP_STATIC.parent)
    ahead = forecast(deck, run.mesh, run.model)
    taken = run_deck(deck, ROLLUP_STATIC.parent)
    steps = len(taken.newton)
    assert ahead["rehearsed"] and ahead["steps"] == steps == taken.sim.state.steps
    assert ahead["pace"] == (sum(s.iterations for s in taken.newton) / steps, len(taken.tangent_seconds) / steps)
    assert ahead["pace"][1] > 2 * NEWTON_PACE["load"][1]  # what the shipped pace would have missed


def test_a_newton_rehearsal_out_of_time_is_forecast_at_the_shipped_pace(monkeypatch):
    monkeypatch.setattr(rehearsal, "REHEARSAL_SECONDS", 0.0)
    deck = parse_deck(ROLLUP_STATIC.read_text())
    run = prepared(deck, ROLLUP_STATIC.parent)
    ahead = forecast(deck, run.mesh, run.model)
    assert not ahead["rehearsed"] and ahead["steps"] == newton_steps(deck) and ahead["pace"] == NEWTON_PACE["load"]
