"""The critical step's later estimates and their schedule (shellsim.solver.timestep):
a later estimate finds a top mode that has overtaken the last one, and estimates come as
often as the critical step moves."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shellsim.solver.timestep import EstimateSchedule, MARGIN_SHARE, mixed_start, short_lanczos


def _diagonal(values: np.ndarray):
    return lambda z: values * z


def test_a_later_estimate_finds_a_mode_that_overtook_the_last_one():
    """The last top eigenvector is now the second mode (another has grown past it, as when
    an element crumples). From it alone Lanczos stops at once on its own eigenvalue;
    mixed with a random vector it finds the top one, within the tolerance, from above."""
    rng = np.random.default_rng(3)
    values = np.sort(rng.uniform(1.0, 100.0, 500))
    values[-1], values[-2] = 130.0, 120.0
    last = np.zeros(500)
    last[-2] = 1.0
    stale, _ = short_lanczos(_diagonal(values), last, 1e-3, 40)
    assert stale == pytest.approx(120.0, rel=1e-12)
    found, vector = short_lanczos(_diagonal(values), mixed_start(last, rng), 1e-3, 40)
    assert 130.0 <= found <= 130.0 * (1 + 1e-3)
    assert abs(vector[-1]) / np.linalg.norm(vector) > 0.99


def test_lanczos_gives_up_when_it_has_not_converged_within_its_products():
    values = np.linspace(1.0, 100.0, 400) ** 0.01  # a cluster at the top: slow to resolve
    assert short_lanczos(_diagonal(values), np.ones(400), 1e-12, 5) is None


def _intervals(criticals, safety: float = 1.25, most: int = 100) -> list[int]:
    schedule = EstimateSchedule(safety, most)
    step, out = 0, [schedule.after_estimate(0, criticals(0))]
    while step < 3000:
        step += out[-1]
        out.append(schedule.after_estimate(step, criticals(step)))
    return out


def test_a_steady_critical_step_is_estimated_ever_less_often_up_to_the_decks_interval():
    assert _intervals(lambda step: 1e-5)[:8] == [5, 10, 20, 40, 80, 100, 100, 100]
    assert _intervals(lambda step: 1e-5, most=30)[:5] == [5, 10, 20, 30, 30]


def test_a_moving_critical_step_is_estimated_as_often_as_its_change_uses_the_margin():
    """Falling by 0.1% a step (a quarter of ln 1.25 in 56 steps) the interval settles at
    56 steps; the change over each interval then stays within that share of the margin."""
    rate = 1e-3
    intervals = _intervals(lambda step: 1e-5 * math.exp(-rate * step))
    allowed = MARGIN_SHARE * math.log(1.25) / rate
    assert intervals[-1] == int(allowed)
    assert all(interval <= allowed for interval in intervals)


def test_a_swing_is_remembered_for_the_decks_interval():
    """The critical step falls fast for 60 steps, then holds: the interval stays short
    until the fall has left the last 100 steps, then grows again by doubling."""
    def critical(step):
        return 1e-5 * math.exp(-0.02 * min(step, 60))

    schedule = EstimateSchedule(1.25, 100)
    step, interval = 0, schedule.after_estimate(0, critical(0))
    steps, intervals = [], []
    while step < 600:
        step += interval
        interval = schedule.after_estimate(step, critical(step))
        steps.append(step), intervals.append(interval)
    short = int(MARGIN_SHARE * math.log(1.25) / 0.02)
    held = [i for s, i in zip(steps, intervals) if 60 < s < 150]
    assert held and all(i <= short for i in held)
    assert intervals[-1] == 100


def test_without_a_margin_the_decks_interval_is_kept():
    assert _intervals(lambda step: 1e-5 * math.exp(-1e-2 * step), safety=0.8)[1:4] == [100, 100, 100]
