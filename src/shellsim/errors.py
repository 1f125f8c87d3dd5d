"""Errors a user can cause and fix. The CLI prints their message, never a traceback."""

from __future__ import annotations

from collections.abc import Sequence

#: How many ids a message names before it counts the rest.
SHOWN_IDS = 5


def id_list(ids: Sequence[int]) -> str:
    """Ids for a message: '3, 8, 12, 20, 31 and 4 more'."""
    shown = ", ".join(str(int(i)) for i in ids[:SHOWN_IDS])
    return shown + (f" and {len(ids) - SHOWN_IDS} more" if len(ids) > SHOWN_IDS else "")


def place(point: Sequence[float]) -> str:
    """A point for a message: '(0.5, 1, 0)'."""
    return "(" + ", ".join(f"{float(c):.6g}" for c in point) + ")"


class ShellsimError(Exception):
    """Base of every error that is the user's to fix (bad deck, bad mesh, bad output path)."""


class DeckError(ShellsimError):
    """A deck that cannot be read or does not validate.

    Parameters
    ----------
    file : str
        Path of the deck as the user gave it.
    problems : list[str]
        One line per problem, each naming the key path, the value given and what was expected.
    """

    def __init__(self, file: str, problems: list[str]):
        self.file = file
        self.problems = problems
        count = f"{len(problems)} problem{'s' if len(problems) != 1 else ''}"
        lines = "\n".join(f"  - {p}" for p in problems)
        super().__init__(f"{file}: {count}:\n{lines}")


class MeshError(ShellsimError):
    """A mesh that cannot be built, imported or used (wrong element type, folded element...)."""


class OutputError(ShellsimError):
    """Results that cannot be written (unwritable directory, disk full)."""


class NumericalError(ShellsimError):
    """A run that went unstable (NaN, energy blow-up); what it wrote so far is kept."""


class SceneTooLarge(ShellsimError):
    """A valid deck whose scene cannot fit in memory or finish in any reasonable time."""


class StudyError(ShellsimError):
    """A study that cannot go on (its scheduler does not answer) or a job whose worker died."""


class Terminated(KeyboardInterrupt):
    """SIGTERM (what schedulers and ``timeout`` send), handled like Ctrl-C: the run stops,
    its files are closed and its summary is marked interrupted."""

    def __str__(self) -> str:
        return "terminated by SIGTERM"
