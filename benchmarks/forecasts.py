"""What ``shellsim check`` and a run's start line forecast for each shipped deck (the
steps and the wall time, :func:`shellsim.solver.outlook.forecast`) beside what the run
then took, run as shipped in this process (kernels compiled before the first). Prints a
Markdown table, the ratios measured over forecast; nothing is asserted. Run it on an
idle machine: the forecast's rates are an idle machine's.

    .venv/bin/python benchmarks/forecasts.py [DECK ...] [--skip NAME ...] [--json FILE] [--runs FILE]

Without decks: every deck under decks/ but the studies' and the bench's. ``--runs FILE``
takes each deck's run from the rows of an earlier ``--json FILE`` instead of running it
again (a forecast changed, the runs not).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from shellsim.execute import built_run, solve
from shellsim.solver.outlook import forecast

ROOT = Path(__file__).resolve().parents[1]


def shipped() -> list[Path]:
    """Every shipped scene: the decks under decks/, the studies' ladders left out."""
    return sorted(p for p in (ROOT / "decks").rglob("*.toml") if p.parent.name not in ("studies", "bench"))


def measured(deck: Path, earlier: dict | None = None) -> dict:
    """The forecast and the run's own numbers for ``deck``, run as shipped without its
    renders, or taken from ``earlier`` (a row of an earlier run of this script)."""
    from shellsim.study.jobs import variant_deck

    scene = variant_deck(deck, {"output.render": []})
    checked = built_run(scene, deck.parent)  # as check builds it
    ahead = forecast(checked.deck, checked.mesh, checked.model)
    row = {"deck": str(deck.relative_to(ROOT)), "method": scene.solver.method, "elements": checked.model.n_elements,
           "forecast_steps": ahead["steps"], "forecast_s": ahead["seconds"], "tangent_s": ahead.get("tangent_seconds")}
    if earlier is not None:
        return earlier | row
    run = built_run(scene, deck.parent)  # a run of its own, untouched by the forecast's timings
    start = time.perf_counter()
    solve(run)
    wall = time.perf_counter() - start
    newton = run.newton
    return row | {"status": run.status, "steps": int(run.sim.state.steps), "wall_s": wall,
                  "iterations": sum(step.iterations for step in newton),
                  "tangents": sum(step.tangents for step in newton),  # those its converged steps used
                  "tangents_formed": len(run.tangent_seconds)}  # every one, stability checks and cut tries too


def table(rows: list[dict]) -> str:
    lines = ["| deck | method | elements | steps forecast | steps taken | ratio | time forecast [s] | "
             "time taken [s] | ratio |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['deck']} | {r['method']} | {r['elements']:,} | {r['forecast_steps']:,} | {r['steps']:,} | "
                     f"{r['steps'] / r['forecast_steps']:.2f} | {r['forecast_s']:.3g} | {r['wall_s']:.3g} | "
                     f"{r['wall_s'] / r['forecast_s']:.2f} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("decks", nargs="*", type=Path)
    parser.add_argument("--skip", nargs="*", default=[], help="leave out decks whose path holds any of these")
    parser.add_argument("--json", type=Path, help="also write each row as a JSON line here")
    parser.add_argument("--runs", type=Path, help="take the runs from this earlier --json file's rows")
    args = parser.parse_args()
    decks = [p.resolve() for p in args.decks] or [p for p in shipped() if not any(s in str(p) for s in args.skip)]
    earlier = {}
    if args.runs:
        earlier = {row["deck"]: row for row in map(json.loads, args.runs.read_text(encoding="utf-8").splitlines())}
        decks = [deck for deck in decks if str(deck.relative_to(ROOT)) in earlier]
    rows = []
    for deck in decks:
        row = measured(deck, earlier.get(str(deck.relative_to(ROOT))))
        rows.append(row)
        print(json.dumps(row), flush=True)
        if args.json:
            with args.json.open("a", encoding="utf-8") as out:
                out.write(json.dumps(row) + "\n")
    print(table(rows))


if __name__ == "__main__":
    main()
