"""The first pages of docs/ (a valve, an artery from an image, an imported model) run as
written: each page's ``toml NAME`` blocks saved as NAME and its ``sh`` blocks run in
order, in a folder standing for the clone's root (its decks and its .venv), each command
to exit 0; then what each page says its run wrote is there and its run completed."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import ROOT

#: A fenced block: its info string (language, then an optional file name) and its text.
BLOCK = re.compile(r"^```(\w+)(?: +(\S+))?\n(.*?)^```", re.MULTILINE | re.DOTALL)


def walk(page: Path, folder: Path) -> None:
    """Run ``page`` in ``folder`` as one terminal session: its files written and its
    shell blocks run, in order, the first failing command ending it."""
    (folder / "decks").symlink_to(ROOT / "decks")
    (folder / ".venv").symlink_to(Path(sys.executable).parent.parent)
    session = []
    for language, name, text in BLOCK.findall(page.read_text(encoding="utf-8")):
        if language == "toml" and name:
            session.append(f"cat > {name} <<'END_OF_FILE'\n{text}END_OF_FILE")
        elif language == "sh":
            session.append(text)
    done = subprocess.run(["bash", "-e", "-x", "-c", "\n".join(session)], cwd=folder,
                          env=os.environ | {"COLUMNS": "80"}, capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, f"{page.name}:\n{done.stdout[-3000:]}\n{done.stderr[-5000:]}"


def completed(folder: Path) -> dict:
    summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    assert summary["status"] == "completed", summary["message"]
    return summary


def test_the_valve_page_closes_a_valve_and_draws_it(tmp_path):
    walk(ROOT / "docs" / "start-valve.md", tmp_path)
    summary = completed(tmp_path / "my_valve")
    assert summary["valve"]["orifice_area"]["final"] < 0.05  # shut: the shipped deck's reference, mm^2
    assert {p.name for p in (tmp_path / "my_valve" / "renders").glob("*.png")} >= {
        "contact_pressure_side_0020.png", "von_mises_iso_0020.png", "von_mises_nodal_top_0020.png"}
    assert (tmp_path / "my_valve" / "plots" / "orifice_area.png").is_file()


def test_the_artery_page_takes_a_surface_to_its_wall_stress(tmp_path):
    walk(ROOT / "docs" / "start-artery.md", tmp_path)
    assert (tmp_path / "my_artery_mesh" / "mesh.png").is_file()
    summary = completed(tmp_path / "my_artery")
    assert summary["steps"] >= 10  # a load step to each frame: the curve's points
    assert list((tmp_path / "my_artery" / "renders").glob("hoop_stress_nodal_front_*.png"))
    assert (tmp_path / "my_artery" / "plots" / "lumen_radius.png").is_file()


def test_the_import_page_brings_a_model_over_and_closes_it(tmp_path):
    walk(ROOT / "docs" / "start-import.md", tmp_path)
    assert (tmp_path / "valve" / "deck.toml").is_file() and (tmp_path / "valve" / "ids.csv").is_file()
    summary = completed(tmp_path / "closed")
    valve = summary["valve"]
    assert valve["coaptation_area"]["final"] > 0.0 and valve["orifice_area"]["final"] < 5.0  # mm^2: met, near shut
    assert list((tmp_path / "closed" / "renders").glob("contact_pressure_top_*.png"))


@pytest.mark.parametrize("page", ["start-valve.md", "start-artery.md", "start-import.md"])
def test_each_first_page_is_named_on_the_readme_s_first_screen(page):
    first_screen = "\n".join((ROOT / "README.md").read_text(encoding="utf-8").splitlines()[:40])
    assert f"docs/{page}" in first_screen
