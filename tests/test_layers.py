"""The package is a one-way house: each part imports only from its own floor or those
below it, so a law never reads the element, a kernel never reads the deck and the solver
never imports a writer. Every import is checked, those inside functions too; no module
reaches for another's private names (a leading underscore), by import or attribute."""

from __future__ import annotations

import ast
from pathlib import Path

import shellsim

PACKAGE = Path(shellsim.__file__).parent

#: The floors, lowest first; a module belongs to the floor of its top-level part.
FLOORS = [
    {"__init__", "errors", "table_types", "lanes", "array_copy", "bundles", "compiled_call", "compile_watch",
     "cache_lock", "compile_beside", "curve_tables", "signals", "threads", "mesh_reading", "printable", "memory",
     "fixed_shape"},
    {"tensor3"},
    {"materials"},
    {"element"},
    {"mesh"},
    {"loads"},
    {"measures"},
    {"deck"},
    {"foreign"},
    {"geometry"},
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


#: Private attributes read across modules on purpose: numba's dispatcher cache, whose index
#: compile_beside.py keys (no public way to it), and the LLVM value of a numba array
#: struct that fixed_shape.py builds (``_getvalue``, the way numba's guide to its low-level
#: extension API hands it back).
FOREIGN_PRIVATE = {("compile_beside",): {"_cache", "_index_key", "_cache_file", "_load_index"},
                   ("fixed_shape",): {"_getvalue"}}
#: A named tuple's own methods and os._exit are public, underscore and all.
PUBLIC_UNDERSCORED = {"_replace", "_fields", "_asdict", "_make", "_exit"}


def private_names_used(text: str, here: tuple[str, ...]) -> list[str]:
    """'line: name' for each private name of another module that ``text`` (the module at
    ``here``) imports, or reads as an attribute of anything but self or cls."""
    used = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("shellsim")):
            used += [f"{node.lineno}: {a.name}" for a in node.names if a.name.startswith("_")
                     and not a.name.startswith("__")]
        elif (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
              and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))
              and node.attr not in PUBLIC_UNDERSCORED | FOREIGN_PRIVATE.get(here, set())):
            used.append(f"{node.lineno}: {ast.unparse(node)}")
    return used


def test_no_module_uses_another_s_private_names():
    found = [f"{'/'.join(here)}.py:{use}" for path, here in _modules() for use in private_names_used(path.read_text(), here)]
    assert not found, "\n".join(found)


def test_the_private_name_check_sees_imports_and_attributes():
    here = ("output", "checkpoint")
    assert private_names_used("from ..solver.run import _record\n", here) == ["1: _record"]
    assert private_names_used("x = sim._fresh\n", here) == ["1: sim._fresh"]
    assert private_names_used("x = self._fresh\ny = p._replace(a=1)\nfrom __future__ import annotations\n", here) == []


def test_no_two_parts_import_each_other_in_a_circle():
    """Parts that share a floor may import each other one way only: the graph of imports
    between top-level parts has no circle (the front door's excepted)."""
    edges: dict[str, set[str]] = {}
    for path, here in _modules():
        for part, _ in imported_parts(path.read_text(), here):
            if part != here[0] and (here, part) != FRONT_DOOR and part in FLOOR:
                edges.setdefault(here[0], set()).add(part)
    circles = []

    def visit(part: str, trail: list[str]) -> None:
        for target in sorted(edges.get(part, ())):
            if target in trail:
                circles.append(" -> ".join(trail[trail.index(target):] + [target]))
            elif len(trail) < len(FLOOR):
                visit(target, trail + [target])

    for start in sorted(edges):
        visit(start, [start])
    assert not circles, "\n".join(sorted(set(circles)))
