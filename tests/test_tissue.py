"""The tissue scenes of decks/tissue, run as coarse variants: the carotid segment remeshed
from its surface (HGO, helical fibres, pulses from a CSV file) and the Lee-Sacks leaflet
flap under a pressure pulse. Each completes, draws its fibres, and obeys what an elastic
wall must: the same pressure gives the same shape on every cycle, the flap comes back."""

from __future__ import annotations

import meshio
import numpy as np
import pytest
from shellsim.output.fields import is_fibre_direction
from shellsim.study.jobs import variant_deck

from .conftest import ROOT

TISSUE = ROOT / "decks" / "tissue"


def _history(folder) -> dict[str, np.ndarray]:
    names = (folder / "history.csv").read_text().splitlines()[0].split(",")
    values = np.loadtxt(folder / "history.csv", delimiter=",", skiprows=1)
    return dict(zip(names, values.T))


def _run_coarse(deck_name: str, overrides: dict, folder):
    """The deck with ``overrides`` run into ``folder`` (its files read beside it), with its
    renders; returns (``folder``, the run)."""
    from shellsim.output.render import deck_renders
    from shellsim.execute import run_scene

    source = TISSUE / deck_name
    scene = variant_deck(source, overrides)
    run, _ = run_scene(scene, source, folder)
    assert run.status == "completed"
    deck_renders(scene, folder)
    return folder, run


def _has_fibres_and_a_picture(out) -> None:
    reader = meshio.xdmf.TimeSeriesReader(out / "results.xdmf")
    reader.read_points_cells()
    _, _, cell_data = reader.read_data(reader.num_steps - 1)
    fibres = [name for name in cell_data if is_fibre_direction(name)]
    assert fibres
    for name in fibres:  # unit vectors, to the precision they are stored at
        stored = cell_data[name][0]
        np.testing.assert_allclose(np.linalg.norm(stored, axis=1), 1.0, rtol=4 * np.finfo(stored.dtype).eps)
    assert list((out / "renders").glob("pressure_band_iso_fibres_outline_*.png"))


@pytest.fixture(scope="module")
def carotid(tmp_path_factory):
    """Two cycles on quads of about 3 mm (253 elements), frames every 0.08 s."""
    return _run_coarse("carotid_hgo_pulse.toml", {"geometry.element_size": 0.003, "solver.end_time": 1.6,
                                                  "output.interval": 0.08}, tmp_path_factory.mktemp("carotid"))[0]


def test_the_carotid_repeats_its_shape_each_cycle_and_widens_with_the_pressure(carotid):
    """An elastic wall solved as equilibria has one shape per pressure: at the end of each
    cycle (diastole, t = 0.8 and 1.6) the lumen radius and the hoop stress agree to 1e-6;
    the lumen is wider at the systolic peak than at diastole, and wider at diastole than
    unloaded."""
    history = _history(carotid)
    t, radius, hoop = history["time"], history["lumen_radius"], history["hoop_stress"]
    first, second = np.argmin(abs(t - 0.8)), np.argmin(abs(t - 1.6))
    np.testing.assert_allclose(radius[second], radius[first], rtol=1e-6)
    np.testing.assert_allclose(hoop[second], hoop[first], rtol=1e-6)
    systole = np.argmin(abs(t - (0.8 + 0.24)))
    assert radius[systole] > radius[first] > radius[0]
    _has_fibres_and_a_picture(carotid)


def test_the_remeshed_carotid_has_its_named_ends(carotid):
    from shellsim.deck.resolved import read_resolved

    deck = read_resolved(carotid)
    assert deck.geometry.boundaries.keys() == {"inlet", "outlet"}


@pytest.fixture(scope="module")
def leaflet(tmp_path_factory):
    """The flap as shipped (30 elements) up to 0.15 s: (its folder, the run)."""
    return _run_coarse("leaflet_lee_sacks_pulse.toml", {}, tmp_path_factory.mktemp("leaflet"))


def test_the_leaflet_bellies_under_the_pulse_and_comes_back(leaflet):
    """The free edge moves out with the pressure (its largest deflection while the pulse
    is on, beyond a tenth of the flap's height), the fibres along the annulus are
    stretched (tension at the belly), and after the pulse the damped flap returns to within
    a twentieth of its largest deflection."""
    folder, _ = leaflet
    history = _history(folder)
    t, deflection = history["time"], history["free_edge_deflection"]
    peak = int(np.argmax(deflection))
    assert 0.0 < t[peak] < 0.1 and deflection[peak] > 0.001
    assert abs(deflection[-1]) < deflection[peak] / 20
    assert history["belly_stress"][np.argmin(abs(t - 0.05))] > 0.0
    _has_fibres_and_a_picture(folder)


def test_the_crumpling_flaps_step_stays_below_each_next_critical_step(leaflet):
    """The flap's critical step swings by 20 times as it crumples and rebounds; estimated as
    often as it moves (more often than every 100 steps), every step taken is shorter than
    the critical step estimated after it."""
    _, run = leaflet
    record = run.dt_history
    assert max(critical for _, critical, _ in record) > 20 * min(critical for _, critical, _ in record)
    assert len(record) > run.sim.state.steps / 100
    assert all(dt < critical for (_, _, dt), (_, critical, _) in zip(record, record[1:]))
