"""The pictures in docs/pictures/: the default scene and both valve decks run as shipped,
then rendered as a slide (1600 x 1200, slide/) and a paper column (800 x 600, column/)
would show them, and plotted (plots/). Each run goes to build/pictures/NAME and is kept: a completed run of the same
deck is drawn again without running it (``--rerun`` runs it anyway). The heartbeat takes
about 20 minutes on 2 cores, the others a few.

    .venv/bin/python docs/pictures/make_pictures.py [--rerun] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PICTURES = ROOT / "docs" / "pictures"
RUNS = ROOT / "build" / "pictures"

#: Each scene: its deck and the renders drawn of it, (field, frame, view, extra options).
SCENES = {
    "carotid": ("decks/tissue/carotid_hgo_pulse.toml",
                [("hoop_stress_nodal", "last", "front", ["--show", "outline"]),
                 ("pressure_band", "last", "iso", ["--show", "fibres"])]),
    "aortic_valve_closing": ("decks/valves/aortic_valve_closing.toml",
                             [("contact_pressure", "last", "side", []),
                              ("von_mises_nodal", "last", "iso", [])]),
    "aortic_valve_cycle": ("decks/valves/aortic_valve_cycle.toml",
                           [("contact_pressure", "72", "side", []),
                            ("von_mises_nodal", "72", "top", [])]),
}
#: (name, pixels) of each picture size.
SIZES = (("slide", "1600x1200"), ("column", "800x600"))


def shellsim(*arguments: str) -> None:
    subprocess.run([sys.executable, "-m", "shellsim", *arguments], check=True, cwd=ROOT)


def completed(folder: Path, deck: Path) -> bool:
    """Whether ``folder`` holds a completed run of ``deck`` as it is now."""
    try:
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
        ran = (folder / "deck.toml").stat().st_mtime
    except (OSError, ValueError):
        return False
    return summary.get("status") == "completed" and ran >= deck.stat().st_mtime


def draw(name: str, rerun: bool) -> list[Path]:
    deck, renders = SCENES[name]
    folder = RUNS / name
    if rerun or not completed(folder, ROOT / deck):
        shellsim("run", deck, "--out", str(folder))
    for size_name, pixels in SIZES:
        for field, frame, view, extra in renders:
            shellsim("render", str(folder), "--field", field, "--frame", frame, "--view", view, "--size", pixels,
                     "--out", str(PICTURES / size_name / name), *extra)
    shellsim("plot", str(folder), "--out", str(PICTURES / "plots" / name))
    return sorted(p for kind in (*(size for size, _ in SIZES), "plots") for p in (PICTURES / kind / name).glob("*.png"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rerun", action="store_true", help="run every scene again")
    parser.add_argument("--only", nargs="*", choices=list(SCENES), default=list(SCENES))
    args = parser.parse_args()
    for name in args.only:
        for kind in (*(size for size, _ in SIZES), "plots"):
            shutil.rmtree(PICTURES / kind / name, ignore_errors=True)
        for path in draw(name, args.rerun):
            print(f"wrote {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
