"""An Abaqus input file's model, flattened: each part placed by its instances with every
node, element and set name qualified by the instance ('Leaflet-1.12'), and the model's
materials, orientations, amplitudes, interactions and steps gathered by name. Keywords
this reader does not know are noted with their line, never skipped quietly."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import MeshError
from .inp_syntax import Keyword, read_keywords

#: The most labels the GENERATE lines of a model may give in all (a typo in a range, or
#: many ranges, must not fill the memory).
MAX_GENERATED = 10_000_000
#: Keywords that belong to the *MATERIAL above them.
MATERIAL_OPTIONS = {"density", "elastic", "hyperelastic", "anisotropic hyperelastic", "user material", "depvar",
                    "damping", "plastic", "viscoelastic", "expansion", "hysteresis", "mullins effect",
                    "conductivity", "specific heat", "user defined field"}
#: Keywords of a *SURFACE INTERACTION.
INTERACTION_OPTIONS = {"friction", "surface behavior", "contact damping"}
#: Keywords that ask for printed or written results: shellsim writes its own fields.
OUTPUT_REQUESTS = {"output", "node output", "element output", "energy output", "contact output", "restart",
                   "monitor", "node print", "el print", "node file", "el file", "energy print", "preprint",
                   "print", "file format", "diagnostics", "integrated output", "section print"}
#: Keywords that only open or close a block.
STRUCTURE = {"part", "end part", "assembly", "end assembly", "instance", "end instance", "step", "end step",
             "heading"}
GEOMETRY = {"node", "element", "nset", "elset", "surface", "shell section", "membrane section",
            "shell general section", "solid section", "beam section", "truss section", "orientation",
            "distribution", "distribution table", "nodal thickness"}


@dataclass
class Element:
    """label : qualified label; kind : Abaqus type (upper case); nodes : qualified node labels."""

    label: str
    kind: str
    nodes: list[str]
    where: str


@dataclass
class Named:
    """A set or a surface. items: qualified labels (sets), (label, side) pairs (surfaces)."""

    name: str
    items: list
    kind: str = "element"  # surfaces: 'element' or 'node'


@dataclass
class AbaqusModel:
    """The flattened model; names are looked up lower case."""

    path: Path
    nodes: dict[str, int] = field(default_factory=dict)
    coords: list[np.ndarray] = field(default_factory=list)
    elements: list[Element] = field(default_factory=list)
    nsets: dict[str, Named] = field(default_factory=dict)
    elsets: dict[str, Named] = field(default_factory=dict)
    surfaces: dict[str, Named] = field(default_factory=dict)
    sections: list[tuple[Keyword, str, str]] = field(default_factory=list)  # (section, elset key, prefix)
    orientations: dict[str, tuple[Keyword, str]] = field(default_factory=dict)  # key -> (keyword, prefix)
    distributions: dict[str, tuple[Keyword, str]] = field(default_factory=dict)
    materials: dict[str, tuple[Keyword, list[Keyword]]] = field(default_factory=dict)
    amplitudes: dict[str, Keyword] = field(default_factory=dict)
    interactions: dict[str, list[Keyword]] = field(default_factory=dict)
    model_data: list[Keyword] = field(default_factory=list)  # boundaries and contact outside steps
    steps: list[tuple[Keyword, list[Keyword]]] = field(default_factory=list)
    heading: str = ""
    unmapped: list[str] = field(default_factory=list)
    generated: int = 0  # labels given by GENERATE lines so far
    element_at: dict[str, str] = field(default_factory=dict)  # element label -> where it is defined

    def node_labels(self, token: str, prefix: str, keyword: Keyword) -> list[str]:
        """The qualified node labels a data field names: a node label ('12', or
        'Instance.12' at the assembly) or a node set."""
        label = qualified(prefix, token)
        return [label] if label else list(self._named(self.nsets, token, prefix, keyword, "node set").items)

    def element_labels(self, token: str, prefix: str, keyword: Keyword) -> list[str]:
        """The qualified element labels a data field names: an element label or set."""
        label = qualified(prefix, token)
        return [label] if label else list(self._named(self.elsets, token, prefix, keyword, "element set").items)

    def surface(self, token: str, keyword: Keyword) -> Named:
        return self._named(self.surfaces, token, "", keyword, "surface")

    def key_of(self, table: dict, token: str, prefix: str, keyword: Keyword, what: str) -> str:
        """The lookup key of the name ``token`` in ``table``: the instance's own first."""
        for key in ((prefix + token).lower(), token.lower()):
            if key in table:
                return key
        known = ", ".join(sorted(n.name if isinstance(n, Named) else k for k, n in table.items())[:12]) or "none"
        raise MeshError(f"{keyword.label()}: unknown {what} '{token}' (known: {known})")

    def _named(self, table: dict, token: str, prefix: str, keyword: Keyword, what: str) -> Named:
        return table[self.key_of(table, token, prefix, keyword, what)]


def read_model(path: Path) -> AbaqusModel:
    """The model of the input file ``path``; MeshError naming the line of what cannot be read."""
    model = AbaqusModel(Path(path))
    keywords = read_keywords(path)
    parts: dict[str, list[Keyword]] = {}
    outputs: list[Keyword] = []
    i = 0
    while i < len(keywords):
        k = keywords[i]
        block, i = _block(keywords, i)
        if k.name == "part":
            parts[(k.param("name") or "").lower()] = block[1:]
        elif k.name == "instance":
            _instance(model, k, block[1:], parts)
        elif k.name == "material":
            model.materials[(k.param("name") or "").lower()] = (k, block[1:])
        elif k.name == "surface interaction":
            model.interactions[(k.param("name") or "").lower()] = block[1:]
        elif k.name == "step":
            model.steps.append((k, block[1:]))
        elif k.name == "amplitude":
            model.amplitudes[(k.param("name") or "").lower()] = k
        elif k.name == "heading":
            model.heading = " ".join(", ".join(row) for row in k.rows).strip()
        elif k.name in GEOMETRY:
            _geometry(model, k, prefix="", move=None)
        elif k.name in {"boundary", "contact pair", "contact", "contact inclusions", "contact property assignment",
                        "cload", "dload", "dsload"}:
            model.model_data.append(k)
        elif k.name in OUTPUT_REQUESTS:
            outputs.append(k)
        elif k.name not in STRUCTURE:
            model.unmapped.append(f"{k.label()}: not read by shellsim")
    for _, items in model.steps:
        outputs += [k for k in items if k.name in OUTPUT_REQUESTS]
    if outputs:
        model.unmapped.append(f"output requests ({', '.join(sorted({'*' + k.name.upper() for k in outputs}))}, "
                              f"first at {outputs[0].where}): shellsim writes its own fields; choose them in [output]")
    return model


def _block(keywords: list[Keyword], i: int) -> tuple[list[Keyword], int]:
    """The keywords from ``i`` that belong together, and the index after them: a part or
    an instance to its end, a material or an interaction with its options, a step to its
    end; any other keyword alone."""
    opener = keywords[i].name
    end = {"part": "end part", "instance": "end instance", "step": "end step"}.get(opener)
    options = {"material": MATERIAL_OPTIONS, "surface interaction": INTERACTION_OPTIONS}.get(opener)
    j = i + 1
    if end:
        while j < len(keywords) and keywords[j].name != end:
            j += 1
        if j == len(keywords):
            raise MeshError(f"{keywords[i].label()} has no *{end.upper()}")
        return keywords[i:j], j + 1
    if options:
        while j < len(keywords) and keywords[j].name in options:
            j += 1
    return keywords[i:j], j


def _instance(model: AbaqusModel, k: Keyword, inline: list[Keyword], parts: dict[str, list[Keyword]]) -> None:
    """Place a part (or the instance's own definition) with the instance's name as prefix."""
    name = k.param("name") or ""
    part = (k.param("part") or "").lower()
    if part and part not in parts:
        raise MeshError(f"{k.label()}: unknown part '{k.param('part')}' (parts: {', '.join(sorted(parts)) or 'none'})")
    move = _placement(k)
    for keyword in parts.get(part, []) + inline:
        if keyword.name in GEOMETRY:
            _geometry(model, keyword, prefix=f"{name}.", move=move)
        elif keyword.name not in STRUCTURE:
            model.unmapped.append(f"{keyword.label()}: not read by shellsim (in instance '{name}')")


def _placement(k: Keyword):
    """The instance's data lines as a function of points (n, 3): a translation, then a
    rotation by an angle (degrees) about the axis through two points."""
    rows = [[float(v) for v in row] for row in k.rows]
    shift = np.asarray(rows[0][:3]) if rows else np.zeros(3)
    if len(rows) < 2:
        return lambda x: x + shift
    a, b, angle = np.asarray(rows[1][:3]), np.asarray(rows[1][3:6]), np.radians(rows[1][6])
    axis = (b - a) / np.linalg.norm(b - a)
    cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turn = np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross
    return lambda x: (x + shift - a) @ turn.T + a


def _geometry(model: AbaqusModel, k: Keyword, prefix: str, move) -> None:
    """Take a geometry keyword read inside an instance qualified by ``prefix``."""
    named_as = prefix  # an assembly-level set over one instance's labels keeps its own name
    at = k.param("instance")
    if at is not None:
        prefix = f"{at}."
    if k.name == "node":
        labels = []
        for row, line in zip(k.rows, k.row_lines):
            try:
                label, xyz = int(row[0]), [float(v) for v in (row[1:4] + ["0"] * 3)[:3]]
            except (ValueError, IndexError):
                raise MeshError(f"{k.at(line)}: a node is 'label, x, y, z'; got '{', '.join(row)}'") from None
            labels.append(qualified(prefix, str(label)))
            model.nodes[labels[-1]] = len(model.coords)
            model.coords.append(np.asarray(move(np.asarray([xyz]))[0] if move else xyz, dtype=float))
        _add(model.nsets, k.param("nset"), named_as, labels)
    elif k.name == "element":
        kind = (k.param("type") or "").upper()
        labels = []
        for row, line in zip(k.rows, k.row_lines):
            if not row or not _is_label(row[0]) or not all(_is_label(t) for t in row[1:]):
                raise MeshError(f"{k.at(line)}: an element is 'label, node, node, ...'; got '{', '.join(row)}'")
            labels.append(qualified(prefix, row[0]))
            where = f"{k.where.rsplit(':', 1)[0]}:{line}"
            first = model.element_at.setdefault(labels[-1], where)
            if first != where:
                raise MeshError(f"{k.at(line)}: element {row[0]} is defined a second time (first at {first}); "
                                "an element label names one element")
            model.elements.append(Element(labels[-1], kind, [qualified(prefix, t) for t in row[1:]], where))
        _add(model.elsets, k.param("elset"), named_as, labels)
    elif k.name in ("nset", "elset"):
        _set(model, k, prefix, named_as)
    elif k.name == "surface":
        _surface(model, k, prefix, named_as)
    elif k.name.endswith("section"):
        if k.param("elset") is None:
            raise MeshError(f"{k.label()}: ELSET= names no element set")
        model.sections.append((k, model.key_of(model.elsets, k.param("elset"), prefix, k, "element set"), prefix))
    elif k.name in ("orientation", "distribution"):
        table = model.orientations if k.name == "orientation" else model.distributions
        table[(prefix + (k.param("name") or "")).lower()] = (k, prefix)
    elif k.name != "distribution table":  # the columns' types: only the distributions' values matter
        model.unmapped.append(f"{k.label()}: not read by shellsim")


def _set(model: AbaqusModel, k: Keyword, prefix: str, named_as: str) -> None:
    is_nodes = k.name == "nset"
    name = k.param(k.name)
    if not name:
        raise MeshError(f"{k.label()}: {k.name.upper()}= names no set")
    labels: list[str] = []
    if "generate" in k.params:
        for row, line in zip(k.rows, k.row_lines):
            try:
                first, last, step = (int(v) for v in (row + ["1"])[:3])
            except ValueError:
                raise MeshError(f"{k.at(line)}: GENERATE takes 'first, last, step'; got '{', '.join(row)}'") from None
            model.generated += max(0, (last - first) // max(step, 1) + 1)
            if step < 1 or model.generated > MAX_GENERATED:
                raise MeshError(f"{k.at(line)}: GENERATE from {first} to {last} by {step} is not a range of labels, "
                                f"or takes the model's GENERATE lines past {MAX_GENERATED:,} labels in all")
            labels += [qualified(prefix, str(i)) for i in range(first, last + 1, step)]
    elif is_nodes and k.param("elset"):
        wanted = set(model.element_labels(k.param("elset"), prefix, k))
        labels = [node for e in model.elements if e.label in wanted for node in e.nodes]
    else:
        lookup = model.node_labels if is_nodes else model.element_labels
        labels = [label for row in k.rows for token in row if token for label in lookup(token, prefix, k)]
    _add(model.nsets if is_nodes else model.elsets, name, named_as, labels)


def _surface(model: AbaqusModel, k: Keyword, prefix: str, named_as: str) -> None:
    name = k.param("name")
    if not name:
        raise MeshError(f"{k.label()}: NAME= names no surface")
    kind = (k.param("type") or "element").lower()
    items: list = []
    for row in k.rows:
        side = row[1].upper() if len(row) > 1 else ""
        if kind == "node":
            items += [(label, "") for label in model.node_labels(row[0], prefix, k)]
        else:
            items += [(label, side) for label in model.element_labels(row[0], prefix, k)]
    model.surfaces[(named_as + name).lower()] = Named(named_as + name, items, kind if kind == "node" else "element")


def _add(table: dict[str, Named], name: str | None, prefix: str, labels: list[str]) -> None:
    """Add ``labels`` to the set ``name`` (a set named again grows)."""
    if not name:
        return
    key = (prefix + name).lower()
    if key in table:
        table[key].items.extend(labels)
    else:
        table[key] = Named(prefix + name, list(labels))


def qualified(prefix: str, token: str) -> str | None:
    """The label a data field gives, qualified by its instance ('strip-1.12'; instance
    names, like all Abaqus names, compare without case), or None for a set's name."""
    head, _, tail = token.rpartition(".")
    if _is_label(tail):
        return f"{(head + '.' if head else prefix).lower()}{int(tail)}"
    return None


def _is_label(token: str) -> bool:
    return token.strip().lstrip("+-").isdigit()
