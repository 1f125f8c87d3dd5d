"""The package is a one-way house: each part imports only from its own floor or those
below it, so a law never reads the element, a kernel never reads the deck and the solver
never imports a writer. Every import is checked, those inside functions too."""

from __future__ import annotations

import ast
from pathlib import Path

import shellsim

PACKAGE = Path(shellsim.__file__).parent

#: The floors, lowest first; a module belongs to the floor of its top-level part.
FLOORS = [
    {"__init__", "errors", "table_types", "lanes", "array_copy", "bundles", "compiled_call", "compile_watch",
     "cache_lock", "compile_beside", "curve_tables", "signals", "threads", "mesh_reading", "printable", "memory"},
    {"tensor3"},
    {"materials"},
    {"element"},
    {"mesh"},
    {"loads"},
    {"deck"},
    {"geometry", "foreign"},
    {"model", "plan"},
    {"solver"},
    {"output", "verify"},
    {"execute", "study", "bench", "imported_deck"},
    {"cli", "__main__", "api"},
]
FLOOR = {part: level for level, parts in enumerate(FLOORS) for part in parts}
#: The one import that runs upward on purpose: the package's front door hands out the
#: Python interface (shellsim.run, ...) on first use.
FRONT_DOOR = (("__init__",), "api")


def imported_parts(text: str, here: tuple[str, ...]) -> set[tuple[str, int]]:
    """(top-level part of the package, line) of every package import in the module text
    ``text`` that stands at ``here`` (its path in the package, e.g. ("materials", "hgo"))."""
    found = set()
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = list(here[:-1])
            base = base[:len(base) - (node.level - 1)]
            target = base + (node.module.split(".") if node.module else [])
            names = [target[0]] if target else [alias.name for alias in node.names]
            found.update((name, node.lineno) for name in names)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("shellsim."):
            found.add((node.module.split(".")[1], node.lineno))
        elif isinstance(node, ast.Import):
            found.update((a.name.split(".")[1], node.lineno) for a in node.names if a.name.startswith("shellsim."))
    return found


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        yield path, path.relative_to(PACKAGE).with_suffix("").parts


def test_every_part_has_a_floor():
    parts = {here[0] for _, here in _modules()}
    assert parts <= set(FLOOR), f"parts without a floor: {sorted(parts - set(FLOOR))}"


def test_no_import_runs_upward():
    upward = []
    for path, here in _modules():
        for part, line in imported_parts(path.read_text(), here):
            if FLOOR.get(part, -1) > FLOOR[here[0]] and (here, part) != FRONT_DOOR:
                upward.append(f"{'/'.join(here)}.py:{line} imports {part} (floor {FLOOR[part]} above {FLOOR[here[0]]})")
    assert not upward, "\n".join(upward)


def test_the_check_reads_relative_and_absolute_imports():
    law = ("materials", "hgo")
    assert imported_parts("from ..solver import run\n", law) == {("solver", 1)}
    assert imported_parts("def f():\n    from ..output.plots import x\n", law) == {("output", 2)}
    assert imported_parts("from . import laws\n", law) == {("materials", 1)}
    assert imported_parts("import shellsim.cli\n", law) == {("cli", 1)}
    assert imported_parts("from .. import errors\n", law) == {("errors", 1)}
    assert imported_parts("from .mesh import Mesh\n", ("model",)) == {("mesh", 1)}
