"""Deck -> Mesh: the scene's geometry built with gmsh (or read from a file) as 9-node quads,
consistently oriented, with directors, nodal thickness and named sets."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..deck import Deck, resolve_mesh_path
from ..deck.references import check_references
from ..errors import MeshError
from ..loads import extend_mesh
from ..mesh import (
    Mesh, NamedSet, averaged_directors, check_mesh, combine_surface_normals, orient_consistently,
    snap_points,
)

__all__ = ["build_mesh"]


def build_mesh(deck: Deck, base_dir: Path | None = None) -> Mesh:
    """The mesh of ``deck``; ``base_dir`` resolves a ``builder = 'file'`` path.

    Directors are the exact surface normals of the built geometry (averaged where patches
    meet); for a file, its own directors or else the averaged element normals; for a
    remeshed surface the averaged element normals, pointing away from its centre.
    Raises MeshError when the mesh cannot be built, a file lacks a set the deck names, or the
    mesh fails the geometric checks.
    """
    g = deck.geometry
    director = thickness = None
    surface_normals: list = []
    cell_vectors: dict[str, np.ndarray] = {}
    point_fields: dict[str, np.ndarray] = {}
    cell_fields: dict[str, np.ndarray] = {}
    lines = np.zeros((0, 2), dtype=np.int64)  # a mesh file's cables
    remeshed = g.builder == "file" and g.surface
    if remeshed:
        from .surfaces import boundary_loops, remesh

        path = resolve_mesh_path(deck, base_dir)
        source = f"surface file '{path}'"
        x, conn = remesh(path, g.element_size)
        sets = boundary_loops(x, conn, g.boundaries, path)
        preferred = x[conn[:, 8]] - x.mean(axis=0)  # outward, for a vessel
    elif g.builder == "file":
        from .importing import read_mesh

        path = resolve_mesh_path(deck, base_dir)
        source = f"mesh file '{path}'"
        imported = read_mesh(path)
        x, conn, sets = imported.x, imported.conn, imported.sets
        director, thickness, cell_vectors = imported.director, imported.thickness, imported.cell_vectors
        lines = imported.lines
        point_fields, cell_fields = imported.point_fields, imported.cell_fields
        preferred = director[conn[:, 8]] if director is not None else None
    else:
        from . import builders
        from .gmsh_extract import extract
        from .session import gmsh_session

        source = f"builder '{g.builder}'"
        with gmsh_session(name=g.builder) as gmsh:
            sketch = builders.Sketch(gmsh)
            hint = builders.BUILDERS[g.builder](sketch, g, deck.mesh, deck.section.thickness)
            sketch.finish()
            x, conn, sets, surface_normals = extract(gmsh, source)
        if g.builder in builders.MAPPED:  # meshed flat, its nodes mapped onto the surface
            x, surface_normals, cell_vectors = builders.MAPPED[g.builder](x, conn, g)
        preferred = hint(x[conn[:, 8]])
    if g.builder == "file":  # a builder makes the sets its deck model declares (tested)
        problems = check_references(deck, {name: s.kind for name, s in sets.items()})
        if problems:
            raise MeshError(f"the deck names sets that {source} does not have:\n"
                            + "\n".join(f"  - {p}" for p in problems))
    conn = orient_consistently(x, conn, preferred)
    if director is None:
        director = combine_surface_normals(averaged_directors(x, conn), surface_normals)
    if thickness is None:
        thickness = np.full(len(x), deck.section.thickness)
    all_elements = np.arange(len(conn))
    sets = sets | {"all": NamedSet("surface", np.unique(conn), elements=all_elements)}
    # on a remeshed surface nobody knows where the nodes are: the nearest within half an element
    sets = sets | snap_points(x, deck.mesh.points, 0.5 * g.element_size if remeshed else None)
    mesh = Mesh(x=x, conn=conn, director=director, thickness=thickness, sets=sets, cell_vectors=cell_vectors,
                point_fields=point_fields, cell_fields=cell_fields, lines=lines)
    check_mesh(mesh, source, deck.section.points_through_thickness)
    return extend_mesh(deck.cable, mesh)

