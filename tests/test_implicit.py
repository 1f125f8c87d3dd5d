"""Implicit dynamics (``solver.method = "implicit"``, HHT-alpha): checked against the closed
forms of a plate's step response (its first peak, twice the static deflection, at half the
first period), the trapezoidal rule's exact energy balance on a linear structure, HHT's
dissipation settling the plate at its static deflection in steps as long as its period
with exactly the energy a step load leaves over, and a slack cable, whose nodes a static
solve finds no stiffness at, brought to the exact elastic catenary."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from shellsim.deck import parse_deck

from .conftest import run_deck
from .test_cable import hanging_cable_errors

#: The quarter plate of decks/bench/plate_step.toml: a = 10 m, h = 0.1 m, aluminium, q = 1000
#: Pa as a step; Kirchhoff's 2 w_static and pi / omega_11 (its references, benchmarks.md 1A).
PLATE = Path(__file__).parents[1] / "decks" / "bench" / "plate_step.toml"
PEAK, PEAK_TIME = -1.26745e-2, 0.103291


def plate_run(end_time: float, increments: int, alpha: float):
    """The plate solved implicitly to ``end_time`` in ``increments`` steps (frames at the
    end only: output times are steps' landings)."""
    text = PLATE.read_text().replace("end_time = 0.18", f'end_time = {end_time}\nmethod = "implicit"\n'
                                                        f"implicit = {{ increments = {increments}, alpha = {alpha} }}")
    return run_deck(parse_deck(text.replace("interval = 0.001", f"interval = {end_time}")))


def test_the_trapezoidal_rule_follows_the_plate_s_step_response_and_keeps_its_energy():
    """alpha = 0, 125 steps over 0.125 s (about 200 per period): the first peak of the
    centre deflection within 0.2% of Kirchhoff's 2 w_static and at half the first period
    within a step; the work of the pressure equals the strain and kinetic energy to 1e-6
    of it (the trapezoidal rule keeps a linear system's energy exactly; the plate's
    rotations of 1e-3 leave it all but linear)."""
    run = plate_run(0.125, 125, 0.0)
    assert run.status == "completed" and len(run.newton) == 125
    w = np.asarray(run.history["centre_deflection"])
    t = np.asarray(run.times)
    assert w.min() == pytest.approx(PEAK, rel=2e-3)
    assert abs(t[np.argmin(w)] - PEAK_TIME) <= 1e-3
    assert abs(run.balance_share()) < 1e-6


def test_hht_damping_settles_the_plate_at_its_static_deflection_in_steps_of_ten_periods():
    """alpha = -1/3 and 30 steps of 2 s (ten periods each: HHT takes each step's
    oscillation down by its spectral radius, 1/2, there): the plate comes to rest at
    Kirchhoff's static deflection (half the peak) within 0.2%, and HHT has taken what a
    step load leaves over the strain energy: half the pressure's work (at rest q w_s is
    twice q w_s / 2), the balance error -1/2 within 1%."""
    run = plate_run(60.0, 30, -1.0 / 3.0)
    assert run.status == "completed"
    assert run.history["centre_deflection"][-1] == pytest.approx(PEAK / 2.0, rel=2e-3)
    assert run.balance_share() == pytest.approx(-0.5, rel=1e-2)


def test_a_slack_cable_falls_to_the_exact_elastic_catenary_where_a_static_solve_cannot_start():
    """The hanging cable of test_cable in 8 segments, its interior nodes with no stiffness
    while it is slack (a static solve is refused it), solved in 60 implicit steps with
    the deck's damping: at rest on the elastic catenary to the same midspan sag error as
    the explicit run's (8.1e-3, the 8 segments' discretisation)."""
    sag, across = hanging_cable_errors(8, 'method = "implicit"\nimplicit = { increments = 60, alpha = -0.3333 }')
    assert 7e-3 < sag < 9e-3 and across < sag


def test_check_times_a_tangent_and_its_factors_for_the_implicit_path(tmp_path, monkeypatch):
    """``check`` of the plate as an implicit deck rehearses its solve: where that ends in
    its time, the cost is the rehearsal's steps and pace; where it cannot (no time here),
    a tangent formed at rest and factorised, timed on this machine, at the implicit
    path's iterations and tangents a step, beside the unknowns (5 per node)."""
    import math
    import re

    from typer.testing import CliRunner

    from shellsim.cli import app
    from shellsim.geometry import build_mesh
    from shellsim.solver import rehearsal

    text = PLATE.read_text().replace("end_time = 0.18", 'end_time = 0.18\nmethod = "implicit"')
    deck = tmp_path / "plate.toml"
    deck.write_text(text)
    unknowns = 5 * len(build_mesh(parse_deck(text)).x)

    def said(seconds: float) -> str:
        monkeypatch.setattr(rehearsal, "REHEARSAL_SECONDS", seconds)
        result = CliRunner().invoke(app, ["check", str(deck)], env={"COLUMNS": "60"})
        assert result.exit_code == 0, result.output
        return " ".join(result.output.replace("│", " ").split())

    timed = said(0.0)
    assert re.search(rf"{unknowns:,} unknowns; about [\d,]+ steps and [\d.e+-]+ (s|min|h) on this machine \(at 11 "
                     r"iterations and 5.1 tangents a step.*: [\d.e+-]+ (s|min|h) a tangent", timed), timed
    rehearsed = said(math.inf)
    assert re.search(rf"{unknowns:,} unknowns; about [\d,]+ steps and [\d.e+-]+ (s|min|h) on this machine \(the solve "
                     r"rehearsed to its end: [\d.]+ iterations and [\d.e-]+ tangents a step\)", rehearsed), rehearsed
