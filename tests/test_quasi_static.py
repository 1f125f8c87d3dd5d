"""Explicit quasi-static runs: uniform mass scaling to a target step, and dynamic
relaxation by kinetic damping to a stated residual, each checked against the static
Newton answer of the same cantilever (Test 2, 3 elements) and against the plain explicit
run (the ramp and hold with viscous damping it replaces)."""

from __future__ import annotations

import numpy as np
import pytest
from shellsim.deck import load_deck, parse_deck
from shellsim.errors import DeckError
from shellsim.solver.explicit import DAMPED, EXTERNAL

from .conftest import ROOT, run_deck

VERIFICATION = ROOT / "decks" / "verification"
CANTILEVER = "test02_cantilever_uniform_load_3"


def _tip(run) -> float:
    return run.history["tip_deflection"][-1]


@pytest.fixture(scope="module")
def cantilever():
    """The 3-element cantilever run by one of its decks, named by the suffix of its file
    ("_static": Newton load steps; "": the ramp and hold to t = 0.12 with viscous damping;
    "_mass_scaled", "_relaxed"), each run once."""
    runs = {}

    def run(suffix: str):
        if suffix not in runs:
            runs[suffix] = run_deck(load_deck(VERIFICATION / f"{CANTILEVER}{suffix}.toml"))
        return runs[suffix]

    return run


def test_mass_scaling_reaches_the_static_answer_in_fewer_steps(cantilever):
    """Every mass times (target step / first step)^2: the step is the target (to the
    estimate's tolerance), the run takes that many times fewer steps than the plain one,
    and the tip comes to rest within 0.5% of the Newton answer."""
    newton, plain, scaled = cantilever("_static"), cantilever(""), cantilever("_mass_scaled")
    target = scaled.deck.solver.mass_scaling.step
    first = plain.dt_history[0][2]
    assert scaled.sim.mass_factor == pytest.approx((target / first) ** 2, rel=1e-3)
    assert scaled.dt_history[1][2] == pytest.approx(target, rel=1e-3)  # estimated again, scaled
    assert scaled.sim.state.steps < plain.sim.state.steps * 1.1 * first / target
    assert _tip(scaled) == pytest.approx(_tip(newton), rel=5e-3)


def test_dynamic_relaxation_stops_at_its_residual_on_the_static_answer(cantilever):
    """Kinetic damping (velocities zeroed at each peak of the kinetic energy), no viscous
    damping: once the load holds, the run stops as the out-of-balance force falls within
    its residual, before the end time and in fewer steps than the plain run, with the tip
    within 0.5% of the Newton answer; the energy taken out is the damping work, and the
    balance holds (internal + kinetic + taken out = external work)."""
    newton, plain, relaxed = cantilever("_static"), cantilever(""), cantilever("_relaxed")
    record = relaxed.relaxing.record(relaxed.sim)
    tolerance = relaxed.deck.solver.relaxation.residual
    assert record["relaxed_at"] is not None and record["relaxed_at"] < relaxed.deck.solver.end_time
    assert record["relaxed_at"] >= record["held_from"] == pytest.approx(0.06)
    assert record["residual"] <= tolerance and record["resets"] > 0
    assert relaxed.sim.state.steps < plain.sim.state.steps
    assert _tip(relaxed) == pytest.approx(_tip(newton), rel=5e-3)
    energy = relaxed.sim.state.energy
    assert energy[DAMPED] > 0.0 and relaxed.deck.solver.damping == 0.0  # the resets' share
    assert abs(relaxed.balance_error) < 1e-4 * energy[EXTERNAL]


def _curves(*tables):
    """Curves tables from (t, v, extrapolation) triples."""
    from shellsim.bundles import Curves
    from shellsim.curve_tables import EXTRAPOLATION

    size = max(len(t) for t, _, _ in tables)
    t = np.zeros((len(tables), size))
    v = np.zeros_like(t)
    for c, (times, values, _) in enumerate(tables):
        t[c, :len(times)], v[c, :len(values)] = times, values
    return Curves(t=t, v=v, length=np.array([len(times) for times, _, _ in tables]),
                  interp=np.zeros(len(tables), dtype=np.int64),
                  extrap=np.array([EXTRAPOLATION[e] for _, _, e in tables], dtype=np.int64))


def test_the_loads_hold_from_the_last_change_of_any_curve():
    from shellsim.solver.relaxation import held_from

    ramp = ([0.0, 0.06], [0.0, 1.0], "constant")
    pulse_then_rest = ([0.0, 0.1, 0.2, 0.5], [0.0, 1.0, 0.5, 0.5], "constant")
    assert held_from(_curves(ramp)) == 0.06
    assert held_from(_curves(ramp, pulse_then_rest)) == 0.2
    assert held_from(_curves(([0.0, 1.0], [1.0, 1.0], "linear"))) == 0.0  # constant: extrapolates to itself
    assert held_from(_curves(ramp, ([0.0, 1.0], [0.0, 1.0], "linear"))) == np.inf


@pytest.mark.parametrize("key", ["relaxation = { residual = 1e-4 }", "mass_scaling = { step = 1e-5 }"])
def test_a_static_run_refuses_what_only_an_explicit_run_has(key):
    text = (VERIFICATION / f"{CANTILEVER}_static.toml").read_text().replace('method = "static"', f'method = "static"\n{key}')
    with pytest.raises(DeckError, match=f"'{key.split()[0]}' is for explicit runs.*set method = 'explicit'"):
        parse_deck(text)
