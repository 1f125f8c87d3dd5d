"""Explicit quasi-static runs: uniform mass scaling to a target step, and dynamic
relaxation by kinetic damping to a stated residual, each checked against the static
Newton answer of the same cantilever (Test 2, 3 elements) and against the plain explicit
run (the ramp and hold with viscous damping it replaces)."""

from __future__ import annotations

import numpy as np
import pytest
from shellsim.deck import load_deck, parse_deck
from shellsim.deck.schema import MassScaling
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


SHEET = ROOT / "decks" / "stability" / "large_strain_sheet.toml"


def _scaled_throughout(deck, step: float):
    """``deck`` with every mass scaled throughout to ``step``."""
    return deck.model_copy(update={"solver": deck.solver.model_copy(
        update={"mass_scaling": MassScaling(step=step, throughout=True)})})


def test_mass_scaling_throughout_holds_the_step_while_the_sheet_stiffens():
    """The Mooney-Rivlin sheet pulled to 3.3 times its length, whose step falls 2.45
    times unscaled (the stability suite), every mass scaled throughout to twice its first
    step: each later estimate that finds the step shorter scales the masses again, so the
    run takes the target step (the estimates' margin below it at most) in about end_time /
    target steps; the factor reaches at least 4 x 2^2; the thickness is the closed form's
    h0 lambda^-1/2 and the energy balances, the kinetic energy kept at each rescaling."""
    from shellsim.study.jobs import variant_deck

    from .conftest import prepared

    deck = load_deck(SHEET)
    target = 2.0 * float(prepared(deck).sim.critical_time_step()) / deck.solver.dt_safety_factor
    run = run_deck(variant_deck(SHEET, {"solver.mass_scaling": {"step": target, "throughout": True}}))
    taken = np.array([dt for _, _, dt in run.dt_history])
    assert run.mass_rescalings > 0 and run.sim.mass_factor > 4.0 * 2.0 ** 2
    assert taken[1:].min() >= 0.95 * target
    assert run.sim.state.steps <= 1.05 * run.deck.solver.end_time / target
    stretch = 1.0 + 0.023 / 0.010
    assert run.history["thickness"][-1] == pytest.approx(0.001 / np.sqrt(stretch), rel=1e-4)
    assert abs(run.balance_error) < 1e-3 * run.sim.state.energy[EXTERNAL]


def test_a_rescaling_keeps_the_kinetic_energy_and_the_springs_stiffness(tmp_path):
    """Scaled again by hand (the step found at half the target): every mass times 4, the
    velocities halved (the kinetic energy the same), the step the target exactly, and the
    contact springs as they were (their rate and the masses they were set on together:
    as stiff as before, so no energy enters those pressed)."""
    from shellsim.solver.run import _hold_scaled_step

    from .conftest import pressed_plates_deck, prepared

    text = pressed_plates_deck(tmp_path / "plates.vtu", 0.01, "[solver]\nend_time = 1e-3\ndamping = 50.0")
    run = prepared(parse_deck(text))
    structure = float(run.sim.critical_time_step())
    run.dt_critical = structure  # no other limit on these plates' step
    run.dt = structure / run.deck.solver.dt_safety_factor
    target = 2.0 * run.dt
    run.deck = _scaled_throughout(run.deck, target)
    s = run.sim.state
    rng = np.random.default_rng(1)
    s.v[...], s.w[...] = rng.standard_normal(s.v.shape), rng.standard_normal(s.w.shape)
    kinetic = 0.5 * (s.mt @ (s.v ** 2).sum(axis=1) + s.mr @ (s.w ** 2).sum(axis=1))
    contact = next(b for b in run.model.loads if b is not None and hasattr(b, "face_inverse_mass"))
    spring, inverse_mass = contact.spring.copy(), contact.inverse_mass.copy()
    _hold_scaled_step(run)
    assert run.sim.mass_factor == pytest.approx(4.0, rel=1e-12) and run.mass_rescalings == 1
    assert run.dt == pytest.approx(target, rel=1e-12) and run.dt_history[-1][2] == run.dt
    assert 0.5 * (s.mt @ (s.v ** 2).sum(axis=1) + s.mr @ (s.w ** 2).sum(axis=1)) == pytest.approx(kinetic, rel=1e-12)
    assert np.array_equal(contact.spring, spring) and np.array_equal(contact.inverse_mass, inverse_mass)


def test_a_rescaling_keeps_the_supports_speeds_and_counts_their_work():
    """The sheet's pulled edge (prescribed translations) scaled again by 4: its imposed
    speeds stay (the supports keep them), the free DOFs' are halved, and the kinetic
    energy the supports give the added mass, (4 - 1) m v^2 / 2 on the unscaled masses,
    is their work."""
    from shellsim.solver.run import _hold_scaled_step

    from .conftest import prepared

    deck = load_deck(SHEET)
    run = prepared(_scaled_throughout(deck, 1.0))
    run.dt_critical, run.dt = 0.625, 0.5  # half the target: every mass times 4
    s = run.sim.state
    prescribed = run.model.constraints.prescribed
    s.v[...] = np.random.default_rng(2).standard_normal(s.v.shape)
    imposed, mass = s.v[prescribed.nodes, prescribed.axes].copy(), s.mt[prescribed.nodes].copy()
    free = np.ones(s.v.shape, dtype=bool)
    free[prescribed.nodes, prescribed.axes] = False
    before, work = s.v[free].copy(), float(s.work[EXTERNAL])
    _hold_scaled_step(run)
    assert len(imposed) > 0 and np.array_equal(s.v[prescribed.nodes, prescribed.axes], imposed)
    np.testing.assert_allclose(s.v[free], before / 2.0, rtol=1e-15)
    assert s.work[EXTERNAL] - work == pytest.approx(0.5 * 3.0 * float(mass @ imposed ** 2), rel=1e-12)
