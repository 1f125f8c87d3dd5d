"""The command line: commands listed, plain errors with exit code 2 and no traceback,
`check` and `mesh` doing their work."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from shellsim.cli import app

from .conftest import ROOT, deck_text

runner = CliRunner()
ARTERY_DECK = ROOT / "decks" / "artery_inflation.toml"


def test_help_lists_every_command():
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    for command in ("run", "mesh", "check", "render", "plot", "report", "bench"):
        assert command in result.output


def test_check_summarises_a_valid_deck():
    result = runner.invoke(app, ["check", str(ARTERY_DECK)])
    assert result.exit_code == 0, result.output
    for fragment in ("tube", "guccione", "19 elements", "technique 1", "anisotropic"):
        assert fragment in result.output


def test_check_forecasts_a_mass_scaled_run_at_its_target_step():
    """The mass-scaled cantilever (Test 2) takes steps of its target 1.2e-5 to t = 0.12:
    `check` says how much every mass grows and counts the steps of the target, not of the
    unscaled critical step (four times as many): 84 equal steps to each of its 120 output
    times 0.001 apart (83.3 of the target apiece), 10,080."""
    result = runner.invoke(app, ["check", str(ROOT / "decks" / "verification"
                                              / "test02_cantilever_uniform_load_3_mass_scaled.toml")])
    said = " ".join(result.output.replace("│", " ").split())  # the table's cells, wrapped, as one text
    assert result.exit_code == 0, result.output
    assert "for the mass scaling's step 1.2e-05: about 10,080 steps to the end" in said
    assert "every mass x 1" in said


def test_check_of_a_broken_deck_prints_the_problem_without_a_traceback(tmp_path):
    deck = tmp_path / "broken.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0').replace("nu = 0.3", "nu = 0.6"))
    result = runner.invoke(app, ["check", str(deck)])
    assert result.exit_code == 2
    assert "material.nu" in result.output and "broken.toml" in result.output
    assert "Traceback" not in result.output


def test_check_warns_about_a_safety_factor_below_one(tmp_path):
    deck = tmp_path / "unstable.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0')
                    .replace("end_time = 1.0", "end_time = 1.0\ndt_safety_factor = 0.8"))
    result = runner.invoke(app, ["check", str(deck)])
    assert result.exit_code == 0
    assert "unstable" in result.output


def test_magnitudes_outside_any_unit_system_and_disproportionate_sizes_are_refused(tmp_path):
    deck = tmp_path / "absurd.toml"
    plate = 'builder = "rectangle"\nlength = 2.0\nwidth = 1e-7'
    deck.write_text(deck_text(plate).replace("E = 1000.0", "E = 1e300"))
    result = runner.invoke(app, ["check", str(deck)])
    assert result.exit_code == 2
    assert "material.E (line 7): got 1e+300: expected a magnitude between 1e-30 and 1e+30" in result.output
    deck.write_text(deck_text(plate).replace("thickness = 0.01", "thickness = 5.0"))
    result = runner.invoke(app, ["check", str(deck)])
    said = " ".join(result.output.split())
    assert result.exit_code == 2
    assert "geometry.width = 1e-07 and geometry.length = 2 are more than 1e+06 times apart" in said
    assert "section.thickness = 5 is larger than the model itself (geometry.length = 2)" in said


def test_a_scene_that_would_take_years_is_refused_by_check_and_run(tmp_path):
    """A 1e-20 thick plate has a critical step near 1e-23 of the end time: check shows the
    scene and refuses it; run refuses before the first step and says so in its summary."""
    import json

    deck = tmp_path / "hopeless.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0').replace("thickness = 0.01",
                                                                                          "thickness = 1e-20"))
    checked = runner.invoke(app, ["check", str(deck)])
    assert checked.exit_code == 2 and "steps to the end" in checked.output
    assert "years on this machine" in " ".join(checked.output.split())
    ran = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert ran.exit_code == 2 and "years on this machine" in " ".join(ran.output.split())
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "refused" and summary["steps"] == 0


def test_a_mesh_larger_than_the_memory_is_refused_before_meshing(tmp_path, monkeypatch):
    """A builder's divisions are counted before gmsh meshes them."""
    from shellsim import memory

    monkeypatch.setattr(memory, "available_bytes", lambda: 1e8)
    result = runner.invoke(app, ["check", str(ARTERY_DECK)])
    assert result.exit_code == 2
    assert "[mesh] divisions give 19 elements: a run needs about 400 MB of memory and 100 MB is available" in \
        " ".join(result.output.split())


def test_a_mesh_file_larger_than_the_memory_is_refused_once_read(tmp_path, monkeypatch):
    """A mesh file's size is known once it is read: refused then, naming its elements."""
    from shellsim import memory

    from .conftest import pressed_plates_deck

    deck = tmp_path / "plates.toml"
    deck.write_text(pressed_plates_deck(tmp_path / "plates.vtu", 1.0, "[solver]\nend_time = 1.0"))
    monkeypatch.setattr(memory, "available_bytes", lambda: 1e8)
    result = runner.invoke(app, ["check", str(deck)])
    assert result.exit_code == 2
    assert "the mesh has 25 elements: a run needs about 400 MB of memory and 100 MB is available" in \
        " ".join(result.output.split())


def test_a_static_scene_is_reckoned_with_its_tangents_factors(tmp_path, monkeypatch):
    """The pinched hemisphere (128 elements) with 410 MB available: solved explicitly it
    would hold about 403 MB and is checked; statically, with its tangent and factors (165 kB
    an element), about 421 MB, and it is refused once meshed."""
    from shellsim import memory

    monkeypatch.setattr(memory, "available_bytes", lambda: 4.1e8)
    static = ROOT / "decks" / "verification" / "pinched_hemisphere_static.toml"
    refused = runner.invoke(app, ["check", str(static)])
    assert refused.exit_code == 2
    assert "the mesh has 128 elements: a run needs about 421 MB of memory and 410 MB is available" in \
        " ".join(refused.output.split())
    explicit = tmp_path / "hemisphere.toml"
    explicit.write_text(static.read_text().replace('method = "static"', 'method = "explicit"'))
    assert "a run needs about" not in " ".join(runner.invoke(app, ["check", str(explicit)]).output.split())


def test_check_gives_the_step_and_suggests_m1_for_a_thin_shell_on_m2(tmp_path):
    thin = ROOT / "decks" / "stability" / "thin_plate_1e-3.toml"
    shipped = runner.invoke(app, ["check", str(thin)])  # M1: no hint
    assert shipped.exit_code == 0 and "hint" not in shipped.output
    assert "time step" in shipped.output and "steps to the end" in shipped.output
    deck = tmp_path / "thin_m2.toml"
    deck.write_text(thin.read_text().replace('mass = "M1"', 'mass = "M2"'))
    result = runner.invoke(app, ["check", str(deck)])
    assert result.exit_code == 0
    assert 'hint: solver.mass = "M1" would take a' in " ".join(result.output.split())


def test_mesh_writes_the_vtu_and_the_png(tmp_path):
    import meshio

    result = runner.invoke(app, ["mesh", str(ARTERY_DECK), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    written = meshio.read(tmp_path / "out" / "mesh.vtu")
    assert written.cells[0].type == "quad9" and len(written.cells[0].data) == 19
    assert {"director", "thickness", "set_sym_x", "set_pole"} <= set(written.point_data)
    assert (tmp_path / "out" / "mesh.png").stat().st_size > 1000


def test_mesh_into_an_unwritable_place_is_a_clear_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    result = runner.invoke(app, ["mesh", str(ARTERY_DECK), "--out", str(blocker / "sub")])
    assert result.exit_code == 2
    assert "not writable" in result.output


@pytest.mark.parametrize("args", [["render", "nowhere"], ["plot", "nowhere"], ["report", "nowhere.toml"]])
def test_render_plot_and_report_of_missing_inputs_are_clear_errors(args, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing may be written into the checkout
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert "nowhere" in result.output and "Traceback" not in result.output
    assert not (tmp_path / "results").exists()


def test_run_of_the_default_scene_completes_and_reports_its_volume(tmp_path):
    """The default deck (Guccione aorta, Technique 1) runs and writes the render it asks for."""
    import json

    result = runner.invoke(app, ["run", str(ARTERY_DECK), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    assert list((tmp_path / "out" / "renders").glob("pressure_band_*.png"))
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "completed"
    assert abs(summary["volume_change_percent"]) < 1.0
    assert abs(summary["energy"]["balance_error_percent"]) < 1.0


def test_help_texts_keep_their_defaults_and_units():
    """Rich markup ate every bracketed default and unit of the option texts ('Output folder
    .'); the help is plain text now, each option with its default."""
    ran = runner.invoke(app, ["run", "--help"])
    assert ran.exit_code == 0 and "[default: results/DECK-NAME]" in " ".join(ran.output.split())
    assert "<bool>" not in ran.output and "static" in ran.output
    rendered = runner.invoke(app, ["render", "--help"])
    said = " ".join(rendered.output.split())
    assert "[default: RESULTS/renders]" in said and "[default: 1200x900]" in said


def test_deck_text_is_shown_as_written_never_read_as_markup_or_tex(tmp_path):
    """A title with a stray closing tag and an unclosed formula ended check in rich's
    MarkupError and plot in matplotlib's TeX parser; both show it as written."""
    title = "A [/bold] plate $\\\\alpha^{2$"
    deck = tmp_path / "odd.toml"
    deck.write_text(deck_text('builder = "rectangle"\nlength = 1.0\nwidth = 1.0', '[[boundary]]\ntype = "clamped"\n'
                              'set = "x0"\n[[load]]\ntype = "pressure"\nvalue = 1.0e-6\n[[output.probe]]\nname = "tip"\n'
                              'quantity = "displacement"\nset = "x1y0"\ncomponent = "z"\n')
                    .replace('title = "test scene"', f'title = "{title}"')
                    .replace("end_time = 1.0", 'method = "static"\nend_time = 1.0'))
    checked = runner.invoke(app, ["check", str(deck)])
    assert checked.exit_code == 0 and "A [/bold] plate $\\alpha^{2$" in checked.output, checked.output
    ran = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    assert ran.exit_code == 0, ran.output
    plotted = runner.invoke(app, ["plot", str(tmp_path / "out")])
    assert plotted.exit_code == 0, plotted.output
    assert (tmp_path / "out" / "plots" / "tip.png").exists() and (tmp_path / "out" / "plots" / "energy.png").exists()


def test_durations_read_as_a_person_writes_them():
    """Seconds below ten with two figures, whole seconds to two minutes (108 s, never
    1.1e+02 s), then minutes, hours, days and years."""
    from shellsim.solver.outlook import duration

    assert [duration(s) for s in (3.24, 108.4, 840.0, 5.1 * 3600, 3 * 86400)] == \
        ["3.2 s", "108 s", "14 min", "5.1 h", "3 days"]


def test_set_changes_a_deck_for_one_run_and_says_what_it_expects(tmp_path):
    """--set KEY=VALUE (a TOML value; [[tables]] by number) changes the deck for one run,
    whose deck.toml keeps the change while the deck file stays as it was; a VALUE that is
    no TOML, a key without a value, a change the deck's model refuses and a change with
    --resume are errors naming what was expected."""
    import tomllib

    deck = ROOT / "decks" / "verification" / "test02_cantilever_uniform_load_3_static.toml"
    shipped = deck.read_text()
    result = runner.invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"), "--quiet",
                                 "--set", "solver.end_time=0.5", "--set", "boundary.0.set=\"x0\"",
                                 "--set", "output.fields=[\"displacement\", \"von_mises\"]"])
    assert result.exit_code in (0, 1), result.output  # 1: the reference is the whole load's
    resolved = tomllib.loads((tmp_path / "out" / "deck.toml").read_text())
    assert resolved["solver"]["end_time"] == 0.5 and resolved["output"]["fields"] == ["displacement", "von_mises"]
    assert deck.read_text() == shipped
    for change, expected in (("solver.end_time=half", "expected KEY=VALUE with VALUE as in TOML"),
                             ("solver.end_time=", "expected KEY=VALUE"),
                             ("solver.end_time=-1", "solver.end_time")):
        result = runner.invoke(app, ["check", str(deck), "--set", change])
        assert result.exit_code != 0 and expected in " ".join(result.output.split()), (change, result.output)
    result = runner.invoke(app, ["run", "--resume", str(tmp_path / "out"), "--set", "solver.end_time=1"])
    assert result.exit_code != 0 and "with the deck it was run with" in " ".join(result.output.split())


def test_a_newton_path_is_forecast_a_step_per_output_time_or_its_increments():
    """A static solve lands on every output time: at least one load step to each, or its
    increments where more; arc length twice that; implicit its time steps' increments."""
    from shellsim.deck import parse_deck
    from shellsim.solver.outlook import newton_path, newton_steps

    plate = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0')
    static = plate.replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "static"\nend_time = 1.0')
    landing = parse_deck(static + "\n[output]\ninterval = 0.25\ntimes = [0.1]\n")
    assert newton_path(landing) == "load" and newton_steps(landing) == 5  # 0.1, 0.25, 0.5, 0.75, 1
    more = parse_deck(static.replace('method = "static"', 'method = "static"\nstatic = { increments = 10 }'))
    assert newton_steps(more) == 10
    arc = parse_deck(static.replace('method = "static"', 'method = "static"\nstatic = { control = "arc_length", '
                                                         'increments = 10 }'))
    assert newton_path(arc) == "arc_length" and newton_steps(arc) == 20
    implicit = parse_deck(plate.replace("[solver]\nend_time = 1.0", '[solver]\nmethod = "implicit"\nend_time = 1.0'))
    assert newton_path(implicit) == "implicit" and newton_steps(implicit) == 100
