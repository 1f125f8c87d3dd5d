"""Off-screen pictures with PyVista. Works with no display: VTK renders through EGL."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..element.shape import shape
from ..mesh import Mesh

#: Points drawn along each element edge so curved edges look curved.
EDGE_SAMPLES = 9
SET_COLOURS = ["#e41a1c", "#377eb8", "#4daf4a", "#984ea3", "#ff7f00", "#a65628", "#f781bf",
               "#999999", "#66c2a5", "#fc8d62", "#8da0cb", "#e78ac3"]


def _pyvista() -> Any:
    """pyvista set up for off-screen use (no X server needed)."""
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista

    pyvista.OFF_SCREEN = True
    return pyvista


def quad9_grid(x: np.ndarray, conn: np.ndarray) -> Any:
    """A pyvista UnstructuredGrid of biquadratic quads. Shapes: x (n, 3), conn (ne, 9)."""
    pv = _pyvista()
    cells = np.hstack([np.full((len(conn), 1), 9), conn]).ravel()
    types = np.full(len(conn), pv.CellType.BIQUADRATIC_QUAD, dtype=np.uint8)
    return pv.UnstructuredGrid(cells, types, x)


def element_outlines(x: np.ndarray, conn: np.ndarray) -> Any:
    """Element edges as curved polylines, each sampled at EDGE_SAMPLES points."""
    pv = _pyvista()
    t = np.linspace(-1.0, 1.0, EDGE_SAMPLES)
    # Natural coordinates along each edge of EDGES, walked from its first to its last node.
    one = np.ones_like(t)
    along = [np.column_stack(rs) for rs in ((-t, one), (-one, -t), (t, -one), (one, t))]
    curves = np.concatenate([np.einsum("sa,eai->esi", shape(rs), x[conn]) for rs in along])
    n_lines = len(curves)
    ids = np.arange(n_lines * EDGE_SAMPLES).reshape(n_lines, EDGE_SAMPLES)
    lines = np.hstack([np.full((n_lines, 1), EDGE_SAMPLES), ids]).ravel()
    return pv.PolyData(curves.reshape(-1, 3), lines=lines)


def render_mesh(mesh: Mesh, path: Path, size: tuple[int, int] = (1200, 900)) -> None:
    """PNG of the mesh: surface, element edges, and every edge and point set in its own
    colour with a legend. Flat meshes are seen from above, others isometrically."""
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    surface = quad9_grid(mesh.x, mesh.conn).extract_surface(nonlinear_subdivision=3, algorithm="dataset_surface")
    actor = plotter.add_mesh(surface, color="#d9d9d9", smooth_shading=True)
    actor.mapper.SetResolveCoincidentTopologyToPolygonOffset()  # edges drawn on top of the face
    plotter.add_mesh(element_outlines(mesh.x, mesh.conn), color="black", line_width=3)
    extent = np.ptp(mesh.x, axis=0)
    scale = float(np.linalg.norm(extent)) or 1.0
    legend = []
    named = sorted(((n, s) for n, s in mesh.sets.items() if s.kind != "surface"),
                   key=lambda item: (item[1].kind == "point", item[0]))  # points drawn last, on top
    for i, (name, named_set) in enumerate(named):
        colour = SET_COLOURS[i % len(SET_COLOURS)]
        radius = (0.014 if named_set.kind == "point" else 0.008) * scale
        glyphs = pv.PolyData(mesh.x[named_set.nodes]).glyph(geom=pv.Sphere(radius=radius), scale=False, orient=False)
        plotter.add_mesh(glyphs, color=colour)
        legend.append([f"{name} ({named_set.kind})", colour])
    if legend:
        plotter.add_legend(legend, bcolor="white", face="circle", loc="upper left",
                           size=(0.22, min(0.9, 0.035 * len(legend) + 0.02)))
    flat_axis = int(np.argmin(extent))
    if extent[flat_axis] < 1e-9 * scale:
        plotter.view_vector(np.eye(3)[flat_axis], viewup=np.eye(3)[(flat_axis + 2) % 3])
    else:
        plotter.view_isometric()
    plotter.camera.zoom(0.85)
    plotter.screenshot(str(path))
    plotter.close()
