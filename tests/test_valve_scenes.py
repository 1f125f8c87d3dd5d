"""The valve scenes of decks/valves, run as coarse variants: the aortic valve with
Lee-Sacks leaflets closed by 80 mmHg. It completes, comes to rest shut (its deck's
reference on the orifice passes), its leaflets touch without passing through each other,
its energy balances, its measures are where a closed valve puts them, and its pictures
are drawn."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shellsim.loads import ToolForces
from shellsim.study.jobs import variant_deck

from .conftest import ROOT

VALVES = ROOT / "decks" / "valves"
COARSE = {"mesh.divisions": {"around": 8, "belly": 4, "coaptation": 2}, "solver.implicit.increments": 40}
#: The deck's reference on the orifice, and one on its least value over the run (read from
#: the samples measured: the history between them holds nan).
REFERENCES = [{"quantity": "orifice area", "probe": "orifice_area", "measure": measure, "expected": 0.0,
               "tolerance": 0.05, "source": "closed form: a closed valve leaves no opening"}
              for measure in ("final", "min")]


@pytest.fixture(scope="module")
def closing(tmp_path_factory):
    """(run, folder): the closing valve on 8 x 6 elements a leaflet (144 in all), in
    steps of 2 ms, with its renders."""
    from shellsim.output.render import deck_renders
    from shellsim.execute import run_scene

    source = VALVES / "aortic_valve_closing.toml"
    scene = variant_deck(source, COARSE | {"reference": REFERENCES})
    folder = tmp_path_factory.mktemp("closing")
    run, _ = run_scene(scene, source, folder)
    deck_renders(scene, folder)
    return run, folder


def test_the_valve_closes_at_rest_without_its_leaflets_passing_through_each_other(closing):
    """Shut: the references (orifice area 0 within the deck's tolerance, at the end and
    at its least) pass; every
    node with a neighbour's face in reach keeps its gap above a quarter of the thickness
    below zero (half of what the contact takes for passed through); at rest, the kinetic
    energy under 1% of the internal; the energy balance within 1% of the external work."""
    run, folder = closing
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["status"] == "completed"
    assert [check["passed"] for check in summary["reference"]] == [True, True]
    state, h = run.sim.state, run.deck.section.thickness
    gaps = ToolForces(run.model, []).gaps(state.t, state.fields.shape)
    assert np.nanmin(gaps) > -0.25 * h
    energy = summary["energy"]
    assert energy["kinetic"] < 0.01 * energy["internal"]
    assert abs(energy["balance_error"]) < 0.01 * energy["external_work"]


def test_the_closed_valve_s_measures_are_a_closed_valve_s(closing):
    """The valve's measures in summary.json: the widest opening a lone pixel's (twice its
    distance to a covered one, 2 pixels of the raster's 400 across the annulus); the leaflets coapting over a band at the
    centre (coaptation height between the builder's band, 2 mm, and the valve's height,
    14 mm); and every measure sampled (at 200 evenly spaced times, or at every step of a
    run of fewer). The peak principal stress is at least the
    attachment's mean: the pressure's push on the annulus' inside, p A, reaches the root
    only through the leaflets' tension along the attachment, of length L, so some point
    there carries p A / (L h) or more."""
    run, folder = closing
    valve = json.loads((folder / "summary.json").read_text())["valve"]
    ring = run.model.x0[run.measure("valve").annulus] @ run.measure("valve").frame[:2].T
    pixel = np.ptp(ring, axis=0).max() / 400
    assert valve["regurgitant_gap"]["final"] <= 2 * pixel * (1 + 1e-12)
    assert 2.0 < valve["coaptation_height"]["final"] < 14.0
    assert valve["coaptation_area"]["final"] > 0.0
    area = 0.5 * abs(np.dot(ring[:, 0], np.roll(ring[:, 1], -1)) - np.dot(ring[:, 1], np.roll(ring[:, 0], -1)))
    edges = run.model.x0[run.mesh.sets["attachment"].edges]
    length = np.linalg.norm(np.diff(edges, axis=1), axis=2).sum()
    assert valve["peak_principal_stress"]["final"] > 0.010666 * area / (length * run.deck.section.thickness)
    history = np.genfromtxt(folder / "history.csv", delimiter=",", names=True)
    assert np.count_nonzero(~np.isnan(history["orifice_area"])) >= min(200, len(history))


def test_the_closed_valve_is_drawn_with_its_contact_pressure_and_stress_and_its_measures_plotted(closing):
    """The deck's renders (contact pressure from the side, von Mises iso) and `shellsim
    plot`'s picture of each valve measure against time, drawn from the samples measured."""
    from shellsim.output.plots import plot_run

    run, folder = closing
    renders = {p.name.split("_side")[0].split("_iso")[0] for p in (folder / "renders").glob("*.png")}
    assert {"contact_pressure", "von_mises"} <= renders
    written = {p.name for p in plot_run(folder)}
    assert {f"{column}.png" for column in run.deck.output.valve.COLUMNS} <= written

