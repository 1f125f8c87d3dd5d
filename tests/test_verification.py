"""Verification decks as a regression suite: each deck listed here runs to its end and
every one of its [reference] checks (closed-form or literature values, cited in the deck)
passes. Test 9 (test09_aorta_slow_M2) runs through the command line in test_output.py,
its references checked by the exit code. Decks left out are slower or not yet within their
references (docs/verification.md)."""

from __future__ import annotations

import numpy as np
import pytest

from shellsim.deck import load_deck
from shellsim.geometry import build_mesh
from shellsim.model import build_model
from shellsim.solver.run import integrate, prepare
from shellsim.verify.check import check

from .conftest import ROOT

DECKS = [
    "test01_nafems_21t_4x4.toml",
    "test02_cantilever_uniform_load_3.toml",
    "test03_strip_moment_irregular3_thick.toml",
    "test07_thick_cylinder_2x3_nu049.toml",
    "test07_thick_cylinder_2x3_nu04999.toml",
    "test05_scordelis_lo_6x6.toml",
    "test06_twisted_beam_8_inplane.toml",
    "test06_twisted_beam_8_outofplane.toml",
    "test10_carotid_slow_M2.toml",
]


@pytest.mark.parametrize("name", DECKS)
def test_deck_meets_its_references(name):
    deck = load_deck(ROOT / "decks" / "verification" / name)
    mesh = build_mesh(deck)
    run = integrate(prepare(deck, mesh, build_model(deck, mesh)))
    times = np.asarray(run.times)
    results = [check(ref, times, np.asarray(run.history[ref.probe])) for ref in deck.reference]
    failed = [r for r in results if not r["passed"]]
    assert not failed, failed
