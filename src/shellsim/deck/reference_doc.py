"""The deck reference (docs/decks.md), written from the deck models themselves so it
cannot drift from what the program accepts. Regenerate with
``python -m shellsim.deck.reference_doc > docs/decks.md``."""

from __future__ import annotations

import inspect

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from . import schema
from .curves import Curve
from .geometry import BUILDERS
from ..materials.axes import CentrelineAxes, CylindricalAxes, FixedAxes, MeshAxes
from .material import MATERIALS
from ..loads import CABLE_TABLES, CONTACT_TABLES
from ..loads.cable_laws import CABLE_LAWS
from ..loads import TABLES as LOAD_TABLES
from ..measures import FAMILIES
from ..table_types import tag_of

INTRO = """# Deck reference

A deck is one TOML file describing one scene. Tables may come in any order; unknown keys
are errors; a deck states only what its scene needs and everything else takes the default
shown. Units are whatever the deck uses consistently: `[meta] units` is only a label.

This page is generated from the deck models (`python -m shellsim.deck.reference_doc`).
"""


def _tag(cls: type[BaseModel]) -> str:
    """The discriminating value of a union member (builder, model, type, kind)."""
    return tag_of(cls)[1]


def _toml(value) -> str:
    """A default as a deck writes it: "text", true, [1.0, 2.0], { key = 1 }."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(map(_toml, value)) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + " }" if value else "{}"
    return repr(value)


def _default(field, name: str, heading: str) -> str:
    if field.default is PydanticUndefined and field.default_factory is None:
        return "required"
    value = field.default_factory() if field.default_factory is not None else field.default
    table = f"[{heading.strip('#[] ')}.{name}]"
    if isinstance(value, BaseModel):
        return f"the table `{table}` below, each key defaulted"
    if value is None and _subtable(field) is not None:
        return f"none: off unless `{table}` (below) is given"
    return "none" if value is None else f"`{_toml(value)}`"


def _subtable(field) -> type[BaseModel] | None:
    """The table class an optional key takes (``MassScaling | None``), or None."""
    arguments = getattr(field.annotation, "__args__", ())
    return next((a for a in arguments if isinstance(a, type) and issubclass(a, BaseModel)), None)


def _table(cls: type[BaseModel], heading: str, skip_tag: bool = False) -> list[str]:
    rows = [f"{heading}", "", inspect.cleandoc(cls.__doc__ or ""), "", "| key | default |", "|---|---|"]
    tag = tag_of(cls)
    names = [n for n in cls.model_fields if not (skip_tag and tag and n == tag[0])]
    rows += [f"| `{name}` | {_default(cls.model_fields[name], name, heading)} |" for name in names]
    return rows + [""]


def deck_reference() -> str:
    """The whole reference as Markdown."""
    lines = [INTRO]
    lines += _table(schema.Meta, "## [meta]")
    lines += ["## [geometry]", "", "Chosen by `builder`; every mesh also has the surface set `all`.", ""]
    for cls in BUILDERS.values():
        lines += _table(cls, f'### builder = "{_tag(cls)}"', skip_tag=True)
        if cls.DIVISIONS:
            lines += ["`[mesh] divisions` and their defaults: "
                      + ", ".join(f"`{k} = {v}`" for k, v in cls.DIVISIONS.items()), ""]
    lines += _table(schema.MeshOptions, "## [mesh]")
    lines += ["## [material] (one) or [[material]] (a material per part)", "",
              "Chosen by `model`. One `[material]` table covers every element; with several "
              "`[[material]]` tables each names the surface sets it covers in `sets` (every element in "
              "exactly one), its law, constants, density and axes its own. The parts share `[section]` "
              "and its technique.", ""]
    for cls in MATERIALS.values():
        lines += _table(cls, f'### model = "{_tag(cls)}"', skip_tag=True)
    lines += ["Material axes (`axes`), chosen by `kind`:", ""]
    for cls in (CylindricalAxes, CentrelineAxes, FixedAxes, MeshAxes):
        lines += _table(cls, f'#### kind = "{_tag(cls)}"', skip_tag=True)
    lines += _table(schema.ShellSection, "## [section]")
    lines += ["## [[boundary]]", "", "Chosen by `type`.", ""]
    for cls in (schema.Clamped, schema.Fixed, schema.Symmetry, schema.Prescribed):
        lines += _table(cls, f'### type = "{_tag(cls)}"', skip_tag=True)
    lines += ["## [[load]]", "", "Chosen by `type`; a load is `value * curve(t)`, constant without a curve "
              "(growing from 0 over a static solve).", ""]
    for cls in LOAD_TABLES:
        lines += _table(cls, f'### type = "{_tag(cls)}"', skip_tag=True)
    lines += ["## [[contact]]", "", "Chosen by `type`; the shell's faces against what they may not pass.", ""]
    for cls in CONTACT_TABLES:
        lines += _table(cls, f'### type = "{_tag(cls)}"', skip_tag=True)
    for cls in CABLE_TABLES:
        lines += _table(cls, "## [[cable]]")
    lines += ["Its `law`, chosen by `model` (nominal stress P, force per initial cross-section, at the "
              "stretch lambda; nothing in compression):", ""]
    for cls in CABLE_LAWS:
        lines += _table(cls, f'#### model = "{_tag(cls)}"', skip_tag=True)
    lines += _table(Curve, "## [curves.NAME]")
    lines += _table(schema.Solver, "## [solver]")
    for name in ("static", "implicit", "mass_scaling", "relaxation", "imaged"):
        field = schema.Solver.model_fields[name]
        lines += _table(_subtable(field) or type(field.default), f"### [solver.{name}]")
    lines += _table(schema.Output, "## [output]")
    lines += _table(schema.Render, "## [[output.render]]")
    for family in FAMILIES:
        if hasattr(family, "TABLE"):
            many = family.OUTPUT_FIELD[1] == []
            lines += _table(family.TABLE, f"## [[output.{family.OUTPUT_KEY}]]" if many else f"## [output.{family.OUTPUT_KEY}]")
    lines += _table(schema.Reference, "## [reference] (one) or [[reference]] (several)")
    return "\n".join(lines).rstrip() + "\n"


if __name__ == "__main__":  # pragma: no cover
    print(deck_reference(), end="")
