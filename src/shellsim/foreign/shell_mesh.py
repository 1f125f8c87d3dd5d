"""Another program's shell elements as shellsim's mesh: 3-, 4-, 8- and 9-node elements made
9-node quads (:mod:`.quad_upgrade`), oriented one way with each element's own normal
remembered, and the named sets of the other program's labels made deck sets."""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..errors import SHOWN_IDS, MeshError
from ..mesh import SOURCE_ELEMENT, SOURCE_NODE, ImportedMesh
from ..mesh import NamedSet, averaged_directors, edges_within, element_normals, orient_consistently
from .quad_upgrade import split, upgrade


class ShellMesh:
    """The mesh of a model file's shells and the deck sets made on it.

    Built from node positions by label and elements as (label, node labels); labels are
    the file's (strings). ``x``, ``conn`` (ne, 9) and ``director`` are the mesh; ``parent``
    (ne,) each element's file element (index in the given list; a triangle or a quad beside
    triangles gives several); ``side`` (ne,) +1 where the element's normal is the file's
    (right-hand rule over its corners), -1 where orienting the mesh turned it.
    ``sets`` are the deck sets made so far, ``set_of`` a file name's deck set by key.
    """

    def __init__(self, path: Path, positions: dict[str, np.ndarray], elements: list[tuple[str, list[str], str]]):
        self.path, self.labels = path, [label for label, _, _ in elements]
        self.notes: list[str] = []
        sizes = sorted({len(nodes) for _, nodes, _ in elements})
        if len(sizes) > 1 and sizes != [3, 4]:
            raise MeshError(f"model file '{path}' mixes shells of {' and '.join(map(str, sizes))} nodes; "
                            "bring them to one order before importing")
        used = list(dict.fromkeys(label for _, nodes, _ in elements for label in nodes))
        missing = [label for label in used if label not in positions]
        if missing:
            raise MeshError(f"model file '{path}': elements use nodes that are not defined: {listed(missing)}")
        for label, nodes, where in elements:
            if len(set(nodes)) != len(nodes):
                raise MeshError(f"model file '{path}', element {label} ({where}): a node is repeated: {', '.join(nodes)}")
        self.index_of_label = {label: i for i, label in enumerate(used)}
        x = np.asarray([positions[label] for label in used], dtype=float)
        by_size = {size: [(i, [self.index_of_label[n] for n in nodes]) for i, (_, nodes, _) in enumerate(elements)
                          if len(nodes) == size] for size in sizes}
        corners = {size: np.asarray([c for _, c in rows], dtype=np.int64) for size, rows in by_size.items()}
        order = np.asarray([i for size in sizes for i, _ in by_size[size]])
        if sizes == [9]:
            x9, conn, self.lift, parent = x, corners[9], np.unique, order
        elif sizes[0] == 3:  # triangles: every element split into quads first, so that they meet
            pieces, piece_parent = split(x, corners[3], corners.get(4, np.zeros((0, 4), dtype=np.int64)))
            refined = upgrade(pieces.x, pieces.conn)
            x9, conn, parent = refined.x, refined.conn, order[piece_parent]
            self.lift = lambda nodes: refined.lift(pieces.lift(nodes))
            first = elements[by_size[3][0][0]][2]
            self.notes.append(f"{len(corners[3])} triangle(s) (first at {first}): each split into three quads"
                              + (", and each quad into four, so that they meet the triangles' pieces" if 4 in sizes else ""))
        else:
            refined = upgrade(x, corners[sizes[0]])
            x9, conn, self.lift, parent = refined.x, refined.conn, refined.lift, order
        own_normals = element_normals(x9, conn, np.zeros((1, 2)))[:, 0]
        self.conn = orient_consistently(x9, conn, own_normals)
        self.side = np.where((self.conn == conn).all(axis=1), 1.0, -1.0)
        self.x, self.parent = x9, parent
        self.director = averaged_directors(x9, self.conn)
        pieces_of = defaultdict(list)
        for piece, p in enumerate(parent):
            pieces_of[self.labels[p]].append(piece)
        self.pieces_of = {label: np.asarray(p) for label, p in pieces_of.items()}
        self.sets: dict[str, NamedSet] = {}
        self.set_of: dict[tuple[str, str], str] = {}
        self.point_fields: dict[str, np.ndarray] = {}
        self.cell_vectors: dict[str, np.ndarray] = {}
        self.thickness: np.ndarray | None = None
        self.shell_nodes = len(x9)  # the cables' own nodes come after
        self.lines = np.zeros((0, 2), dtype=np.int64)
        self.line_of_label: dict[str, int] = {}

    def add_lines(self, positions: dict[str, np.ndarray], lines: list[tuple[str, list[str], str]]) -> None:
        """The file's 2-node line elements (label, node labels, where) as cables: their
        nodes that no shell has appended (their directors along the line, which no cable
        uses), the elements as :attr:`lines` (L, 2), found by label in ``line_of_label``."""
        ends = [nodes for _, nodes, _ in lines]
        new = [label for label in dict.fromkeys(n for pair in ends for n in pair) if label not in self.index_of_label]
        missing = [label for label in new if label not in positions]
        if missing:
            raise MeshError(f"model file '{self.path}': line elements use nodes that are not defined: {listed(missing)}")
        for label, nodes, where in lines:
            if nodes[0] == nodes[1]:
                raise MeshError(f"model file '{self.path}', element {label} ({where}): both ends are node {nodes[0]}")
        self.index_of_label |= {label: len(self.x) + i for i, label in enumerate(new)}
        self.lines = np.asarray([[self.index_of_label[a], self.index_of_label[b]] for a, b in ends], dtype=np.int64)
        self.line_of_label = {label: i for i, (label, _, _) in enumerate(lines)}
        self.x = np.vstack([self.x, np.asarray([positions[label] for label in new], dtype=float).reshape(-1, 3)])
        along = self.x[self.lines[:, 1]] - self.x[self.lines[:, 0]]
        director = np.tile([0.0, 0.0, 1.0], (len(new), 1))
        for end in (1, 0):  # each new node along a line it ends
            owner = self.lines[:, end] >= self.shell_nodes
            director[self.lines[owner, end] - self.shell_nodes] = along[owner]
        self.director = np.vstack([self.director, director / np.linalg.norm(director, axis=1, keepdims=True)])

    def line_set(self, labels) -> NamedSet | None:
        """The line set of the file's line elements ``labels`` (None where it names none)."""
        elements = np.unique([self.line_of_label[label] for label in labels if label in self.line_of_label])
        if not len(elements):
            return None
        elements = elements.astype(np.int64)
        return NamedSet("line", np.unique(self.lines[elements]), elements=elements)

    def elements_of(self, labels) -> np.ndarray:
        """The mesh elements (sorted) made from the file's elements ``labels``."""
        pieces = [self.pieces_of[label] for label in labels if label in self.pieces_of]
        return np.unique(np.concatenate(pieces)).astype(np.int64) if pieces else np.zeros(0, dtype=np.int64)

    def labels_of(self, chosen: np.ndarray) -> list[str]:
        """The file's labels of the elements the mesh elements ``chosen`` (mask) come from."""
        return list(dict.fromkeys(self.labels[p] for p in self.parent[chosen]))

    def nodes_of(self, labels, lift: bool = True) -> np.ndarray:
        """The mesh nodes of the file's node ``labels`` and, with ``lift``, the new nodes the
        shells' among them span (a cable's own node spans none)."""
        given = np.unique([self.index_of_label[label] for label in labels if label in self.index_of_label])
        given = given.astype(np.int64)
        shells = given[given < self.shell_nodes]
        return np.union1d(self.lift(shells), given[given >= self.shell_nodes]) if len(shells) and lift else given

    def surface_set(self, elements: np.ndarray) -> NamedSet:
        return NamedSet("surface", np.unique(self.conn[elements]), elements=elements)

    def node_set(self, nodes: np.ndarray) -> NamedSet:
        """A point set, or an edge set where the nodes make element edges."""
        edges = edges_within(self.conn, nodes)
        if len(nodes) > 1 and len(edges):
            return NamedSet("edge", nodes, edges=edges)
        return NamedSet("point", nodes)

    def add_set(self, key: tuple[str, str] | None, wanted: str, named: NamedSet) -> str:
        """Add ``named`` under a deck name made from ``wanted`` (a letter, then letters,
        digits, '_' or '-'), unique; remember it under ``key``. Returns the name."""
        name = deck_name(wanted, "set")
        base, count = name, 1
        while name.lower() in {n.lower() for n in self.sets}:
            count += 1
            name = f"{base}_{count}"
        self.sets[name] = named
        if key is not None:
            self.set_of[key] = name
        return name

    def new_node_set(self, labels: list[str], wanted: str, user: str, lift: bool = True) -> str:
        """A new deck set ``wanted`` of the nodes with the file's ``labels`` (with ``lift``,
        and the new nodes between them); MeshError naming ``user`` when none is a shell's."""
        nodes = self.nodes_of(labels, lift)
        if not len(nodes):
            raise MeshError(f"{user}: names no node of a shell element")
        return self.add_set(None, wanted, self.node_set(nodes))

    def corners_of(self, node: int) -> np.ndarray:
        """The nodes a new node was placed between: an edge's two, a centre's four."""
        e, position = np.argwhere(self.conn == node)[0]
        if position == 8:
            return self.conn[e, :4]
        return self.conn[e, [position - 4, (position - 3) % 4]]

    def imported(self) -> ImportedMesh:
        """The mesh, with the file's node and element numbers as the fields SOURCE_NODE and
        SOURCE_ELEMENT (:meth:`id_map`)."""
        node_ids, element_ids = np.zeros(len(self.x)), np.asarray([number(self.labels[p]) for p in self.parent],
                                                                   dtype=float)
        for label, i in self.index_of_label.items():
            node_ids[i] = number(label)
        return ImportedMesh(self.x, self.conn, self.sets, self.director, self.thickness, self.cell_vectors,
                            self.point_fields | {SOURCE_NODE: node_ids}, {SOURCE_ELEMENT: element_ids}, self.lines)

    def id_map(self) -> list[tuple[str, str, int]]:
        """(kind, the file's label, shellsim's index) of every node ('node'), shell element
        ('element'; a triangle split into quads has several) and cable element ('cable')."""
        rows = [("node", label, i) for label, i in self.index_of_label.items()]
        rows += [("element", self.labels[p], piece) for piece, p in enumerate(self.parent)]
        return rows + [("cable", label, i) for label, i in self.line_of_label.items()]



def number(label: str) -> int:
    """The number a file's label ends in: 12 for 'leaflet-1.12' (an instance's labels
    repeat another's numbers: the id map tells them apart)."""
    return int(label.rpartition(".")[2])


def deck_name(wanted: str, lead: str) -> str:
    """A deck name (a letter, then letters, digits, '_' or '-') from another program's
    name: other characters become '_', and ``lead`` goes first where no letter does."""
    name = re.sub(r"[^A-Za-z0-9_\-]", "_", wanted)
    return name if name[:1].isalpha() else lead + name


def listed(labels: list[str]) -> str:
    """Labels for a message: 'strip-1.3, strip-1.4 and 12 more'."""
    shown = ", ".join(labels[:SHOWN_IDS])
    return shown + (f" and {len(labels) - SHOWN_IDS} more" if len(labels) > SHOWN_IDS else "")
