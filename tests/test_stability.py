"""The stability suite (decks/studies/stability.toml, make verify): every extreme variant
completes without NaN, balances its energy within 0.5%, lets the time step follow the
stiffening, meets the references that still apply; the run unstable by construction is
stopped with a message naming the safety factor."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shellsim.cli import app

from .conftest import ROOT

STABILITY = ROOT / "decks" / "studies" / "stability.toml"
BALANCE_BOUND_PERCENT = 0.5
#: Families whose stiffness grows with the load: the step must shrink by at least this.
STIFFENING = {"very large strain (E = 4.9)": 2.0, "fast loading (carotid)": 2.0,
              "aorta: stiffening and the safety factor": 1.2}


@pytest.mark.slow
def test_stability_suite(tmp_path):
    result = CliRunner().invoke(app, ["report", str(STABILITY), "--out", str(tmp_path), "--workers", "2"])
    assert result.exit_code == 0, result.output  # every run ended as expected
    with open(tmp_path / "report.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert len(rows) == 13
    for row in rows:
        summary = json.loads((Path(row["folder"]) / "summary.json").read_text())
        if row["family"] == "unstable by construction":
            assert row["status"] == "unstable"
            assert "dt_safety_factor = 0.9 < 1" in row["message"]
            continue
        assert row["status"] == "completed", row
        assert all(math.isfinite(v) for v in summary["energy"].values())
        assert abs(summary["energy"]["balance_error_percent"]) < BALANCE_BOUND_PERCENT, row
        assert row["passed"] in ("True", ""), row  # references that apply are met
        if row["family"] in STIFFENING:
            assert summary["dt"]["max"] > STIFFENING[row["family"]] * summary["dt"]["min"], row
