"""What a run leaves behind: the XDMF and VTU series read back with meshio and pyvista
(times, shapes, the pressure band against the stored stresses), the sub-cell fields
against a closed-form strain field, the resolved deck, renders and plots of Test 9, and
the files of runs stopped by Ctrl-C or by an instability."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from shellsim.cli import app, sigterm_as_interrupt
from shellsim.deck import load_deck, parse_deck
from shellsim.element.shape import gauss_rule
from shellsim.errors import OutputError, Terminated
from shellsim.output.encoding import Encoding, symmetric_tensors
from shellsim.output.fields import CORNER_RS, SUB_BOUNDS, frame_fields, output_mesh
from shellsim.output.series import check_space
from shellsim.solver.run import Listener, integrate, output_times

from .conftest import CLAMPED_PLATE, ROOT, deck_text, prepared

runner = CliRunner()
ALL_FIELDS = ["displacement", "director", "thickness", "cauchy_stress", "lamina_stress", "pressure_band",
              "green_lagrange_strain", "von_mises"]
PLATE = deck_text(CLAMPED_PLATE[0], CLAMPED_PLATE[1] + f"""curve = "ramp"

[curves.ramp]
t = [0.0, 0.5]
value = [0.0, 1.0]

[output]
times = [0.1, 0.25]
formats = ["xdmf", "vtu"]
precision = "double"
fields = {ALL_FIELDS}

[[output.probe]]
name = "tip"
quantity = "displacement"
set = "x1y0"
component = "z"
""").replace("thickness = 0.01", "thickness = 0.05").replace("end_time = 1.0", "end_time = 0.5")


@pytest.fixture(scope="module")
def plate_run(tmp_path_factory):
    """A clamped plate under a ramped pressure, written as XDMF and VTU at t = 0.1, 0.25
    and the end (0.5)."""
    folder = tmp_path_factory.mktemp("plate")
    (folder / "plate.toml").write_text(PLATE)
    result = runner.invoke(app, ["run", str(folder / "plate.toml"), "--out", str(folder / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    return folder / "out"


def test_xdmf_series_has_one_time_per_frame_and_the_sub_cell_mesh(plate_run):
    reader = meshio.xdmf.TimeSeriesReader(plate_run / "results.xdmf")
    points, cells = reader.read_points_cells()
    frames = [reader.read_data(k) for k in range(reader.num_steps)]
    assert [t for t, _, _ in frames] == pytest.approx([0.0, 0.1, 0.25, 0.5], abs=1e-12)
    ne = 4  # 2 x 2 elements
    assert points.shape == (ne * 16, 3) and cells[0].type == "quad" and cells[0].data.shape == (ne * 9, 4)
    _, point_data, cell_data = frames[-1]
    assert point_data["displacement"].shape == (ne * 16, 3)
    assert point_data["director"].shape == (ne * 16, 3) and point_data["thickness"].shape == (ne * 16,)
    for name in ("cauchy_stress", "lamina_stress", "green_lagrange_strain"):
        assert cell_data[name][0].shape == (ne * 9, 6) and point_data[name + "_nodal"].shape == (ne * 16, 6)
    assert cell_data["pressure_band"][0].shape == (ne * 9,)
    sigma = symmetric_tensors(cell_data["cauchy_stress"][0])
    np.testing.assert_allclose(cell_data["pressure_band"][0], -np.trace(sigma, axis1=1, axis2=2) / 3, rtol=1e-12)
    # bending: the tip has moved, and the frame at t = 0 is the undeformed plate
    assert abs(point_data["displacement"][:, 2]).max() > 1e-3
    assert np.abs(frames[0][1]["displacement"]).max() == 0.0
    # the last frame's tip deflection is the history's last probe reading
    history = np.genfromtxt(plate_run / "history.csv", delimiter=",", names=True)
    tip = np.argmin(np.linalg.norm(points - [2.0, 0.0, 0.0], axis=1))
    assert point_data["displacement"][tip, 2] == pytest.approx(history["tip"][-1], rel=1e-9)


def test_vtu_frames_hold_the_same_arrays_as_the_xdmf_series(plate_run):
    import pyvista

    index = ET.parse(plate_run / "results.pvd").getroot().iter("DataSet")
    entries = [(float(e.get("timestep")), e.get("file")) for e in index]
    assert [t for t, _ in entries] == pytest.approx([0.0, 0.1, 0.25, 0.5], abs=1e-12)
    grid = pyvista.read(plate_run / entries[-1][1])
    reader = meshio.xdmf.TimeSeriesReader(plate_run / "results.xdmf")
    reader.read_points_cells()  # the reader needs the mesh before any frame
    _, point_data, cell_data = reader.read_data(3)
    np.testing.assert_array_equal(grid.point_data["displacement"], point_data["displacement"])
    np.testing.assert_array_equal(grid.cell_data["cauchy_stress"], cell_data["cauchy_stress"][0])
    np.testing.assert_array_equal(grid.cell_data["pressure_band"], cell_data["pressure_band"][0])


def _written_both_ways(folder: Path, encoding: Encoding) -> tuple[Path, dict]:
    """A 2 x 2 grid of quads with a smooth vector and tensor field over two frames, written
    as XDMF and VTU with ``encoding`` into ``folder``; returns the folder and the last
    frame's fields as given."""
    from types import SimpleNamespace

    from shellsim.output.vtu import VtuSeries
    from shellsim.output.xdmf import XdmfSeries

    x, y = np.meshgrid(np.linspace(0.0, 1.0, 3), np.linspace(0.0, 1.0, 3))
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(9)])
    cells = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
    mesh = SimpleNamespace(points=points, cells=cells, cell_type="quad")
    folder.mkdir()
    series = [XdmfSeries(folder, mesh, encoding), VtuSeries(folder, mesh, encoding)]
    for t in (0.0, 0.1):
        fields = ({"displacement": t * np.sin(points + 1.0 / 3.0)},
                  {"cauchy_stress": t * np.cos(np.arange(24.0).reshape(4, 6) / 7.0), "pressure_band": t * np.ones(4)})
        for one in series:
            one.write(t, *fields)
    for one in series:
        one.close()
    return folder, fields


@pytest.mark.parametrize("precision, float_type", [("single", np.float32), ("double", np.float64)])
def test_series_store_their_numbers_at_the_decks_precision_compressed_or_not(tmp_path, precision, float_type):
    """Both formats hold the values rounded to the asked precision, exactly, compressed or
    not; compressed, the HDF5 datasets are gzip'ed and the VTU zlib'ed."""
    import h5py

    for compress in (True, False):
        encoding = Encoding.of(parse_deck(PLATE.replace('precision = "double"', f'precision = "{precision}"\n'
                                                        f'compress = {str(compress).lower()}')).output)
        assert encoding == Encoding(float_type, compress)
        folder, (point_data, cell_data) = _written_both_ways(tmp_path / f"{precision}_{compress}", encoding)
        reader = meshio.xdmf.TimeSeriesReader(folder / "results.xdmf")
        reader.read_points_cells()
        _, xdmf_points, xdmf_cells = reader.read_data(1)
        vtu = meshio.read(folder / "frames" / "results_0001.vtu")
        for read_points, read_cells in ((xdmf_points, xdmf_cells), (vtu.point_data, vtu.cell_data)):
            assert read_points["displacement"].dtype == float_type
            np.testing.assert_array_equal(read_points["displacement"], point_data["displacement"].astype(float_type))
            np.testing.assert_array_equal(read_cells["cauchy_stress"][0], cell_data["cauchy_stress"].astype(float_type))
        with h5py.File(folder / "results.h5") as stored:
            assert stored["frames/1/displacement"].compression == ("gzip" if compress else None)
        assert (b"vtkZLibDataCompressor" in (folder / "frames" / "results_0001.vtu").read_bytes()) == compress


def test_each_xdmf_frame_names_its_own_mesh_and_tensors_have_six_components(tmp_path):
    """No mesh grid beside the frames (ParaView's legacy XDMF reader showed one as an
    undeformed copy): the domain holds only the temporal collection, each frame points at
    the one stored topology and geometry, and a symmetric tensor is a six-column Matrix,
    whose components every ParaView reader names XX, YY, ZZ, XY, YZ, XZ."""
    folder, _ = _written_both_ways(tmp_path / "out", Encoding())
    (collection,) = ET.parse(folder / "results.xdmf").getroot().find("Domain")
    assert collection.get("CollectionType") == "Temporal"
    for frame in collection:
        assert frame.find("Topology/DataItem").text == "results.h5:/mesh/cells"
        assert frame.find("Geometry/DataItem").text == "results.h5:/mesh/points"
        stress = frame.find("Attribute[@Name='cauchy_stress']")
        assert stress.get("AttributeType") == "Matrix" and stress.find("DataItem").get("Dimensions") == "4 6"
    assert [float(frame.find("Time").get("Value")) for frame in collection] == [0.0, 0.1]


def test_a_symmetric_tensor_is_written_in_paraviews_order_and_rebuilt():
    """Six components in VTK's order (xx, yy, zz, xy, yz, xz: the names ParaView gives a
    six-component array), and back to the same tensor."""
    from shellsim.output.encoding import symmetric_columns

    tensor = np.array([[1.0, 4.0, 6.0], [4.0, 2.0, 5.0], [6.0, 5.0, 3.0]])
    np.testing.assert_array_equal(symmetric_columns(tensor), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    np.testing.assert_array_equal(symmetric_tensors(symmetric_columns(np.stack([tensor, 2 * tensor]))),
                                  np.stack([tensor, 2 * tensor]))


PARAVIEW_SCRIPT = """
import json, sys
from paraview.simple import PVDReader, XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT
folder = sys.argv[1]
seen = {}
for name, reader in (("XDMF Reader", lambda: XDMFReader(FileNames=[folder + "/results.xdmf"])),
                     ("Xdmf3ReaderS", lambda: Xdmf3ReaderS(FileName=[folder + "/results.xdmf"])),
                     ("Xdmf3ReaderT", lambda: Xdmf3ReaderT(FileName=[folder + "/results.xdmf"])),
                     ("PVD", lambda: PVDReader(FileName=folder + "/results.pvd"))):
    source = reader()
    times = list(source.TimestepValues)
    frames = []
    for t in times:
        source.UpdatePipeline(t)
        info = source.GetDataInformation()
        arrays = {a.Name: [a.GetComponentName(c) for c in range(a.GetNumberOfComponents())]
                  for arrays in (source.PointData, source.CellData) for a in arrays.values()}
        frames.append({"points": info.GetNumberOfPoints(), "cells": info.GetNumberOfCells(), "arrays": arrays,
                       "largest_displacement": source.PointData["displacement"].GetRange(-1)[1]})
    seen[name] = {"times": times, "frames": frames}
print(json.dumps(seen))
"""


@pytest.mark.skipif(shutil.which("pvpython") is None, reason="ParaView's pvpython is not installed")
def test_paraview_reads_every_frame_at_its_time_with_every_field_named(plate_run):
    """ParaView's XDMF readers (legacy and both Xdmf3) and its PVD reader show each frame at
    its time, on the mesh alone (no second, undeformed copy), moving, with every field and
    a tensor's components named."""
    result = subprocess.run(["pvpython", "-c", PARAVIEW_SCRIPT, str(plate_run)], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr
    seen = json.loads(result.stdout.strip().splitlines()[-1])
    assert len(seen) == 4
    ne = 4
    for reader, found in seen.items():
        assert found["times"] == pytest.approx([0.0, 0.1, 0.25, 0.5], abs=1e-12), reader
        moved = [frame["largest_displacement"] for frame in found["frames"]]
        assert moved[0] == 0.0 and moved[1] < moved[2] < moved[3], reader
        for frame in found["frames"]:
            assert (frame["points"], frame["cells"]) == (ne * 16, ne * 9), reader
            assert set(frame["arrays"]) == {"displacement", "director", "thickness", *(
                f"{name}{nodal}" for name in ALL_FIELDS[3:] for nodal in ("", "_nodal"))}, reader
            assert frame["arrays"]["cauchy_stress"] == ["XX", "YY", "ZZ", "XY", "YZ", "XZ"], reader


def test_resolved_deck_loads_back_to_the_same_scene_with_the_version(plate_run):
    from shellsim import __version__

    text = (plate_run / "deck.toml").read_text()
    assert f"shellsim {__version__}" in text.splitlines()[0]
    original = parse_deck(PLATE)
    assert parse_deck(text) == original
    assert "dt_safety_factor" in text and "points_through_thickness" in text  # defaults written out


def test_summary_records_frames_and_output_time(plate_run):
    summary = json.loads((plate_run / "summary.json").read_text())
    assert summary["frames"] == 4
    assert 0.0 < summary["output_wall_time_s"] < summary["wall_time_s"]


def _plate_simulation(displacement, director=None):
    """A 2 x 2 flat plate with its mid-surface moved by ``displacement(x0)`` (n, 3) and
    its directors set to ``director(x0)`` (n, 3) if given."""
    deck = parse_deck(PLATE)
    run = prepared(deck)
    run.sim.state.x[:] = run.model.x0 + displacement(run.model.x0)
    if director is not None:
        d = director(run.model.x0)
        run.sim.state.d[:] = d / np.linalg.norm(d, axis=1, keepdims=True)
    return run


def test_sub_cells_carry_their_gauss_points_values_and_the_nodal_version_is_exact_for_quadratics():
    """u_x = a x^2 gives E_xx = 2 a x + 2 a^2 x^2 (quadratic in x), exactly represented by
    the 9-node element on a regular mesh: every sub-cell holds the value at the Gauss point
    inside it, and the smoothed nodal version equals the closed form at every corner,
    clipped to the Gauss values' range: beyond the outermost Gauss points, at the plate's
    ends, the closed form leaves it."""
    a = 0.05
    run = _plate_simulation(lambda x0: np.column_stack([a * x0[:, 0] ** 2, 0 * x0[:, 0], 0 * x0[:, 0]]))
    mesh = output_mesh(run.model)
    point_data, cell_data = frame_fields(run.sim, mesh, ["green_lagrange_strain"])
    exx = lambda x: 2 * a * x + 2 * a ** 2 * x ** 2  # noqa: E731
    corners = mesh.points[mesh.cells]  # (C, 4, 3)
    gauss_x = np.einsum("qa,ea->eq", run.model.rule.N[:9], run.model.x0[run.model.conn][:, :, 0]).reshape(-1)
    inside = (corners[:, :, 0].min(axis=1) < gauss_x) & (gauss_x < corners[:, :, 0].max(axis=1))
    assert inside.all()
    np.testing.assert_allclose(cell_data["green_lagrange_strain"][:, 0], exx(gauss_x), rtol=1e-10)
    gauss_range = cell_data["green_lagrange_strain"][:, 0].min(), cell_data["green_lagrange_strain"][:, 0].max()
    closed_form = exx(mesh.points[:, 0])
    assert (closed_form < gauss_range[0]).any() and (closed_form > gauss_range[1]).any()  # the ends clip
    np.testing.assert_allclose(point_data["green_lagrange_strain_nodal"][:, 0], np.clip(closed_form, *gauss_range),
                               rtol=1e-9, atol=1e-11 * exx(2.0))
    assert np.abs(cell_data["green_lagrange_strain"][:, [1, 2]]).max() < 1e-14  # nothing along y or z


def test_no_smoothed_field_leaves_the_range_of_its_integration_point_values():
    """A stretch that starts halfway along the left elements (u_x = a max(x - 1/2, 0)^2, a
    kink no biquadratic follows) makes the extrapolated nodal values undershoot: every
    ``_nodal`` field, the principal stresses' too, stays within its cell values' range,
    each component's, and the von Mises stress's never falls below zero."""
    a = 0.05
    run = _plate_simulation(lambda x0: np.column_stack(
        [a * np.maximum(x0[:, 0] - 0.5, 0.0) ** 2, 0 * x0[:, 0], 0 * x0[:, 0]]))
    point_data, cell_data = frame_fields(run.sim, output_mesh(run.model), [
        "cauchy_stress", "pressure_band", "green_lagrange_strain", "von_mises", "principal_stress"])
    smoothed = [name for name in point_data if name.endswith("_nodal")]
    assert {"von_mises_nodal", "principal_stress_1_nodal", "principal_stress_3_nodal"} <= set(smoothed)
    for name in smoothed:
        cells, nodal = cell_data[name.removesuffix("_nodal")], point_data[name]
        assert (nodal >= cells.min(axis=0)).all() and (nodal <= cells.max(axis=0)).all(), name
    assert point_data["von_mises_nodal"].min() == cell_data["von_mises"].min() >= 0.0  # clipped at the kink


def test_von_mises_is_per_layer_in_the_solid_view_and_its_largest_in_the_shell_view():
    """Plate bent to w = 0.001 x^2, directors normal to it: each solid sub-cell's von Mises is sqrt(3/2 s:s) of its own Cauchy
    stress; the shell view shows the largest over the layers (the faces), its Cauchy stress
    the thickness mean."""
    zero = lambda x0: 0 * x0[:, 0]  # noqa: E731
    run = _plate_simulation(lambda x0: np.column_stack([zero(x0), zero(x0), 0.001 * x0[:, 0] ** 2]),
                            lambda x0: np.column_stack([-0.002 * x0[:, 0], zero(x0), 1 + zero(x0)]))
    run.sim.evaluate_forces()
    nt = len(run.model.rule.tz)
    _, solid = frame_fields(run.sim, output_mesh(run.model, solid=True), ["cauchy_stress", "von_mises"])
    _, shell = frame_fields(run.sim, output_mesh(run.model), ["cauchy_stress", "von_mises"])
    sigma = symmetric_tensors(solid["cauchy_stress"])
    deviator = sigma - np.trace(sigma, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    np.testing.assert_allclose(solid["von_mises"], np.sqrt(1.5 * (deviator ** 2).sum(axis=(1, 2))), rtol=1e-12)
    by_layer = solid["von_mises"].reshape(run.model.n_elements, nt, 9)
    np.testing.assert_array_equal(shell["von_mises"], by_layer.max(axis=1).ravel())
    weights = run.model.rule.wt / run.model.rule.wt.sum()
    mean = np.einsum("k,ekqc->eqc", weights, solid["cauchy_stress"].reshape(run.model.n_elements, nt, 9, 6))
    np.testing.assert_allclose(shell["cauchy_stress"], mean.reshape(-1, 6), rtol=1e-12, atol=1e-15)
    assert (by_layer.max(axis=1) > 1.2 * by_layer.min(axis=1)).any()  # the faces differ: the choice matters


def test_solid_view_puts_the_faces_half_a_fibre_from_the_mid_surface():
    run = _plate_simulation(lambda x0: np.zeros_like(x0))
    solid = output_mesh(run.model, solid=True)
    nt = len(run.model.rule.tz)
    assert solid.cells.shape == (run.model.n_elements * 9 * nt, 8)
    assert solid.points.shape == (run.model.n_elements * (nt + 1) * 16, 3)
    z = solid.points[:, 2].reshape(run.model.n_elements, nt + 1, 16)
    np.testing.assert_allclose(z[:, 0], -0.025)
    np.testing.assert_allclose(z[:, -1], 0.025)
    assert len(SUB_BOUNDS) == 4 and CORNER_RS.shape == (16, 2)
    volumes = [box_volume(solid.points[c]) for c in solid.cells]
    assert sum(volumes) == pytest.approx(2.0 * 1.0 * 0.05, rel=1e-12)


def box_volume(corners: np.ndarray) -> float:
    """Volume of an axis-aligned box given by its 8 corners (8, 3)."""
    return float(np.prod(np.ptp(corners, axis=0)))


def test_a_solid_series_is_written_and_rendered(tmp_path):
    """output.solid: hexahedra between the faces in the series, a cell per integration
    point, and a render of them."""
    deck = tmp_path / "solid.toml"
    deck.write_text(PLATE.replace('formats = ["xdmf", "vtu"]', 'formats = ["xdmf"]\nsolid = true'))
    result = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    reader = meshio.xdmf.TimeSeriesReader(tmp_path / "out" / "results.xdmf")
    points, cells = reader.read_points_cells()
    nt = load_deck(deck).section.points_through_thickness
    assert cells[0].type == "hexahedron" and cells[0].data.shape == (4 * 9 * nt, 8)
    assert points.shape == (4 * (nt + 1) * 16, 3)
    _, point_data, cell_data = reader.read_data(reader.num_steps - 1)
    assert cell_data["von_mises"][0].shape == (4 * 9 * nt,) and "von_mises_nodal" not in point_data
    result = runner.invoke(app, ["render", str(tmp_path / "out"), "--field", "von_mises", "--size", "400x300"])
    assert result.exit_code == 0, result.output
    (png,) = (tmp_path / "out" / "renders").glob("von_mises_iso_*.png")
    size, contrast = _picture_contrast(png)
    assert size == (400, 300) and contrast > 20.0


def test_not_enough_disk_space_is_reported_before_the_run(tmp_path):
    with pytest.raises(OutputError, match=r"the run's frames need about 1,000,000,000 GB but '.*' has [\d.,]+ [kMG]?B "
                                          r"free \(the disk is full or nearly\)"):
        check_space(tmp_path, 10 ** 18)


# --- Test 9: renders and plots of a finished run ---------------------------------------

TEST9 = ROOT / "decks" / "verification" / "test09_aorta_slow_M2.toml"


@pytest.fixture(scope="module")
def test9_run(tmp_path_factory):
    """Test 9 through the command line: exit code 0 means every reference passed."""
    folder = tmp_path_factory.mktemp("test9")
    result = runner.invoke(app, ["run", str(TEST9), "--out", str(folder), "--quiet"])
    assert result.exit_code == 0, result.output
    return folder


def test_test9_series_has_a_frame_at_each_output_time(test9_run):
    reader = meshio.xdmf.TimeSeriesReader(test9_run / "results.xdmf")
    reader.read_points_cells()
    times = [reader.read_data(k)[0] for k in range(reader.num_steps)]
    assert times == pytest.approx([0.0, *output_times(load_deck(TEST9))], abs=1e-12)


def _picture_contrast(path: Path) -> tuple[tuple[int, int], float]:
    import imageio.v3 as iio

    image = iio.imread(path)[..., :3].astype(float)
    return (image.shape[1], image.shape[0]), float(image.std())


def test_render_of_test9_writes_a_picture_of_the_requested_size_that_is_not_blank(test9_run):
    result = runner.invoke(app, ["render", str(test9_run), "--size", "640x480", "--view", "iso"])
    assert result.exit_code == 0, result.output
    (png,) = (test9_run / "renders").glob("pressure_band_iso_*.png")
    size, contrast = _picture_contrast(png)
    assert size == (640, 480)
    assert contrast > 20.0  # a white background alone has none


def test_render_of_every_frame_also_makes_an_animated_gif(test9_run, tmp_path):
    import imageio.v3 as iio

    result = runner.invoke(app, ["render", str(test9_run), "--frame", "all", "--field", "von_mises_nodal",
                                 "--size", "320x240", "--out", str(tmp_path)])
    assert result.exit_code == 2 and "von_mises_nodal" in result.output  # not written by this deck
    result = runner.invoke(app, ["render", str(test9_run), "--frame", "all", "--field", "displacement",
                                 "--component", "x", "--size", "320x240", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    frames = len(list(tmp_path.glob("displacement_x_iso_*.png")))
    assert frames == len(output_times(load_deck(TEST9))) + 1
    assert iio.imread(tmp_path / "displacement_x_iso.gif").shape[0] == frames


def test_deck_renders_are_written_at_the_end_of_the_run(test9_run):
    assert (test9_run / "renders").is_dir()
    requested = load_deck(TEST9).output.render
    assert requested and all(list((test9_run / "renders").glob(f"{r.field}_{r.view}_*.png")) for r in requested)


def test_plot_draws_each_probe_with_its_references_and_the_energies(test9_run):
    result = runner.invoke(app, ["plot", str(test9_run)])
    assert result.exit_code == 0, result.output
    deck = load_deck(TEST9)
    for name in [p.name for p in deck.output.probe] + ["energy"]:
        size, contrast = _picture_contrast(test9_run / "plots" / f"{name}.png")
        assert contrast > 10.0


# --- runs that stop early ---------------------------------------------------------------

def _wait_for_frames(path: Path, count: int, process: subprocess.Popen, limit: float = 600.0) -> None:
    start = time.monotonic()
    while time.monotonic() - start < limit:
        assert process.poll() is None, process.communicate()
        if path.exists():
            try:
                if meshio.xdmf.TimeSeriesReader(path).num_steps >= count:
                    return
            except Exception:  # noqa: BLE001 - the file is replaced atomically; retry until it has frames
                pass
        time.sleep(0.2)
    raise AssertionError(f"no {count} frames in {path} after {limit} s")


@pytest.mark.parametrize(("stop", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["ctrl-c", "sigterm"])
def test_a_stopped_run_leaves_a_readable_series_and_a_summary_marked_interrupted(tmp_path, stop, code,
                                                                                ctrl_c_delivered):
    deck = tmp_path / "long.toml"
    # a dead load: under the follower pressure this cantilever flutters and folds by t = 9,
    # which a loaded machine can reach before the signal lands
    deck.write_text(PLATE.replace("end_time = 0.5", "end_time = 500.0")
                    .replace("times = [0.1, 0.25]", "interval = 0.5")
                    .replace('curve = "ramp"', 'curve = "ramp"\nfollower = false'))
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "shellsim", "run", str(deck), "--out", str(out), "--quiet"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=ctrl_c_delivered)
    _wait_for_frames(out / "results.xdmf", 3, process)
    process.send_signal(stop)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == code, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert summary["message"] == ("terminated by SIGTERM" if stop == signal.SIGTERM else "interrupted by the user")
    reader = meshio.xdmf.TimeSeriesReader(out / "results.xdmf")
    reader.read_points_cells()
    times = [reader.read_data(k)[0] for k in range(reader.num_steps)]
    assert len(times) == summary["frames"] >= 3
    assert times == pytest.approx(0.5 * np.arange(len(times)))
    assert len(list((out / "frames").glob("*.vtu"))) == len(times)


class _StoppedMidFrame(Listener):
    """Writes each frame in two parts and has the signal ``stop`` land between them at the
    second frame."""

    def __init__(self, stop):
        self.stop = stop
        self.parts = []

    def on_frame(self, run):
        self.parts.append("first")
        if len(self.parts) == 3:
            os.kill(os.getpid(), self.stop)
        self.parts.append("second")


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_a_stop_during_a_frame_lands_after_the_whole_frame_is_written_and_counted(stop, ctrl_c_delivered):
    run = prepared(parse_deck(PLATE))
    listener = _StoppedMidFrame(stop)
    with pytest.raises(KeyboardInterrupt), sigterm_as_interrupt([]):
        integrate(run, listener)
    assert run.status == "interrupted"
    assert listener.parts == ["first", "second"] * 2
    assert len(run.frame_times) == 2


class _StopSwallowedByACompiledCall(Listener):
    """At the second sample the signal ``stop`` lands, and its KeyboardInterrupt turns into
    another error, as when it lands while numba converts a compiled call's arguments."""

    def __init__(self, stop):
        self.stop = stop
        self.samples = 0

    def on_sample(self, run):
        self.samples += 1
        if self.samples == 2:
            try:
                os.kill(os.getpid(), self.stop)
            except KeyboardInterrupt:
                raise TypeError("can't unbox a <class 'numba.typed.typedlist.List'> as a <NULL>") from None


@pytest.mark.parametrize(("stop", "stopped"), [(signal.SIGINT, KeyboardInterrupt), (signal.SIGTERM, Terminated)],
                         ids=["ctrl-c", "sigterm"])
def test_a_stop_that_a_compiled_call_turns_into_another_error_still_stops_the_run(stop, stopped, ctrl_c_delivered):
    run = prepared(parse_deck(PLATE))
    with pytest.raises(stopped), sigterm_as_interrupt([]):
        integrate(run, _StopSwallowedByACompiledCall(stop))
    assert run.status == "interrupted"


def test_an_error_without_a_stop_stays_that_error(ctrl_c_delivered):
    class Failing(Listener):
        def on_sample(self, run):
            raise TypeError("a fault of the code")

    run = prepared(parse_deck(PLATE))
    with pytest.raises(TypeError, match="a fault of the code"):
        integrate(run, Failing())
    assert run.status == "running"


@pytest.mark.parametrize("tolerance", ["tolerance = 1e-3", "tolerance_percent = 5.0"])
@pytest.mark.parametrize("measure", ['measure = "at_time"\ntime = 0.4', 'measure = "first_peak_time"',
                                     'measure = "final"'])
def test_an_unstable_run_prints_its_reference_table_and_why(tmp_path, tolerance, measure):
    """Every shape of reference entry prints: absolute and relative tolerances, a measure
    taken and one the broken history cannot give."""
    deck = tmp_path / "unstable.toml"
    deck.write_text(PLATE.replace("end_time = 0.5", "end_time = 0.5\ndt_safety_factor = 0.5")
                    + f'\n[[reference]]\nquantity = "tip"\nprobe = "tip"\n{measure}\n'
                      f'expected = 0.05\n{tolerance}\nsource = "none; the run breaks down"\n')
    result = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out")])
    assert result.exit_code == 3, result.output
    assert "unstable" in result.output and "dt_safety_factor" in result.output
    assert "tip" in result.output and "0.05" in result.output
    assert "energies [" in result.output  # the message's brackets are text, not markup


def test_an_unstable_run_keeps_its_frames_and_says_why(tmp_path):
    deck = tmp_path / "unstable.toml"
    deck.write_text(PLATE.replace("end_time = 0.5", "end_time = 0.5\ndt_safety_factor = 0.5")
                    .replace("times = [0.1, 0.25]", "interval = 0.01"))
    result = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 3
    assert "dt_safety_factor" in result.output
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "unstable"
    reader = meshio.xdmf.TimeSeriesReader(tmp_path / "out" / "results.xdmf")
    assert reader.num_steps == summary["frames"] >= 1


def test_a_radial_probe_on_its_axis_is_refused_with_a_message():
    from shellsim.errors import MeshError

    deck = parse_deck(PLATE + '\n[[output.probe]]\nname = "r"\nquantity = "displacement"\nset = "x0y0"\n'
                              'component = "radial"\n')
    with pytest.raises(MeshError, match=r"probe 'r': set 'x0y0' has a point on the probe's axis"):
        prepared(deck)


# --- The whole model and its fibres: Test 9 (static) mirrored, helical fibres ----------


@pytest.fixture(scope="module")
def mirrored_run(tmp_path_factory):
    """Test 9 solved statically, its axes turned by -30 degrees at the inner face to +30 at
    the outer, written whole (mirrored across its three symmetry planes) with the fibres,
    and rendered with them and the initial outline."""
    text = (ROOT / "decks" / "verification" / "test09_aorta_static.toml").read_text()
    text = text.replace('axes = { kind = "cylindrical", axis = [0.0, 0.0, 1.0] }',
                        'axes = { kind = "cylindrical", axis = [0.0, 0.0, 1.0], angle_deg = [-30.0, 30.0] }')
    assert "angle_deg" in text
    text = text.replace("[output]\n", '[output]\nmirror = ["sym_x", "sym_y", "z0"]\nformats = ["xdmf", "vtu"]\n'
                        'solid = true\nprecision = "double"\n'
                        'fields = ["displacement", "cauchy_stress", "pressure_band", "fibres"]\n', 1)
    text += '\n[[output.render]]\nfield = "cauchy_stress"\nfibres = true\noutline = true\nsize = [640, 480]\n'

    deck = tmp_path_factory.mktemp("mirrored") / "deck.toml"
    deck.write_text(text)
    folder = deck.parent / "out"
    result = runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"])
    assert result.exit_code == 0, result.output
    return folder, load_deck(deck)


def test_a_mirrored_series_is_the_whole_tube_and_its_fibres_turn_through_the_wall(mirrored_run):
    """The quarter tube with its end cap is written as eight copies: its points fill all
    eight octants, the deformed shape stays symmetric (a point and its mirror image move
    as mirror images), and the fibres are unit vectors at +-30 degrees from the hoop
    direction on the outermost and innermost layers at t = 0."""
    from shellsim.output.series import StoredSeries

    folder, deck = mirrored_run
    series = StoredSeries(folder)
    points = series.points
    assert len(points) % 8 == 0
    part = len(points) // 8
    assert {tuple(np.sign(p)) for p in points[::97] if np.all(np.abs(p) > 1e-6)} == {
        (sx, sy, sz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)}
    point_data, cell_data = series.frame(len(series.times) - 1)
    u = point_data["displacement"]
    np.testing.assert_allclose(u[part:2 * part], u[:part] * [-1, 1, 1], atol=1e-12 * np.abs(u).max())  # across x = 0
    _, first = series.frame(0)
    fibre = first["fibre_1"]
    np.testing.assert_allclose(np.linalg.norm(fibre, axis=1), 1.0, rtol=1e-12)
    cells = len(series.cells) // 8
    depths = gauss_rule(deck.section.points_through_thickness)[0]
    part_fibres = fibre[:cells].reshape(-1, len(depths), 9, 3)  # (element, layer, point): the solid view
    centres = points[series.cells[:cells]].mean(axis=1).reshape(-1, len(depths), 9, 3)
    on_wall = centres[..., 2] < 0.039  # the cylinder, not the cap
    hoop = np.stack([-centres[..., 1], centres[..., 0], np.zeros_like(centres[..., 0])], axis=-1)
    hoop /= np.linalg.norm(hoop, axis=-1, keepdims=True)
    turned = np.degrees(np.arctan2(part_fibres[..., 2], np.einsum("elqi,elqi->elq", part_fibres, hoop)))
    for k, depth in enumerate(depths):  # -30 degrees at the inner face, +30 at the outer, linear between
        np.testing.assert_allclose(turned[:, k][on_wall[:, k]], 30.0 * depth, atol=0.1)


def test_the_deck_render_draws_the_fibres_and_the_outline(mirrored_run):
    folder, _ = mirrored_run
    (png,) = (folder / "renders").glob("cauchy_stress_xx_iso_fibres_outline_*.png")
    size, contrast = _picture_contrast(png)
    assert size == (640, 480) and contrast > 20.0


def test_mirror_needs_a_symmetry_plane_and_fibres_a_fibre_law():
    from shellsim.errors import DeckError

    plate = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0')
    with pytest.raises(DeckError, match="no symmetry boundary to mirror across"):
        parse_deck(plate + "\n[output]\nmirror = true\n")
    with pytest.raises(DeckError, match="'fibres' is of a fibre-reinforced law's fibres"):
        parse_deck(plate + '\n[output]\nfields = ["displacement", "fibres"]\n')


def test_mirror_names_its_planes_and_reflects_across_those_alone():
    """A symmetry boundary may hold a vessel's cut end in its plane: ``mirror = true`` is
    refused with the symmetry sets to choose from, a set that is no symmetry boundary's is
    named, planes that do not meet at right angles are refused, and the copies are made
    across the named planes only (two of Test 9's three: four copies)."""
    from shellsim.errors import DeckError
    from shellsim.output.mirror import mirror_planes, mirrors

    text = (ROOT / "decks" / "verification" / "test09_aorta_static.toml").read_text()
    with pytest.raises(DeckError, match=r'mirror = true: name the symmetry boundaries .* as mirror = '
                                        r'\["sym_x", "sym_y", "z0"\] or fewer'):
        parse_deck(text.replace("[output]\n", "[output]\nmirror = true\n", 1))
    with pytest.raises(DeckError, match="'ends' is not the set of a symmetry boundary; they are 'sym_x', 'sym_y', "
                                        "'z0'"):
        parse_deck(text.replace("[output]\n", '[output]\nmirror = ["sym_x", "ends"]\n', 1))
    # planes that do not meet at right angles would give overlapping copies
    slanted = text.replace("normal = [1.0, 0.0, 0.0]", "normal = [0.866, 0.5, 0.0]", 1)
    with pytest.raises(DeckError, match="the planes of 'sym_x' and 'sym_y' meet at 60 degrees; the model is mirrored "
                                        "across planes at right angles only"):
        parse_deck(slanted.replace("[output]\n", '[output]\nmirror = ["sym_x", "sym_y"]\n', 1))
    run = prepared(parse_deck(text.replace("[output]\n", '[output]\nmirror = ["sym_x", "z0"]\n', 1)))
    planes = mirror_planes(run.deck, run.mesh)
    normals = np.array([normal for normal, _ in planes])
    np.testing.assert_allclose(np.abs(normals), [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert mirrors(planes).count == 4


def test_display_units_convert_what_renders_and_plots_show():
    """Lengths, stresses, pressures, areas and times in the units asked, from any unit
    system; a pressure follows the stresses' unit unless given its own; a field's nodal
    version is shown as the field."""
    from shellsim.output.units import DisplayUnits

    units = DisplayUnits("SI", {"length": "mm", "stress": "kPa", "pressure": "mmHg"})
    assert units.scale("displacement") == 1e3 and units.label("r", "position") == "r (mm)"
    assert units.scale("hoop_stress") == 1e-3 and units.label("s", "cauchy_stress_nodal") == "s (kPa)"
    assert units.scale("pressure") == pytest.approx(1.0 / 133.322387415, rel=1e-15)
    assert units.scale("area") == pytest.approx(1e6, rel=1e-15) and units.label("A", "area") == "A (mm^2)"
    assert units.scale("volume") == pytest.approx(1e9, rel=1e-15) and units.label("V", "volume") == "V (mm^3)"
    assert units.scale("time") == 1.0 and units.label("t", "time") == "t (s)"
    assert DisplayUnits("mm-kg-ms", {"stress": "kPa", "time": "s"}).scale("pressure") == pytest.approx(1e6)
    assert DisplayUnits("mm-kg-ms", {"time": "s"}).scale("time") == pytest.approx(1e-3)
    assert DisplayUnits().label("t", "time") == "t" and DisplayUnits().scale("stress") == 1.0
    plate = PLATE.replace('precision = "double"', 'display_units = { stress = "bar" }')
    with pytest.raises(Exception, match="display_units.stress = 'bar' is not a unit of stress; expected one of Pa"):
        parse_deck(plate)
    with pytest.raises(Exception, match="meta.units = 'consistent' names no units to convert from"):
        parse_deck(PLATE.replace('precision = "double"', 'display_units = { stress = "kPa" }')
                   .replace('title = "test scene"', 'title = "test scene"\nunits = "consistent"'))


def test_the_carotid_plots_against_its_whole_lumen_pressure_in_mmhg():
    """The carotid's diastolic ramp and its pulse above it are one lumen pressure on the
    plots' load axis, shown in mmHg: 80 mmHg at 0.08 s with the pulse file's value then,
    and the pulse's peak above 80 mmHg at the most."""
    from shellsim.output.plots import _load_axis
    from shellsim.output.units import DisplayUnits

    deck = load_deck(ROOT / "decks" / "tissue" / "carotid_hgo_pulse.toml")
    t = np.linspace(0.0, 2.4, 241)
    pressure, label = _load_axis(deck, t, DisplayUnits.of(deck))
    assert label == "pressure on the bottom face (mmHg)"  # the lumen's: 'all' of the wall goes unsaid
    pascals = 10.666e3 * deck.curves["diastole"](t) + deck.curves["pulse"](t)  # the pulse curve is in Pa
    np.testing.assert_allclose(pressure, pascals / 133.322387415, rtol=1e-12)
    csv = np.loadtxt(ROOT / "decks" / "tissue" / "carotid_pulse.csv", delimiter=",", skiprows=2)
    # the deck's own mmHg: 10.666e3 Pa for 80 and value_scale 133.322 for the file's
    assert pressure[8] == pytest.approx((10.666e3 + 133.322 * np.interp(0.08, *csv.T)) / 133.322387415, rel=1e-9)
    assert pressure.max() == pytest.approx(80.0 + csv[:, 1].max(), rel=2e-3)


def test_a_static_vtu_series_has_its_times_and_renders_and_its_summary_is_strict_json(tmp_path):
    """A static run written as VTU only: results.pvd gives every frame its load time as a
    plain number (ParaView read 'np.float64(0.1)' as 0 and showed only the first frame),
    ``shellsim render`` reads the series back, and summary.json parses as strict JSON
    (no NaN for the energies a static run has no balance of)."""
    import json
    import xml.etree.ElementTree as ET

    deck = tmp_path / "static.toml"
    deck.write_text(PLATE.replace('formats = ["xdmf", "vtu"]', 'formats = ["vtu"]')
                    .replace("end_time = 0.5", 'method = "static"\nend_time = 0.5'))
    result = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    steps = [item.get("timestep") for item in ET.parse(tmp_path / "out" / "results.pvd").getroot().iter("DataSet")]
    times = [float(step) for step in steps]
    assert times == sorted(times) and len(set(times)) == len(times) >= 3 and times[-1] == 0.5
    rendered = runner.invoke(app, ["render", str(tmp_path / "out"), "--size", "320x240"])
    assert rendered.exit_code == 0, rendered.output

    def refuse(constant):
        raise ValueError(f"not strict JSON: {constant}")

    json.loads((tmp_path / "out" / "summary.json").read_text(), parse_constant=refuse)


def test_a_run_cut_short_judges_only_the_values_it_reached(tmp_path):
    """The plate stopped at its frame at t = 0.25 (as Ctrl-C stops it) with two references
    it meets there: the tip's value at t = 0.1, reached, is judged; its largest value over
    the run is not (passed None, with a note), since the run did not see the rest; the
    plot draws the one judged and not the other at the run's last time as if it were met."""
    from shellsim.execute import run_scene

    class StopAtSecondFrame(Listener):
        def on_frame(self, run) -> None:
            if run.sim.state.t >= 0.25:
                raise KeyboardInterrupt

    references = ''.join(f'\n[[reference]]\nquantity = "tip {name}"\nprobe = "tip"\n{measure}\nexpected = 1.0\n'
                         f'tolerance = 1e9\nsource = "any value passes"\n'
                         for name, measure in (("early", 'measure = "at_time"\ntime = 0.1'), ("largest", 'measure = "max"')))
    deck_path = tmp_path / "plate.toml"
    deck_path.write_text(PLATE + references)
    run, summary = run_scene(load_deck(deck_path), deck_path, tmp_path, StopAtSecondFrame())
    assert run.status == "interrupted"
    early, largest = summary["reference"]
    assert early["passed"] and early["computed"] is not None
    assert largest["passed"] is None and largest["computed"] is None
    assert largest["note"].startswith("not judged: the run ended interrupted at t = 0.25, and its max is of the whole run")
    from matplotlib.figure import Figure

    from shellsim.output.plots import _draw_references

    for whole, drawn in ((True, ["at time", "max"]), (False, ["at time"])):
        ax = Figure().subplots()
        times = np.asarray(run.times)
        _draw_references(ax, run.deck, "tip", times, times, 1.0, 1.0, whole)
        assert sorted(label.split("(")[1].split(")")[0] for label in ax.get_legend_handles_labels()[1]) == drawn


def test_values_beyond_single_precision_are_written_as_infinities_without_a_warning():
    """The last frame of a run that blew up holds values past float32's range: they are
    stored as +-inf, and nothing is printed over the run's own error message."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stored = Encoding(np.float32).floats(np.array([1e300, -1e300, 1.5]))
    np.testing.assert_array_equal(stored, np.array([np.inf, -np.inf, 1.5], dtype=np.float32))


def test_the_colour_bar_spans_the_finite_values_and_an_infinite_one_is_drawn_as_missing():
    """A crushed element's infinite stress (a run that broke down) and a gap beyond the
    search (NaN) are left out of the bar, which spans the other values over every frame
    drawn; a flat field gets a scale around its value."""
    from shellsim.output.render import _finite_or_missing, colour_limits

    frames = [_finite_or_missing(np.array([0.2, np.inf, 0.5])), _finite_or_missing(np.array([np.nan, -np.inf, 0.1]))]
    assert colour_limits(frames) == (0.1, 0.5, "")
    assert np.isnan(frames[0][1]) and np.isnan(frames[1][1])
    assert colour_limits([np.full(3, 2.0)])[:2] == (1.0, 3.0)
    assert colour_limits([np.full(2, np.nan)])[:2] == (-0.5, 0.5)


def test_the_colour_limits_leave_out_a_single_outlying_cell_and_say_so():
    """The default scene's case: 98% of a vessel's hoop stress between 55 and 93 kPa, one
    sub-cell at 139. The robust bar ends below that cell and the picture's note gives the
    whole range; 'full' spans it; a field without strays, and a given range, are as they
    are."""
    from shellsim.output.render import colour_limits

    vessel = np.random.default_rng(3).uniform(55.0, 93.0, 4000)
    with_outlier = [vessel[:2000], np.append(vessel[2000:], 139.0)]
    low, high, note = colour_limits(with_outlier, "robust", "kPa")
    assert 55.0 <= low < 56.0 and 92.0 < high <= 93.0
    assert "middle 98% of the values" in note and note.endswith(f"all lie in {vessel.min():.4g} to 139 kPa")
    assert colour_limits(with_outlier, "full")[:2] == (vessel.min(), 139.0)
    assert colour_limits([np.linspace(55.0, 93.0, 4000)]) == (55.0, 93.0, "")
    assert colour_limits(with_outlier, (60.0, 90.0)) == (60.0, 90.0, "")
