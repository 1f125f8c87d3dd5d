"""Studies: deck variants run through a dask LocalCluster, each timed and checked, rows
streamed into report.md / report.csv / error_vs_time.png; a failed job is a row."""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.errors import DeckError
from shellsim.study.jobs import Job, apply_overrides, as_expected, row
from shellsim.study.report import read_external, table

from .conftest import BASE, ROOT, STUDIES

runner = CliRunner()
QUICK = ROOT / "decks" / "studies" / "quick.toml"


def _rows(folder: Path) -> list[dict]:
    with open(folder / "report.csv", newline="") as file:
        return list(csv.DictReader(file))


def test_quick_study_runs_every_variant_through_a_local_cluster(tmp_path):
    record = tmp_path / "record.md"
    record.write_text("# Record\n\nbefore\n<!-- report quick -->\nold table\n<!-- end report quick -->\nafter\n")
    result = runner.invoke(app, ["report", str(QUICK), "--out", str(tmp_path), "--workers", "2", "--embed", str(record)])
    assert result.exit_code == 0, result.output
    rows = _rows(tmp_path)
    assert [(r["family"].split()[1], r["variant"]) for r in rows] == [("1", "2x2"), ("1", "3x3"), ("7", "M2"), ("7", "M1")]
    for r in rows:
        assert r["status"] == "completed" and r["passed"] == "True"
        assert 0.0 < float(r["error_percent"]) < 2.0 and float(r["wall_time_s"]) > 0.0
        assert (Path(r["folder"]) / "summary.json").exists()
    assert int(rows[1]["dofs"]) > int(rows[0]["dofs"])  # the 3x3 variant did refine the mesh
    table = (tmp_path / "report.md").read_text()
    assert table.count("| completed |") == 4 and "still running" not in table
    embedded = record.read_text()  # the same table, between the markers, the rest kept
    assert embedded.startswith("# Record\n\nbefore\n<!-- report quick -->\n| deck |")
    assert embedded.endswith("<!-- end report quick -->\nafter\n") and "old table" not in embedded
    assert embedded.count("| completed |") == 4
    import imageio.v3 as iio

    assert iio.imread(tmp_path / "error_vs_time.png")[..., :3].std() > 10.0


def test_a_failed_job_is_a_row_of_the_report_not_the_end_of_the_study(tmp_path):
    study = tmp_path / "study.toml"
    deck = (ROOT / "decks" / "verification" / "test01_plate_step_2x2.toml").as_posix()
    study.write_text(f"""
[meta]
title = "one good job, one broken"

[[deck]]
path = "{deck}"

[[deck.variant]]
label = "as shipped"

[[deck.variant]]
label = "broken"
set = {{ "mesh.divisions.depth" = 3 }}
""")
    result = runner.invoke(app, ["report", str(study), "--out", str(tmp_path / "out"), "--workers", "1"])
    assert result.exit_code == 1
    rows = {r["variant"]: r for r in _rows(tmp_path / "out")}
    assert rows["as shipped"]["status"] == "completed"
    assert rows["broken"]["status"] == "failed" and "depth" in rows["broken"]["message"]


def test_a_record_without_the_markers_is_refused_before_any_job_runs(tmp_path):
    record = tmp_path / "record.md"
    record.write_text("# Record\n")
    result = runner.invoke(app, ["report", str(QUICK), "--out", str(tmp_path / "out"), "--embed", str(record)])
    assert result.exit_code == 2
    assert "<!-- report quick -->" in result.output and "<!-- end report quick -->" in result.output
    assert not (tmp_path / "out").exists()
    assert record.read_text() == "# Record\n"


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.name)
def test_every_variant_of_every_shipped_study_is_a_valid_deck(path, tmp_path):
    from shellsim.study.jobs import study_jobs, variant_deck
    from shellsim.study.schema import load_study

    jobs = study_jobs(load_study(path), path, tmp_path)
    assert jobs
    for job in jobs:
        variant_deck(job.deck, job.overrides, job.label)  # raises DeckError on a broken variant


def test_variant_keys_reach_into_tables_and_arrays_of_tables():
    data = {"mesh": {"divisions": {"length": 2}}, "load": [{"value": 1.0}, {"value": 2.0}]}
    apply_overrides(data, {"mesh.divisions.length": 4, "load.1.value": 5.0, "solver.mass": "M1"}, "deck")
    assert data == {"mesh": {"divisions": {"length": 4}}, "load": [{"value": 1.0}, {"value": 5.0}],
                    "solver": {"mass": "M1"}}
    with pytest.raises(DeckError, match="load.7.value"):
        apply_overrides(data, {"load.7.value": 1.0}, "deck")


def test_external_points_need_their_columns(tmp_path):
    good = tmp_path / "peers.csv"
    good.write_text("family,program,label,error_percent,wall_time_s\nTest 1,other,4x4,0.5,12\n")
    assert read_external(good) == [{"family": "Test 1", "program": "other", "label": "4x4",
                                    "error_percent": 0.5, "wall_time_s": 12.0}]
    bad = tmp_path / "bad.csv"
    bad.write_text("family,program,error\nTest 1,other,0.5\n")
    with pytest.raises(DeckError, match="label"):
        read_external(bad)


#: A run's summary.json, the parts a report row reads.
SUMMARY = {"status": "completed", "method": "explicit", "message": "", "dofs": 5, "elements": 1, "steps": 3,
           "dt": {"mean": 1e-3, "min": 1e-3, "max": 3e-3}, "wall_time_s": 0.1, "us_per_element_step": 1.0,
           "energy": {"balance_error_percent": 0.2}, "reference": []}


def test_a_stability_run_is_judged_by_its_energy_balance_and_its_falling_step():
    job = Job("f", "v", Path("d.toml"), {}, Path("out"), balance_within_percent=0.5, dt_falls_by=2.0)
    good = row(job, SUMMARY)
    assert good["passed"] is True and good["dt_fall"] == pytest.approx(3.0) and good["balance_error_percent"] == 0.2
    leaky = row(job, SUMMARY | {"energy": {"balance_error_percent": -0.7}})
    assert leaky["passed"] is False and "energy balance error -0.7% beyond 0.5%" in leaky["message"]
    stiff = row(replace(job, dt_falls_by=4.0), SUMMARY)
    assert stiff["passed"] is False and "fell 3 times, not 4.0" in stiff["message"]
    assert row(replace(job, balance_within_percent=None, dt_falls_by=None), SUMMARY)["passed"] is None  # nothing checked


def _entry(**values) -> dict:
    """A summary's reference entry (the keys :func:`shellsim.verify.check.check` gives),
    expected 1.0 with a 2% tolerance, with ``values`` in place."""
    return {"quantity": "q", "probe": "p", "measure": "final", "computed": None, "expected": 1.0, "error": None,
            "error_percent": None, "tolerance_percent": 2.0, "tolerance": None, "passed": False,
            "source": "a test"} | values


def test_a_run_cut_short_is_judged_by_its_expected_status_not_its_references():
    summary = SUMMARY | {"status": "unstable", "message": "the run became unstable",
                         "reference": [_entry(error=0.98, error_percent=98.0, passed=False)]}
    on_purpose = row(Job("f", "v", Path("d.toml"), {}, Path("out"), expect="unstable"), summary)
    assert on_purpose["error_percent"] is None and on_purpose["passed"] is None and as_expected(on_purpose)
    by_accident = row(Job("f", "v", Path("d.toml"), {}, Path("out")), summary)
    assert not as_expected(by_accident)
    completed = row(Job("f", "v", Path("d.toml"), {}, Path("out")), summary | {"status": "completed"})
    assert completed["error_percent"] == 98.0 and not as_expected(completed)


def test_a_coarse_mesh_expected_to_miss_is_judged_by_missing():
    summary = SUMMARY | {"reference": [_entry(error=0.038, error_percent=3.8, passed=False)]}
    coarse = Job("f", "1x1", Path("d.toml"), {}, Path("out"), expect="missed")
    missed = row(coarse, summary)
    assert missed["error_percent"] == 3.8 and as_expected(missed)
    assert "as expected" in table([missed]) and "(expected" not in table([missed])
    met = row(coarse, summary | {"reference": [_entry(error=0.01, error_percent=1.0, passed=True)]})
    assert not as_expected(met) and "completed (expected missed)" in table([met])  # a change worth a look
    unstable = row(coarse, summary | {"status": "unstable"})
    assert not as_expected(unstable)


def test_an_absolute_tolerance_counts_its_error_against_the_largest_value_on_its_probe():
    """A tip swinging back through zero: 0.1 off an expected 0.4 is 1% of the 10 the
    probe reaches, not 25%."""
    references = [
        _entry(probe="tip", expected=-10.0, error=0.05, error_percent=-0.5, tolerance=0.24, passed=True),
        _entry(probe="tip", expected=0.4, error=0.1, error_percent=25.0, tolerance=0.24, passed=True),
        _entry(probe="twist", expected=0.0, error=1e-12, tolerance=0.01, passed=True),
        _entry(probe="r", expected=2.0, error=0.02, error_percent=1.0, passed=True),
    ]
    summary = SUMMARY | {"reference": references}
    assert row(Job("f", "v", Path("d.toml"), {}, Path("out")), summary)["error_percent"] == pytest.approx(1.0)


def test_an_unreachable_scheduler_is_named_with_the_wait_it_was_given(tmp_path):
    """Refused at once and said so (no wall-clock bound here: how long a machine takes is not
    the point; the silent scheduler below is what a wait must end for)."""
    result = runner.invoke(app, ["report", str(QUICK), "--out", str(tmp_path / "out"),
                                 "--scheduler", "tcp://127.0.0.1:1", "--connect-timeout", "2"])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "the dask scheduler at 'tcp://127.0.0.1:1' did not answer within 2 s" in " ".join(result.output.split())


def test_a_truncated_mesh_is_a_failed_row_and_a_dying_worker_is_named(tmp_path):
    """A job reading a truncated mesh file (meshio calls sys.exit on it) is a failed row with
    the reason, and its worker lives on (same process before and after); a job whose worker
    dies is one failed row naming the job, not four workers taken down in turn."""
    import os

    from shellsim.study.executor import open_client, run_jobs
    from shellsim.study.jobs import study_jobs
    from shellsim.study.schema import load_study

    from .test_mesh_files import write_mesh

    def kill_own_worker(job, threads):  # nested, so dask ships it by value
        import signal

        os.kill(os.getpid(), signal.SIGKILL)

    write_mesh(tmp_path / "whole.vtu", [])
    (tmp_path / "cut.vtu").write_bytes((tmp_path / "whole.vtu").read_bytes()[:700])
    (tmp_path / "cut.toml").write_text(BASE + '[geometry]\nbuilder = "file"\npath = "cut.vtu"\n')
    study = tmp_path / "study.toml"
    study.write_text('[meta]\ntitle = "a truncated mesh"\n\n[[deck]]\npath = "cut.toml"\n\n'
                     '[[deck.variant]]\nlabel = "cut"\n')
    jobs = study_jobs(load_study(study), study, tmp_path / "out")
    rows: list[dict] = []
    with open_client(None, 1) as client:
        before = client.run(os.getpid)
        run_jobs(jobs, client, rows.append, threads=1)
        after = client.run(os.getpid)
        run_jobs(jobs, client, rows.append, threads=1, work=kill_own_worker)
    assert rows[0]["status"] == "failed" and "could not be read" in rows[0]["message"]
    assert before == after
    assert rows[1]["status"] == "failed" and "the worker process running this job" in rows[1]["message"]
    assert "variant 'cut'" in rows[1]["message"]


def test_every_job_has_its_own_folder_and_row(tmp_path):
    """Two decks of one file name in different folders, and labels that slug alike ("a b",
    "a-b"): four jobs, four row keys (the shared name becomes each deck's path), four
    folders (the alike slugs each with a short hash of their own name), the same whatever
    the order; one label given twice for one family is refused."""
    from shellsim.errors import StudyError
    from shellsim.study.jobs import study_jobs
    from shellsim.study.schema import load_study

    for sub in ("left", "right"):
        (tmp_path / sub).mkdir()
        (tmp_path / sub / "plate.toml").write_text(BASE + '[geometry]\nbuilder = "rectangle"\nlength = 1.0\nwidth = 1.0\n')
    variants = '[[deck.variant]]\nlabel = "a b"\n\n[[deck.variant]]\nlabel = "a-b"\n'
    study = tmp_path / "study.toml"
    study.write_text(f'[meta]\ntitle = "alike"\n\n[[deck]]\npath = "left/plate.toml"\n\n{variants}\n'
                     f'[[deck]]\npath = "right/plate.toml"\n\n{variants}')
    jobs = study_jobs(load_study(study), study, tmp_path / "out")
    assert len({job.key for job in jobs}) == len({job.folder for job in jobs}) == 4
    assert {job.family for job in jobs} == {"left/plate", "right/plate"}
    reversed_study = tmp_path / "reversed.toml"
    reversed_study.write_text(f'[meta]\ntitle = "alike"\n\n[[deck]]\npath = "right/plate.toml"\n\n'
                              f'{variants.replace("a b", "x").replace("a-b", "a b")}\n[[deck]]\npath = "left/plate.toml"\n\n'
                              f'{variants}')
    again = {(job.family, job.label): job.folder for job in study_jobs(load_study(reversed_study), reversed_study,
                                                                        tmp_path / "out")}
    assert again[("left/plate", "a b")] == next(job.folder for job in jobs if job.key == "left/plate / a b")
    twice = tmp_path / "twice.toml"
    twice.write_text('[meta]\ntitle = "twice"\n\n[[deck]]\npath = "left/plate.toml"\nfamily = "plates"\n\n'
                     '[[deck.variant]]\nlabel = "coarse"\n\n[[deck]]\npath = "right/plate.toml"\nfamily = "plates"\n\n'
                     '[[deck.variant]]\nlabel = "coarse"\n')
    with pytest.raises(StudyError, match="variant 'coarse' of family 'plates' is given twice"):
        study_jobs(load_study(twice), twice, tmp_path / "out")


def test_an_interrupted_study_says_so_in_its_report(tmp_path, monkeypatch):
    """Ctrl-C after the first of the quick study's four jobs: report.md says three did not
    finish, with the one row there is, and the command ends as interrupted (exit code 130)."""
    from contextlib import nullcontext

    from shellsim.study import executor
    from shellsim.study.jobs import failed_row

    def one_then_ctrl_c(jobs, client, on_row, threads=None):
        on_row(failed_row(jobs[0], RuntimeError("stand-in for a finished job")))
        raise KeyboardInterrupt

    monkeypatch.setattr(executor, "open_client", lambda *args: nullcontext())
    monkeypatch.setattr(executor, "prepare_workers", lambda *args, **kwargs: None)
    monkeypatch.setattr(executor, "run_jobs", one_then_ctrl_c)
    result = runner.invoke(app, ["report", str(QUICK), "--out", str(tmp_path)])
    assert result.exit_code == 130, result.output
    report = (tmp_path / "report.md").read_text()
    assert "*Interrupted: 3 job(s) did not finish and have no row.*" in report and "still running" not in report
    assert len(_rows(tmp_path)) == 1


@pytest.mark.parametrize("stranger", ["silent", "talking"])
def test_a_port_that_answers_but_is_no_dask_scheduler_is_named(stranger, tmp_path):
    """A TCP port that takes the connection and says nothing, or says something else (an
    HTTP reply): the study ends with a message naming the address (dask's Client waited
    for ever on the first and raised a MemoryError on the second)."""
    import socket
    import threading

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    held = []

    def serve():
        while True:
            try:
                connection, _ = server.accept()
            except OSError:
                return
            held.append(connection)
            if stranger == "talking":
                connection.sendall(b"HTTP/1.0 200 OK\r\n\r\nhello")

    threading.Thread(target=serve, daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    outcome = []
    command = threading.Thread(target=lambda: outcome.append(runner.invoke(
        app, ["report", str(QUICK), "--out", str(tmp_path), "--scheduler", address, "--connect-timeout", "2"])),
        daemon=True)
    command.start()
    command.join(120.0)  # it used to wait for ever
    server.close()
    assert outcome, "the study still waits on a port that is not a dask scheduler"
    result = outcome[0]
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert f"'{address}' took the connection but answered" in " ".join(result.output.split())
