"""Off-screen pictures with PyVista: the mesh with its named sets, and a field of a run's
results on the deformed shape. Works with no display: VTK renders through EGL."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from ..measures.probes import TENSOR_COMPONENTS, VECTOR_COMPONENTS
from ..element.shape import shape
from ..errors import OutputError, ShellsimError
from .encoding import SYMMETRIC_PAIRS
from .folder import output_folder, refuse_link, replacing
from .units import NODAL_SUFFIX, DisplayUnits
from ..mesh import Mesh

#: Points drawn along each element edge so curved edges look curved.
EDGE_SAMPLES = 9
#: The colour cables are drawn in, over any field.
CABLE_COLOUR = "#7b3f00"
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


#: Camera directions (view vector, view-up) of the named views.
VIEWS = {"top": ((0, 0, 1), (0, 1, 0)), "front": ((0, -1, 0), (0, 0, 1)), "side": ((1, 0, 0), (0, 0, 1))}


#: Shares of the picture's height kept clear of the shape: (bottom, top), for the colour
#: bar and the caption.
FIELD_MARGINS = (0.17, 0.13)
#: The share of the picture's width the shape may fill.
WIDTH_FILLED = 0.94


def _look(plotter: Any, view: str, x: np.ndarray, margins: tuple[float, float] = (0.04, 0.04)) -> None:
    """Point the camera: a named view, isometric, or ('auto') from above a flat scene
    (along its thinnest axis) and isometric otherwise; then frame the points ``x`` (n, 3)
    in parallel projection so they fill the picture's width or its height between the
    ``margins`` (shares of the height kept clear at the bottom and top), whichever is
    reached first."""
    extent = np.ptp(x, axis=0)
    flat_axis = int(np.argmin(extent))
    if view == "auto" and extent[flat_axis] < 1e-9 * (float(np.linalg.norm(extent)) or 1.0):
        plotter.view_vector(np.eye(3)[flat_axis], viewup=np.eye(3)[(flat_axis + 2) % 3])
    elif view in VIEWS:
        plotter.view_vector(*VIEWS[view])
    else:
        plotter.view_isometric()
    plotter.reset_camera()
    camera = plotter.camera
    camera.enable_parallel_projection()
    focal, position = np.asarray(camera.focal_point), np.asarray(camera.position)
    ahead = (focal - position) / np.linalg.norm(focal - position)
    up = np.asarray(camera.up) - np.dot(camera.up, ahead) * ahead
    up /= np.linalg.norm(up)
    right = np.cross(ahead, up)
    across, along = (x - focal) @ right, (x - focal) @ up
    width, height = plotter.window_size
    bottom, top = margins
    half_height = max(0.5 * np.ptp(along) / (1.0 - bottom - top), 0.5 * np.ptp(across) / (WIDTH_FILLED * width / height),
                      1e-12 * (float(np.linalg.norm(extent)) or 1.0))
    # the shape's centre at the middle of the band between the margins
    shift = right * 0.5 * (across.max() + across.min()) + up * (
        0.5 * (along.max() + along.min()) - (bottom - top) * half_height)
    camera.focal_point, camera.position = focal + shift, position + shift
    camera.parallel_scale = half_height
    plotter.renderer.ResetCameraClippingRange()


def render_mesh(mesh: Mesh, path: Path, size: tuple[int, int] = (1200, 900)) -> None:
    """PNG of the mesh: surface, element edges, cables, and every edge, line and point set
    in its own colour with a legend. Flat meshes are seen from above, others isometrically."""
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    surface = quad9_grid(mesh.x, mesh.conn).extract_surface(nonlinear_subdivision=3, algorithm="dataset_surface")
    actor = plotter.add_mesh(surface, color="#d9d9d9", smooth_shading=True)
    actor.mapper.SetResolveCoincidentTopologyToPolygonOffset()  # edges drawn on top of the face
    plotter.add_mesh(element_outlines(mesh.x, mesh.conn), color="black", line_width=3)
    if len(mesh.lines):
        segments = np.column_stack([np.full(len(mesh.lines), 2), mesh.lines]).ravel()
        plotter.add_mesh(pv.PolyData(mesh.x, lines=segments), color=CABLE_COLOUR, line_width=3)
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
    _look(plotter, "auto", mesh.x)
    try:
        with replacing(path) as partial:
            plotter.screenshot(str(partial))
    finally:
        plotter.close()


#: The outer ring of an element's 4 x 4 sub-cell corners (r fastest), closed.
ELEMENT_RING = np.array([0, 1, 2, 3, 7, 11, 15, 14, 13, 12, 8, 4, 0])
#: Columns of a written symmetric tensor (a 3-vector's are the probes' own).
TENSOR_COLUMNS = {name: SYMMETRIC_PAIRS.index(tuple(sorted(pair))) for name, pair in TENSOR_COMPONENTS.items()}
RENDERS_DIR = "renders"


def field_values(point_data: dict, cell_data: dict, field: str, component: str | None) -> tuple[np.ndarray, bool, str]:
    """(values, on_cells, component) of a scalar picked from a frame: a scalar field as it
    is, a vector's component (magnitude by default), a tensor's component (xx by default)."""
    on_cells = field in cell_data
    if not on_cells and field not in point_data:
        known = sorted({*point_data, *cell_data})
        raise OutputError(f"field '{field}' is not in the results; written fields: {', '.join(known)}")
    values = np.asarray((cell_data if on_cells else point_data)[field], dtype=float)
    columns = values.shape[1] if values.ndim == 2 else 1
    named = {1: {}, 3: VECTOR_COMPONENTS | {"magnitude": None}, 6: TENSOR_COLUMNS}[columns]
    if columns == 1:
        if component is not None:
            raise OutputError(f"field '{field}' is a scalar; leave out the component")
        return values.reshape(-1), on_cells, ""
    component = (component or ("xx" if columns == 6 else "magnitude")).lower()
    if columns == 6 and len(component) == 2:  # XZ as files and ParaView name it, zx as probes do
        component = next((name for name in named if sorted(name) == sorted(component)), component)
    if component not in named:
        raise OutputError(f"component '{component}' does not fit field '{field}'; expected one of {', '.join(named)}")
    column = named[component]
    return (np.linalg.norm(values, axis=1) if column is None else values[:, column]), on_cells, component


def _series_units(folder: Path) -> tuple[str, DisplayUnits]:
    """(title, units shown) of the deck a results folder was run from, if it is there."""
    from ..deck.resolved import read_resolved

    try:
        deck = read_resolved(folder)
    except ShellsimError:  # a series without its deck is still drawn, without units
        return "", DisplayUnits()
    return deck.meta.title, DisplayUnits.of(deck)


def _frame_indices(frame: str | int, count: int) -> list[int]:
    if frame == "all":
        return list(range(count))
    if frame == "last":
        return [count - 1]
    index = int(frame)
    if not -count <= index < count:
        raise OutputError(f"frame {index} does not exist; the series has frames 0 to {count - 1}")
    return [index % count]


class Overlays(NamedTuple):
    """What a field render draws besides the field: each fibre family as a short line
    through each element's centre (from the ``fibre_<k>`` cell vectors), and the initial
    shape's element outlines in grey."""

    fibres: bool = False
    outline: bool = False


class Drawn(NamedTuple):
    """The overlays' data for one frame: the initial points (P, 3) whose element outlines
    are drawn, or None, each fibre family's cell vectors (C, 3), and the cables: their
    points now (m, 3) and lines (L, 2), or None."""

    initial: np.ndarray | None = None
    fibres: tuple[np.ndarray, ...] = ()
    cables: tuple[np.ndarray, np.ndarray] | None = None



NO_OVERLAYS = Overlays()


def _finite_or_missing(values: np.ndarray) -> np.ndarray:
    """values with every infinity made NaN: missing, drawn grey, as a value that is not
    there (a contact gap beyond the search) is; an element crushed in a run that then
    broke down has an infinite stress, which would otherwise take the whole scale."""
    return np.where(np.isfinite(values), values, np.nan)


#: The share of the values (percent) the colour bar may leave out at each end by default:
#: one stray sub-cell (a clamp's corner, a single crushed element) does not take the scale.
CLIPPED_PERCENT = 1.0
#: A clipped bar is kept only where the whole range is this much wider (a share of the
#: clipped one); otherwise the bar spans every value.
CLIPPING_WORTH = 0.1


class Limits(NamedTuple):
    """The colour bar's ``low`` and ``high`` and what it says of them: ``note`` is '' when
    it spans every value drawn, otherwise the values' whole range it leaves out."""

    low: float
    high: float
    note: str = ""


def colour_limits(fields: list[np.ndarray], scale: str | tuple[float, float] = "robust",
                  unit: str = "") -> Limits:
    """The colour bar's limits over the values of every frame drawn, NaN left out:
    ``scale`` "robust" spans the CLIPPED_PERCENT to 100 - CLIPPED_PERCENT percentiles
    where the whole range is more than CLIPPING_WORTH wider (and there are values enough
    for a percent of them to be one), "full" every value, a pair
    (low, high) itself. A flat field still gets a scale around its value, and none at
    all (0, 0) widened. ``unit`` is named in the note of what the clipping left out."""
    finite = np.concatenate([np.ravel(v)[np.isfinite(np.ravel(v))] for v in fields] or [np.zeros(0)])
    if not isinstance(scale, str):
        return Limits(*map(float, scale))
    if not len(finite):
        finite = np.zeros(1)
    low, high = float(finite.min()), float(finite.max())
    if high - low <= 1e-12 * max(abs(low), abs(high), 1e-300):
        return Limits(low - 0.5 * max(abs(low), 1.0), high + 0.5 * max(abs(high), 1.0))
    if scale == "robust" and len(finite) >= 100 / CLIPPED_PERCENT:  # fewer: the tail holds no whole value
        clipped = [float(v) for v in np.percentile(finite, [CLIPPED_PERCENT, 100.0 - CLIPPED_PERCENT])]
        if (high - low) > (1.0 + CLIPPING_WORTH) * (clipped[1] - clipped[0]):
            return Limits(*clipped, f"colours span the middle {100 - 2 * CLIPPED_PERCENT:g}% of the values; "
                                    f"all lie in {low:.4g} to {high:.4g}{' ' + unit if unit else ''}")
    return Limits(low, high)


def render_field(folder: Path, field: str = "pressure_band", frame: str | int = "last", view: str = "iso",  # noqa: PLR0913 (the render command's options, each defaulted)
                 size: tuple[int, int] = (1200, 900), component: str | None = None,
                 out_dir: Path | None = None, overlays: Overlays = NO_OVERLAYS,
                 on_frame: Callable[[int, int], None] = lambda done, total: None,
                 scale: str | tuple[float, float] = "robust") -> list[Path]:
    """PNGs of ``field`` on the deformed shape for the chosen frames of the series in
    ``folder`` ('last', 'all' or a frame number), plus an animated GIF for 'all'; written
    to ``out_dir`` (default ``folder/renders``), with the ``overlays``, the colours over
    ``scale`` (:func:`colour_limits`; a pair in the units shown). ``on_frame(done,
    total)`` hears of each picture written. Returns the files written."""
    from .fields import is_fibre_direction
    from .series import CABLES, StoredSeries

    series = StoredSeries(folder)
    cables = StoredSeries(folder, CABLES) if (folder / f"{CABLES}.xdmf").exists() or (
        folder / f"{CABLES}.pvd").exists() else None
    indices = _frame_indices(frame, len(series.times))
    frames = [series.frame(i) for i in indices]
    title, units = _series_units(folder)
    picked = [(_finite_or_missing(units.scale(field) * values), on_cells, part)
              for values, on_cells, part in (field_values(p, c, field, component) for p, c in frames)]
    limits = colour_limits([v for v, _, _ in picked], scale, units.unit(field))
    label = (field.removesuffix(NODAL_SUFFIX).replace("_", " ").replace("von mises", "von Mises")
             + (", nodal" if field.endswith(NODAL_SUFFIX) else ""))
    part = picked[0][2]  # a tensor's component as files and ParaView name it: XZ, not zx
    bar = units.label(f"{label} {''.join(sorted(part)).upper() if part in TENSOR_COLUMNS else part}".strip(), field)
    out_dir = output_folder(out_dir or refuse_link(folder / RENDERS_DIR))
    stem = f"{field}{'_' + picked[0][2] if picked[0][2] else ''}_{view}"
    written = []
    if overlays.fibres and not any(map(is_fibre_direction, frames[0][1])):
        raise OutputError(f"the series in '{folder}' holds no fibre directions; write them with "
                          "output.fields = [..., 'fibres'] (a fibre-reinforced material)")
    stem += "".join(f"_{name}" for name, shown in overlays._asdict().items() if shown)
    for index, (point_data, cell_data), (values, on_cells, _) in zip(indices, frames, picked):
        path = out_dir / f"{stem}_{index:04d}.png"
        deformed = series.points + np.asarray(point_data.get("displacement", 0.0))
        fibres = tuple(v for name, v in sorted(cell_data.items()) if overlays.fibres and is_fibre_direction(name))
        chords = None
        if cables is not None:  # written with the shells' frames, frame for frame
            chords = (cables.points + np.asarray(cables.frame(index)[0]["displacement"]), cables.cells)
        caption = [title, f"t = {units.scale('time') * series.times[index]:.4g} {units.unit('time')}".strip()]
        if overlays.outline:  # the initial shape drawn where it was: say how far the body moved as a whole
            drift = np.linalg.norm(np.mean(deformed - series.points, axis=0)) * units.scale("length")
            caption.append(f"grey: the initial shape (the body's centre has moved {drift:.3g} "
                           f"{units.unit('length')})".replace(" )", ")"))
        _render_frame(deformed, series, Colouring(values, on_cells, bar, limits), view, size,
                      "\n".join(filter(None, caption + [limits.note])), path,
                      Drawn(series.points if overlays.outline else None, fibres, chords))
        written.append(path)
        on_frame(len(written), len(indices))
    if frame == "all":
        import imageio.v3 as iio

        gif = out_dir / f"{stem}.gif"
        with replacing(gif) as partial:
            iio.imwrite(partial, np.stack([iio.imread(p) for p in written]), duration=200, loop=0)
        written.append(gif)
    return written


def deck_renders(scene, folder: Path) -> list[Path]:
    """The renders a deck's [[output.render]] tables ask for, from the series in
    ``folder``; returns the files written."""
    return [path for picture in scene.output.render
            for path in render_field(folder, picture.field, picture.frame, picture.view, picture.size,
                                     overlays=Overlays(picture.fibres, picture.outline), scale=picture.range)]


class Colouring(NamedTuple):
    """A field's values on the sub-cells (``on_cells``) or their corners, the scalar bar's
    title and its limits."""

    values: np.ndarray
    on_cells: bool
    bar: str
    limits: Limits


#: About how far apart (pixels, on a shape that fills the picture) fibre ticks are drawn:
#: sparse enough that the field shows between them.
FIBRE_PIXELS = 45


def _quad_areas(quads: np.ndarray) -> np.ndarray:
    """Areas (m,) of quadrilaterals (m, 4, 3): half the cross product of their diagonals."""
    return 0.5 * np.linalg.norm(np.cross(quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 1]), axis=1)


def _spread(points: np.ndarray, spacing: float) -> np.ndarray:
    """Indices of ``points`` (m, 3), in order, each at least ``spacing`` from those kept
    before it: a cover of the shape at about that spacing."""
    cells: dict[tuple, list[int]] = {}
    kept = []
    for i, cell in enumerate(map(tuple, np.floor(points / spacing).astype(np.int64))):
        near = (cells.get((cell[0] + a, cell[1] + b, cell[2] + c), ()) for a in (-1, 0, 1) for b in (-1, 0, 1)
                for c in (-1, 0, 1))
        if all(np.linalg.norm(points[j] - points[i]) >= spacing for group in near for j in group):
            cells.setdefault(cell, []).append(i)
            kept.append(i)
    return np.asarray(kept, dtype=np.int64)


#: The fields' colour map: perceptually uniform, so equal steps in value look equal.
COLOUR_MAP = "viridis"
#: Colours of the fibre families' lines.
FIBRE_COLOURS = ["black", "white", "magenta"]


def _render_frame(points: np.ndarray, series, colouring: Colouring, view: str, size: tuple[int, int], caption: str,
                  path: Path, drawn: Drawn) -> None:
    """One PNG: the sub-cells at ``points`` coloured by ``colouring``, element outlines on
    top; the ``drawn`` overlays: the initial shape's outlines in grey, each fibre family as
    lines through the elements' centres, and the cables."""
    values, on_cells, bar, (low, high, _) = colouring
    pv = _pyvista()
    cell_type = pv.CellType.HEXAHEDRON if series.cell_type == "hexahedron" else pv.CellType.QUAD
    grid = pv.UnstructuredGrid({cell_type: series.cells}, points)
    if on_cells:
        grid.cell_data["values"] = values
    else:
        grid.point_data["values"] = values
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    field_actor = plotter.add_mesh(
        grid, scalars="values", clim=(low, high), cmap=COLOUR_MAP, preference="cell" if on_cells else "point",
        scalar_bar_args={"title": bar, "color": "black", "vertical": False, "fmt": "%.4g", "position_x": 0.2,
                         "position_y": 0.02, "width": 0.6, "height": 0.12, "n_labels": 5,
                         "title_font_size": max(10, size[1] // 40), "label_font_size": max(8, size[1] // 50)})
    field_actor.mapper.SetResolveCoincidentTopologyToPolygonOffset()  # lines on the surface drawn in front
    plotter.scalar_bar.SetTextPositionToPrecedeScalarBar()  # the tick labels under the bar, its title under them
    rings = np.arange(0, len(points), 16)[:, None] + ELEMENT_RING[None]
    lines = np.hstack([np.full((len(rings), 1), len(ELEMENT_RING)), rings]).ravel()
    plotter.add_mesh(pv.PolyData(points, lines=lines), color="black", line_width=2)
    if drawn.initial is not None:
        plotter.add_mesh(pv.PolyData(drawn.initial, lines=lines), color="#808080", line_width=1)
    if drawn.fibres:  # through the centre sub-cells (q = 4) of elements spread over the shape
        middle = np.flatnonzero(np.arange(len(series.cells)) % 9 == 4)
        faces = series.cells[middle, 4:] if series.cell_type == "hexahedron" else series.cells[middle]  # top faces
        centres = points[faces].mean(axis=1)
        # the centre sub-cell spans 4/9 of the element each way: the element's area from it
        element_area = _quad_areas(points[faces]) / (4.0 / 9.0) ** 2
        # the solid view has ne * nt * 9 cells on ne * (nt + 1) * 16 points: each element's centre nt times
        layers = len(middle) / (len(points) // 16 - len(series.cells) // 9) if series.cell_type == "hexahedron" else 1
        spacing = np.sqrt(element_area.sum() / layers / (size[0] * size[1] / FIBRE_PIXELS ** 2))
        kept = _spread(centres, spacing)
        centres, count = centres[kept], len(kept)
        segments = np.column_stack([np.full(count, 2), np.arange(count), np.arange(count) + count]).ravel()
        for family, every in enumerate(drawn.fibres):
            directions = every[middle[kept]]
            ends = np.concatenate([centres - 0.35 * spacing * directions, centres + 0.35 * spacing * directions])
            plotter.add_mesh(pv.PolyData(ends, lines=segments), color=FIBRE_COLOURS[family % len(FIBRE_COLOURS)],
                             line_width=2)
    if drawn.cables is not None:
        at, ends = drawn.cables
        segments = np.column_stack([np.full(len(ends), 2), ends]).ravel()
        plotter.add_mesh(pv.PolyData(at, lines=segments), color=CABLE_COLOUR, line_width=3)
        points = np.vstack([points, at])  # the view takes them in
    plotter.add_text(caption, position="upper_left", font_size=max(9, size[1] // 70), color="black")
    _look(plotter, view, points, FIELD_MARGINS)
    try:
        with replacing(path) as partial:
            plotter.screenshot(str(partial))
    finally:
        plotter.close()
