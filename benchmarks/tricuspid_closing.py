"""The synthetic tricuspid valve (:mod:`shellsim.verify.synthetic_valve`: 8,100 shells in
three leaflets of their own constants, 4,095 chordae, self-contact with friction) written as
an Abaqus input file, imported as a valve engineer would (its user law mapped onto
Lee-Sacks), and closed under its full 23 mmHg by the path docs/verification.md recommends
for a valve's closed state: explicit dynamics with every mass scaled throughout to a step
of ``--step`` seconds and mass-proportional damping ``--damping`` [1/s], the valve's
measures and a render of its contact pressure written.

The deck it runs is the imported one with these keys added (what a user adds by hand):
``[solver] damping, dt_max`` (the step never above the scaled one: the soft leaflets'
unloaded step is longer, and they stiffen faster than estimates follow),
``[solver.mass_scaling] step, throughout = true``, the contact's ``penalty`` (its springs
are set on the unloaded leaflets' step: at the default 0.1 the pressed leaflets sink into
each other by half their thickness, at 1 and 2 the sides pressed together beside the
commissures by 9% and 6%), ``end_time`` the file's step and a ``--hold`` at full pressure, and
``[output.valve]`` on the leaflets and the annulus. Prints the run's numbers as a Markdown
table; nothing is asserted.

    .venv/bin/python benchmarks/tricuspid_closing.py OUT [--step 4e-5] [--damping 300]
        [--penalty 3] [--hold 0.01] [--circumferential 90 --belly 24 --band 6 --segments 15 --tips 32]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import h5py
import numpy as np
import tomli_w

from shellsim.foreign.user_law import UserLaw
from shellsim.imported_deck import import_model
from shellsim.study.jobs import apply_overrides
from shellsim.verify.synthetic_valve import THICKNESS, SyntheticValve, abaqus_text

LEE_SACKS = UserLaw.parse("lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1")


def closing_deck(deck: Path, step: float, damping: float, penalty: float, hold: float) -> Path:
    """The imported ``deck`` with the closing path's keys, written beside it."""
    data = tomllib.loads(deck.read_text(encoding="utf-8"))
    data = apply_overrides(data, {
        "solver.end_time": data["solver"]["end_time"] + hold, "solver.damping": damping, "solver.dt_max": step,
        "solver.mass_scaling": {"step": step, "throughout": True}, "contact.0.penalty": penalty,
        "output": {"interval": 0.005, "fields": ["displacement", "von_mises", "contact_pressure", "contact_gap"],
                   "valve": {"leaflets": "Leaflets", "annulus": "moved_x", "axis": [0.0, 0.0, -1.0], "samples": 20},
                   "render": [{"field": "contact_pressure", "view": "top"}, {"field": "von_mises", "view": "iso"}]},
    }, str(deck))
    closing = deck.with_name("closing.toml")
    closing.write_bytes(tomli_w.dumps(data).encode())
    return closing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="a new folder for the model, its deck and the run")
    parser.add_argument("--step", type=float, default=4e-5, help="the step the masses are scaled to [s]")
    parser.add_argument("--damping", type=float, default=300.0, help="mass-proportional damping [1/s]")
    parser.add_argument("--penalty", type=float, default=3.0, help="the contact's penalty scale")
    parser.add_argument("--hold", type=float, default=0.01, help="the full pressure held after the file's step [s]")
    defaults = SyntheticValve()
    for key in ("circumferential", "belly", "band", "segments", "tips"):
        parser.add_argument(f"--{key}", type=int, default=getattr(defaults, key))
    args = parser.parse_args()
    valve = SyntheticValve(args.circumferential, args.belly, args.band, args.segments, args.tips)
    args.out.mkdir(parents=True)
    source = args.out / "valve.inp"
    source.write_text(abaqus_text(valve))
    imported = import_model(source, args.out / "imported", LEE_SACKS)
    deck = closing_deck(imported.deck, args.step, args.damping, args.penalty, args.hold)
    results = args.out / "closed"
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "shellsim", "run", str(deck), "--out", str(results)], check=False)
    wall = time.perf_counter() - start
    summary = json.loads((results / "summary.json").read_text())
    with h5py.File(results / "results.h5") as frames:
        last = frames["frames"][str(max(map(int, frames["frames"])))]
        nearest = float(np.nanmin(last["contact_gap"][:]))  # nan: no face within reach
    valve_record = summary.get("valve", {})
    row = {"shells": summary["elements"], "status": summary["status"], "steps": summary["steps"],
           "run (s)": summary["wall_time_s"], "whole command (s)": wall,
           "mass factor": summary.get("mass_scaling", {}).get("factor", 1.0),
           "nearest gap / h": nearest / THICKNESS, "balance (%)": summary["energy"]["balance_error_percent"],
           "contact's share of the step": summary["contact"]["share_of_step"],
           "us per element-step": summary["us_per_element_step"]}
    row |= {name: values["final"] for name, values in valve_record.items()}
    print("| " + " | ".join(row) + " |")
    print("|---" * len(row) + "|")
    print("| " + " | ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in row.values()) + " |")


if __name__ == "__main__":
    main()
