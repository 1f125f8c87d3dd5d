"""gmsh model -> arrays: contiguous nodes, 9-node connectivity in the element's order, and
named sets from physical groups. The only place that knows gmsh's numbering."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError
from ..mesh import NamedSet

GMSH_QUAD9 = 10
GMSH_LINE3 = 8

#: gmsh's 9-node quadrangle lists its nodes in the same sequence as the thesis' Table 2.1,
#: with reference axes turned half a turn: gmsh (u, v) = (-r, -s), which leaves the normal
#: g_r x g_s unchanged. So element node k is gmsh node GMSH_TO_ELEMENT[k] (tested against
#: gmsh's own element properties).
GMSH_TO_ELEMENT = np.arange(9)

#: gmsh's 3-node line is (end, end, middle); edge sets store (end, middle, end).
GMSH_LINE3_TO_EDGE = np.array([0, 2, 1])


def extract(gmsh: Any, what: str) -> tuple[np.ndarray, np.ndarray, dict[str, NamedSet], list]:
    """Nodes, elements, named sets and exact surface normals of the current gmsh model.

    Parameters
    ----------
    gmsh : the gmsh module inside a session, with a generated second-order mesh.
    what : name of what was built, for messages.

    Returns
    -------
    x : (n, 3) float — positions of the nodes used by the quads, renumbered from 0.
    conn : (ne, 9) int
    sets : name -> NamedSet, one per physical group.
    normals : list of (nodes (k,) int, unit normals (k, 3)), one per CAD surface, each in
        the surface's own (arbitrary) sense.
    """
    tags, coords, _ = gmsh.model.mesh.getNodes()
    coords = coords.reshape(-1, 3)
    types, element_tags, element_nodes = gmsh.model.mesh.getElements(dim=2)
    foreign = [gmsh.model.mesh.getElementProperties(t)[0] for t in types if t != GMSH_QUAD9]
    if foreign or GMSH_QUAD9 not in types:
        raise MeshError(
            f"{what}: gmsh produced {', '.join(foreign) or 'no surface elements'}; "
            "expected only 9-node quadrilaterals"
        )
    k = list(types).index(GMSH_QUAD9)
    quad_tags = element_tags[k]
    conn_tags = element_nodes[k].reshape(-1, 9)[:, GMSH_TO_ELEMENT]

    used = np.unique(conn_tags)
    row_of_tag = np.full(int(tags.max()) + 1, -1)
    row_of_tag[tags] = np.arange(len(tags))
    index_of_tag = np.full(int(tags.max()) + 1, -1)
    index_of_tag[used] = np.arange(len(used))
    x = coords[row_of_tag[used]]
    conn = index_of_tag[conn_tags]
    element_of_tag = {int(t): i for i, t in enumerate(quad_tags)}

    sets: dict[str, NamedSet] = {}
    for dim, group in gmsh.model.getPhysicalGroups():
        name = gmsh.model.getPhysicalName(dim, group)
        entities = gmsh.model.getEntitiesForPhysicalGroup(dim, group)
        if dim == 2:
            elements = np.array(sorted(
                element_of_tag[int(t)]
                for e in entities
                for t in gmsh.model.mesh.getElements(2, e)[1][0]
            ))
            sets[name] = NamedSet("surface", np.unique(conn[elements]), elements=elements)
        elif dim == 1:
            pieces = []
            for e in entities:
                etypes, _, enodes = gmsh.model.mesh.getElements(1, e)
                pieces.append(enodes[list(etypes).index(GMSH_LINE3)].reshape(-1, 3)[:, GMSH_LINE3_TO_EDGE])
            edges = index_of_tag[np.concatenate(pieces)]
            sets[name] = NamedSet("edge", np.unique(edges), edges=edges)
        else:
            nodes = np.concatenate([gmsh.model.mesh.getNodes(0, e)[0] for e in entities])
            sets[name] = NamedSet("point", np.unique(index_of_tag[nodes.astype(int)]))
    return x, conn, sets, _cad_normals(gmsh, index_of_tag)


def _cad_normals(gmsh: Any, index_of_tag: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The CAD surface normal at every node of every surface (boundary nodes included)."""
    pieces = []
    for _, surface in gmsh.model.getEntities(2):
        tags, xyz, _ = gmsh.model.mesh.getNodes(2, surface, includeBoundary=True)
        nodes = index_of_tag[tags.astype(int)]
        keep = nodes >= 0
        uv = gmsh.model.getParametrization(2, surface, xyz)
        normals = np.asarray(gmsh.model.getNormal(surface, uv)).reshape(-1, 3)
        pieces.append((nodes[keep], normals[keep]))
    return pieces
