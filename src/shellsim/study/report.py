"""The study report: ``report.md`` (a table), ``report.csv`` and ``error_vs_time.png``
(log-log, one curve per deck family, points labelled by variant, other programs' points
beside ours), each rewritten atomically as rows arrive; and the table embedded in a
document between two marker comments, so a record like docs/verification.md is
rewritten by the run that measures it."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from ..errors import DeckError, OutputError
from ..output.folder import write_atomically
from .jobs import COLUMNS, as_expected

EXTERNAL_COLUMNS = ("family", "program", "label", "error_percent", "wall_time_s")


def read_external(path: Path) -> list[dict]:
    """Other programs' points: rows of EXTERNAL_COLUMNS, numbers parsed."""
    try:
        with open(path, newline="", encoding="utf-8") as file:
            rows = list(csv.DictReader(file))
    except OSError as error:
        raise DeckError(str(path), [f"cannot be read: {error.strerror or error}"]) from None
    missing = [c for c in EXTERNAL_COLUMNS if rows and c not in rows[0]]
    if missing:
        raise DeckError(str(path), [f"missing columns: {', '.join(missing)}"])
    try:
        return [r | {"error_percent": float(r["error_percent"]), "wall_time_s": float(r["wall_time_s"])} for r in rows]
    except ValueError as error:
        raise DeckError(str(path), [f"not a number: {error}"]) from None


def _cell(value) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value).replace("|", "/").replace("\n", " ")


def table(rows: list[dict]) -> str:
    """The markdown table of ``rows``."""
    header = ("deck", "variant", "method", "status", "DOFs", "steps", "mean dt", "wall time [s]", "us/element-step",
              "error [%]", "balance [%]", "dt max/min", "passed", "note")
    keys = ("family", "variant", "method", "status", "dofs", "steps", "mean_dt", "wall_time_s", "us_per_element_step",
            "error_percent", "balance_error_percent", "dt_fall", "passed", "message")
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        shown = r | {"status": r["status"] + ("" if as_expected(r) else f" (expected {r['expected']})")}
        if r["expected"] == "missed" and as_expected(r):
            shown["message"] = "misses its references, as expected of this coarse mesh"
        lines.append("| " + " | ".join(_cell(shown[k]) for k in keys) + " |")
    return "\n".join(lines) + "\n"


def markdown(title: str, rows: list[dict], pending: int, interrupted: bool = False) -> str:
    """report.md: the title, what the columns mean, how many jobs are still running (or,
    the study ``interrupted``, did not finish), the table."""
    lines = [f"# {title}", "", "Error: the largest relative error over the deck's references (closed-form or "
             "literature values cited in each deck); a check with an absolute tolerance counts its error against "
             "the largest value checked on its probe. Balance: the energy balance error, percent of the largest "
             "energy. Wall time: the whole run, one process per job.", ""]
    if pending:
        lines += [f"*Interrupted: {pending} job(s) did not finish and have no row.*" if interrupted else
                  f"*{pending} job(s) still running.*", ""]
    return "\n".join(lines) + "\n" + table(rows)


def _markers(key: str) -> tuple[str, str]:
    return f"<!-- report {key} -->", f"<!-- end report {key} -->"


def embed_span(document: Path, key: str) -> tuple[str, int, int]:
    """(text of ``document``, start, end) of the span between its two markers for ``key``;
    raises OutputError, before any job runs, when the document or a marker is missing."""
    begin, end = _markers(key)
    try:
        text = document.read_text(encoding="utf-8")
    except OSError as error:
        raise OutputError(f"{document}: cannot be read: {error.strerror or error}") from None
    start, stop = text.find(begin), text.find(end)
    if start < 0 or stop < start:
        raise OutputError(f"{document}: the report goes between the lines '{begin}' and '{end}'; "
                          "add them where the table belongs")
    return text, start + len(begin), stop


def embed(document: Path, key: str, rows: list[dict]) -> None:
    """Replace the span between ``document``'s markers for ``key`` with the table of ``rows``."""
    text, start, stop = embed_span(document, key)
    write_atomically(document, text[:start] + "\n" + table(rows) + text[stop:])


def csv_text(rows: list[dict]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


def error_vs_time_png(title: str, rows: list[dict], external: list[dict]) -> bytes:
    """Log-log error against wall time: one line per family and method in ladder order
    (static rungs dashed, in their family's colour), each point labelled with its variant;
    other programs' points as open markers."""
    from matplotlib import colormaps
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8.5, 6.5), layout="constrained")
    ax = figure.subplots()
    families = list(dict.fromkeys(r["family"] for r in rows))
    colours = colormaps["tab20"].colors  # 20 colours and 7 markers: no two families look alike
    for index, family in enumerate(families):
        for method in dict.fromkeys(r["method"] for r in rows if r["family"] == family):
            done = [r for r in rows if r["family"] == family and r["method"] == method and r["error_percent"]
                    and r["wall_time_s"]]
            if not done:
                continue
            static = method == "static"
            line, = ax.plot([r["wall_time_s"] for r in done], [r["error_percent"] for r in done],
                            "--" if static else "-", marker="os^Dv<>"[index % 7], color=colours[index % len(colours)],
                            label=f"{family}, static" if static else family)
            for r in done:
                ax.annotate(r["variant"], (r["wall_time_s"], r["error_percent"]), textcoords="offset points",
                            xytext=(4, 4), fontsize="x-small", color=line.get_color())
    for program in dict.fromkeys(e["program"] for e in external):
        points = [e for e in external if e["program"] == program]
        ax.plot([e["wall_time_s"] for e in points], [e["error_percent"] for e in points], "s", mfc="none",
                label=f"{program} (external)")
        for e in points:
            ax.annotate(f"{e['family']} {e['label']}", (e["wall_time_s"], e["error_percent"]),
                        textcoords="offset points", xytext=(4, -8), fontsize="x-small")
    if ax.lines:
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel("largest reference error (%)")
    ax.grid(alpha=0.3, which="both")
    if ax.lines:
        figure.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncols=3, fontsize="small")
    figure.suptitle(title, fontsize="medium")
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110)
    return buffer.getvalue()


def write_report(out_dir: Path, title: str, rows: list[dict], pending: int, external: list[dict],
                 interrupted: bool = False) -> None:
    """report.md, report.csv and error_vs_time.png in ``out_dir`` for the rows so far
    (``pending`` jobs without one; see :func:`markdown`)."""
    write_atomically(out_dir / "report.md", markdown(title, rows, pending, interrupted))
    write_atomically(out_dir / "report.csv", csv_text(rows))
    write_atomically(out_dir / "error_vs_time.png", error_vs_time_png(title, rows, external))
