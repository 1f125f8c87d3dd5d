"""A study's jobs: one deck variant each, run in whichever process the executor picks,
returning one small row for the report (the run's files stay in its own folder)."""

from __future__ import annotations

import hashlib
import re
import tomllib
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

from ..deck import Deck
from ..errors import DeckError, StudyError
from .schema import Study


@dataclass(frozen=True)
class Job:
    """deck: the deck file; overrides: dotted deck keys and their values; folder: where
    the run writes; expect: how the run should end; balance_within_percent and
    dt_falls_by: the study's checks beyond the references (None: not checked)."""

    family: str
    label: str
    deck: Path
    overrides: dict
    folder: Path
    expect: str = "completed"
    balance_within_percent: float | None = None
    dt_falls_by: float | None = None

    @property
    def key(self) -> str:
        return f"{self.family} / {self.label}"


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-").lower() or "run"


def study_jobs(study: Study, study_path: Path, out_dir: Path) -> list[Job]:
    """Every (deck, variant) of ``study`` as a job writing under ``out_dir/runs``, each in
    a folder of its own and with a row key (family, label) of its own: a deck's family is
    its file name, or its path from the study where decks in other folders share the name;
    names that slug alike ("a b", "a-b") get a short stable hash of themselves. Raises
    StudyError for two variants of one family with the same label."""
    decks = [(entry, (study_path.parent / entry.path).resolve()) for entry in study.deck]
    paths_by_stem: dict[str, set[Path]] = {}
    for entry, deck in decks:
        if not entry.family:
            paths_by_stem.setdefault(deck.stem, set()).add(deck)
    jobs = []
    for entry, deck in decks:
        shared = len(paths_by_stem.get(deck.stem, ())) > 1
        family = entry.family or (_relative(deck, study_path.parent) if shared else deck.stem)
        for variant in entry.variant:
            jobs.append(Job(family, variant.label, deck, dict(variant.set), Path(), variant.expect,
                            study.meta.balance_within_percent, entry.dt_falls_by))
    twice = [key for key, count in Counter((job.family, job.label) for job in jobs).items() if count > 1]
    if twice:
        raise StudyError(f"{study_path}: variant '{twice[0][1]}' of family '{twice[0][0]}' is given twice; its "
                         "rows and runs would overwrite each other: give each a label of its own")
    families = _folder_names({job.family for job in jobs})
    labels = {family: _folder_names({job.label for job in jobs if job.family == family}) for family in families}
    return [replace(job, folder=out_dir / "runs" / families[job.family] / labels[job.family][job.label]) for job in jobs]


def _relative(deck: Path, base: Path) -> str:
    """``deck``'s path from ``base`` without its suffix (absolute where it is not under it)."""
    try:
        return deck.relative_to(base.resolve()).with_suffix("").as_posix()
    except ValueError:
        return deck.with_suffix("").as_posix()


def _folder_names(names: set[str]) -> dict[str, str]:
    """A folder name for each of ``names``: its slug, and where another name slugs alike,
    a short hash of the name itself after it (the same whatever the order)."""
    by_slug: dict[str, set[str]] = {}
    for name in names:
        by_slug.setdefault(_slug(name), set()).add(name)
    return {name: slug if len(alike) == 1 else f"{slug}-{hashlib.sha1(name.encode()).hexdigest()[:6]}"
            for slug, alike in by_slug.items() for name in alike}


def apply_overrides(data: dict, overrides: dict, name: str) -> dict:
    """``data`` (a parsed deck) with each dotted key of ``overrides`` replaced; integer
    parts index arrays of tables ("load.0.value"). Missing tables are created."""
    for dotted, value in overrides.items():
        node = data
        parts = dotted.split(".")
        try:
            for part in parts[:-1]:
                node = node[int(part)] if isinstance(node, list) else node.setdefault(part, {})
            if isinstance(node, list):
                node[int(parts[-1])] = value
            else:
                node[parts[-1]] = value
        except (IndexError, ValueError, TypeError, AttributeError):
            raise DeckError(name, [f"variant key '{dotted}' does not fit the deck"]) from None
    return data


def variant_deck(path: Path, overrides: dict, label: str = "") -> Deck:
    """The deck at ``path`` with ``overrides`` (dotted keys) applied, validated; named
    ``path [label]`` in its messages. Raises DeckError on a broken deck or variant."""
    from ..deck import deck_from_data

    data = apply_overrides(tomllib.loads(path.read_text(encoding="utf-8")), overrides, str(path))
    return deck_from_data(data, f"{path} [{label}]" if label else str(path), path.parent)


def run_job(job: Job) -> dict:
    """Run one job; returns its report row, a failed one when the deck, the variant or its
    files are broken. Nothing a job meets ends its worker: even a library's ``sys.exit``
    becomes the row's message."""
    from ..execute import run_scene
    from ..output.folder import output_folder

    try:
        scene = variant_deck(job.deck, job.overrides, job.label)
        _, summary = run_scene(scene, job.deck, output_folder(job.folder))
    except (Exception, SystemExit) as error:
        return failed_row(job, error)
    return row(job, summary)


#: The columns of a report row, in order.
COLUMNS = ("family", "variant", "method", "status", "expected", "dofs", "elements", "steps", "mean_dt", "wall_time_s",
           "us_per_element_step", "error_percent", "balance_error_percent", "dt_fall", "passed", "message", "folder")


def _identity(job: Job) -> dict:
    return {"family": job.family, "variant": job.label, "expected": job.expect, "folder": str(job.folder)}


def _reference_errors(references: list[dict]) -> list[float | None]:
    """Each reference check's error in percent: of its expected value when its tolerance
    is relative; when it is absolute (a history that passes through zero, like a tip that
    swings back), of the largest expected value checked on the same probe, since an error
    relative to a value near zero says nothing. None where neither is defined."""
    largest: dict[str, float] = {}
    for r in references:
        largest[r["probe"]] = max(largest.get(r["probe"], 0.0), abs(r["expected"]))
    errors = []
    for r in references:
        if r["error"] is None:
            errors.append(None)
        elif r["tolerance"] is None:
            errors.append(None if r["error_percent"] is None else abs(r["error_percent"]))
        else:
            scale = largest[r["probe"]]
            errors.append(100.0 * abs(r["error"]) / scale if scale else None)
    return errors


def _study_checks(job: Job, balance: float, fall: float) -> list[str]:
    """What a completed run misses of the study's own checks, one phrase each."""
    missed = []
    if job.balance_within_percent is not None and not abs(balance) <= job.balance_within_percent:
        missed.append(f"energy balance error {balance:.3g}% beyond {job.balance_within_percent}%")
    if job.dt_falls_by is not None and not fall >= job.dt_falls_by:
        missed.append(f"the time step fell {fall:.3g} times, not {job.dt_falls_by}")
    return missed


def row(job: Job, summary: dict) -> dict:
    """The report's row of a finished run: size, steps, time, the worst reference error,
    the energy balance error and how far the step fell (largest over smallest step); a
    completed run passes when it meets its references and the study's checks (a run cut
    short is not measured)."""
    completed = summary["status"] == "completed"
    errors = [e for e in _reference_errors(summary["reference"]) if e is not None] if completed else []
    balance = summary["energy"]["balance_error_percent"]
    fall = summary["dt"]["max"] / summary["dt"]["min"]
    missed = _study_checks(job, balance, fall) if completed else []
    checked = bool(summary["reference"]) or job.balance_within_percent is not None or job.dt_falls_by is not None
    passed = (all(r["passed"] for r in summary["reference"]) and not missed) if checked and completed else None
    return _identity(job) | {
        "status": summary["status"], "method": summary["method"], "dofs": summary["dofs"],
        "elements": summary["elements"], "steps": summary["steps"],
        "mean_dt": summary["dt"]["mean"], "wall_time_s": summary["wall_time_s"],
        "us_per_element_step": summary["us_per_element_step"],
        "error_percent": max(errors) if errors else None, "balance_error_percent": balance, "dt_fall": fall,
        "passed": passed, "message": "; ".join(missed) or summary["message"] or "",
    }


def as_expected(row: dict) -> bool:
    """Whether a row ended as its variant expects: completed within every reference it
    checked, unstable, or (``missed``) completed outside at least one."""
    if row["expected"] == "missed":
        return row["status"] == "completed" and row["passed"] is False
    return row["status"] == row["expected"] and row["passed"] is not False


def failed_row(job: Job, error: BaseException) -> dict:
    """The row of a job that raised."""
    return dict.fromkeys(COLUMNS) | _identity(job) | {
        "status": "failed", "passed": False, "message": str(error) or type(error).__name__}
