"""Scene geometries built with gmsh's built-in kernel as structured (transfinite) patches.

Each builder draws its mid-surface, sets element divisions on every curve and names the
sets its ``[geometry]`` model declares (:meth:`shellsim.deck.geometry.Rectangle.sets` and
siblings). Curved patches are exact: circle arcs, cylinders filled by transfinite
interpolation of arcs and straight lines, and sphere patches filled with gmsh's spherical
filling, so second-order nodes lie on the true surface. The pre-twisted strip is meshed
flat and its nodes mapped exactly onto the helicoid (gmsh's twist extrusion puts the
second-order nodes off it).

A builder returns an *orientation hint*: a function of positions (n, 3) giving the
direction (n, 3) the shell normal, and so the directors, should point to.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..deck.geometry import (
    AnnularSector, AorticValve, CylindricalPanel, Hemisphere, PlateWithHole, Rectangle, Tube, TwistedStrip,
)
from ..deck.schema import MeshOptions
from ..memory import refuse_if_too_big

Hint = Callable[[np.ndarray], np.ndarray]


def _up(x: np.ndarray) -> np.ndarray:
    return np.broadcast_to([0.0, 0.0, 1.0], x.shape)


class Sketch:
    """Points, curves with their element counts, structured patches and named groups in the
    built-in kernel. A curve asked for twice (either way round) is created once, so
    neighbouring patches share it and the mesh is conforming."""

    def __init__(self, gmsh: Any):
        self.gmsh = gmsh
        self.geo = gmsh.model.geo
        self._curves: dict[frozenset, tuple[int, int, int]] = {}
        self._groups: dict[tuple[int, str], list[int]] = {}
        self.elements = 0  # the patches' elements, known before gmsh meshes them

    def point(self, xyz: tuple[float, float, float] | np.ndarray) -> int:
        return self.geo.addPoint(*map(float, xyz))

    def line(self, a: int, b: int, divisions: int) -> int:
        return self._curve(a, b, divisions, lambda: self.geo.addLine(a, b))

    def arc(self, a: int, centre: int, b: int, divisions: int) -> int:
        return self._curve(a, b, divisions, lambda: self.geo.addCircleArc(a, centre, b))

    def _curve(self, a: int, b: int, divisions: int, make: Callable[[], int]) -> int:
        """Signed tag of the curve from a to b (negative when it exists from b to a)."""
        key = frozenset((a, b))
        if key not in self._curves:
            tag = make()
            self.geo.mesh.setTransfiniteCurve(tag, divisions + 1)
            self._curves[key] = (tag, a, divisions)
        tag, start, n = self._curves[key]
        assert n == divisions, "a shared curve must keep its division count"
        return tag if start == a else -tag

    def patch(self, curves: list[int], flat: bool = False, sphere_centre: int = -1) -> int:
        """A structured four-sided patch bounded by ``curves`` (signed, in loop order)."""
        divisions = {abs(tag): n for tag, _, n in self._curves.values()}
        self.elements += divisions[abs(curves[0])] * divisions[abs(curves[1])]
        loop = self.geo.addCurveLoop(curves)
        if flat:
            surface = self.geo.addPlaneSurface([loop])
        else:
            surface = self.geo.addSurfaceFilling([loop], sphereCenterTag=sphere_centre)
        self.geo.mesh.setTransfiniteSurface(surface)
        self.geo.mesh.setRecombine(2, surface)
        return surface

    def name(self, dim: int, name: str, tags: list[int]) -> None:
        """Add entities (signs dropped) to the named set ``name`` of dimension ``dim``."""
        self._groups.setdefault((dim, name), []).extend(abs(t) for t in tags)

    def finish(self) -> None:
        """Synchronise, mesh as complete 9-node quads, create the physical groups. Raises
        SceneTooLarge first when a run of the patches' elements would not fit in memory
        (gmsh meshing 8e8 elements died of a segmentation fault)."""
        refuse_if_too_big(self.elements, "[mesh] divisions give")
        self.geo.synchronize()
        for (dim, name), tags in self._groups.items():
            self.gmsh.model.addPhysicalGroup(dim, sorted(set(tags)), name=name)
        self.gmsh.model.mesh.generate(2)
        self.gmsh.model.mesh.setOrder(2)


def rectangle(sk: Sketch, g: Rectangle, mesh: MeshOptions, thickness: float) -> Hint:
    nx, ny = mesh.divisions["length"], mesh.divisions["width"]
    regular = np.linspace(0.0, 1.0, nx + 1)
    b0 = np.asarray(mesh.boundaries_y0 if mesh.boundaries_y0 is not None else regular)
    b1 = np.asarray(mesh.boundaries_y1 if mesh.boundaries_y1 is not None else regular)
    # One patch per element column, so element boundaries may differ along the two edges.
    bottom = [sk.point((g.length * f, 0.0, 0.0)) for f in b0]
    top = [sk.point((g.length * f, g.width, 0.0)) for f in b1]
    for i in range(nx):
        sk.patch(
            [sk.line(bottom[i], bottom[i + 1], 1), sk.line(bottom[i + 1], top[i + 1], ny),
             sk.line(top[i + 1], top[i], 1), sk.line(top[i], bottom[i], ny)],
            flat=True,
        )
    sk.name(1, "x0", [sk.line(bottom[0], top[0], ny)])
    sk.name(1, "x1", [sk.line(bottom[-1], top[-1], ny)])
    sk.name(1, "y0", [sk.line(a, b, 1) for a, b in zip(bottom, bottom[1:])])
    sk.name(1, "y1", [sk.line(a, b, 1) for a, b in zip(top, top[1:])])
    for name, p in (("x0y0", bottom[0]), ("x1y0", bottom[-1]), ("x1y1", top[-1]), ("x0y1", top[0])):
        sk.name(0, name, [p])
    return _up


def cylindrical_panel(sk: Sketch, g: CylindricalPanel, mesh: MeshOptions, thickness: float) -> Hint:
    n_around, n_along = mesh.divisions["around"], mesh.divisions["along"]
    phi = math.radians(g.angle_deg)

    def at(angle: float, y: float) -> int:
        return sk.point((g.radius * math.sin(angle), y, g.radius * math.cos(angle)))

    c0, c1 = sk.point((0.0, 0.0, 0.0)), sk.point((0.0, g.length, 0.0))
    p00, p10, p11, p01 = at(0, 0), at(phi, 0), at(phi, g.length), at(0, g.length)
    sk.patch([sk.arc(p00, c0, p10, n_around), sk.line(p10, p11, n_along),
              sk.arc(p11, c1, p01, n_around), sk.line(p01, p00, n_along)])
    sk.name(1, "phi0", [sk.line(p00, p01, n_along)])
    sk.name(1, "phi1", [sk.line(p10, p11, n_along)])
    sk.name(1, "y0", [sk.arc(p00, c0, p10, n_around)])
    sk.name(1, "y1", [sk.arc(p01, c1, p11, n_around)])
    for name, p in (("phi0_y0", p00), ("phi1_y0", p10), ("phi1_y1", p11), ("phi0_y1", p01)):
        sk.name(0, name, [p])
    return lambda x: x * np.array([1.0, 0.0, 1.0])


def twisted_strip(sk: Sketch, g: TwistedStrip, mesh: MeshOptions, thickness: float) -> Hint:
    """Meshed flat here; :func:`twist_onto_helicoid` maps the nodes afterwards."""
    nx, nw = mesh.divisions["length"], mesh.divisions["width"]
    half = g.width / 2
    r0, r1 = sk.point((0.0, -half, 0.0)), sk.point((0.0, half, 0.0))
    t0, t1 = sk.point((g.length, -half, 0.0)), sk.point((g.length, half, 0.0))
    rc, tc = sk.point((0.0, 0.0, 0.0)), sk.point((g.length, 0.0, 0.0))
    half_w = nw // 2
    sk.patch([sk.line(r0, t0, nx), sk.line(t0, tc, half_w), sk.line(tc, rc, nx),
              sk.line(rc, r0, half_w)], flat=True)
    sk.patch([sk.line(rc, tc, nx), sk.line(tc, t1, half_w), sk.line(t1, r1, nx),
              sk.line(r1, rc, half_w)], flat=True)
    sk.name(1, "root", [sk.line(r0, rc, half_w), sk.line(rc, r1, half_w)])
    sk.name(1, "tip", [sk.line(t0, tc, half_w), sk.line(tc, t1, half_w)])
    sk.name(1, "side0", [sk.line(r0, t0, nx)])
    sk.name(1, "side1", [sk.line(r1, t1, nx)])
    sk.name(0, "tip_centre", [tc])
    twist = math.radians(g.twist_deg)

    def hint(x: np.ndarray) -> np.ndarray:
        a = twist * x[:, 0] / g.length
        return np.column_stack([np.zeros_like(a), -np.sin(a), np.cos(a)])

    return hint


def twist_onto_helicoid(x: np.ndarray, conn: np.ndarray, g: TwistedStrip) -> tuple[np.ndarray, list, dict]:
    """Map flat-strip positions (x, w, 0) (n, 3) to (x, w cos a, w sin a), a = twist x / length.

    Returns the mapped positions (n, 3), the helicoid's unit normals there as every
    node's surface normals, (x_,x) cross (x_,w) = (-w a', -sin a, cos a), a' = twist /
    length, and no cell vectors.
    """
    rate = math.radians(g.twist_deg) / g.length
    a, w = rate * x[:, 0], x[:, 1]
    mapped = np.column_stack([x[:, 0], w * np.cos(a), w * np.sin(a)])
    normal = np.column_stack([-w * rate, -np.sin(a), np.cos(a)])
    return mapped, [(np.arange(len(x)), normal / np.linalg.norm(normal, axis=1, keepdims=True))], {}


def annular_sector(sk: Sketch, g: AnnularSector, mesh: MeshOptions, thickness: float) -> Hint:
    n_around, n_radial = mesh.divisions["around"], mesh.divisions["radial"]
    theta = math.radians(g.angle_deg)
    o = sk.point((0.0, 0.0, 0.0))
    i0, o0 = sk.point((g.inner_radius, 0.0, 0.0)), sk.point((g.outer_radius, 0.0, 0.0))
    o1 = sk.point((g.outer_radius * math.cos(theta), g.outer_radius * math.sin(theta), 0.0))
    i1 = sk.point((g.inner_radius * math.cos(theta), g.inner_radius * math.sin(theta), 0.0))
    sk.patch([sk.line(i0, o0, n_radial), sk.arc(o0, o, o1, n_around),
              sk.line(o1, i1, n_radial), sk.arc(i1, o, i0, n_around)], flat=True)
    sk.name(1, "inner", [sk.arc(i0, o, i1, n_around)])
    sk.name(1, "outer", [sk.arc(o0, o, o1, n_around)])
    sk.name(1, "theta0", [sk.line(i0, o0, n_radial)])
    sk.name(1, "theta1", [sk.line(i1, o1, n_radial)])
    for name, p in (("inner_theta0", i0), ("outer_theta0", o0), ("outer_theta1", o1), ("inner_theta1", i1)):
        sk.name(0, name, [p])
    return _up


def plate_with_hole(sk: Sketch, g: PlateWithHole, mesh: MeshOptions, thickness: float) -> Hint:
    n_around, n_radial = mesh.divisions["around"], mesh.divisions["radial"]
    a, w = g.hole_radius, g.half_width
    o = sk.point((0.0, 0.0, 0.0))
    pa, pb = sk.point((a, 0.0, 0.0)), sk.point((0.0, a, 0.0))
    pd = sk.point((a / math.sqrt(2), a / math.sqrt(2), 0.0))
    pe, pc, pf = sk.point((w, 0.0, 0.0)), sk.point((w, w, 0.0)), sk.point((0.0, w, 0.0))
    sk.patch([sk.arc(pa, o, pd, n_around), sk.line(pd, pc, n_radial),
              sk.line(pc, pe, n_around), sk.line(pe, pa, n_radial)], flat=True)
    sk.patch([sk.arc(pd, o, pb, n_around), sk.line(pb, pf, n_radial),
              sk.line(pf, pc, n_around), sk.line(pc, pd, n_radial)], flat=True)
    sk.name(1, "hole", [sk.arc(pa, o, pd, n_around), sk.arc(pd, o, pb, n_around)])
    sk.name(1, "x0", [sk.line(pb, pf, n_radial)])
    sk.name(1, "y0", [sk.line(pa, pe, n_radial)])
    sk.name(1, "x1", [sk.line(pe, pc, n_around)])
    sk.name(1, "y1", [sk.line(pf, pc, n_around)])
    for name, p in (("A", pa), ("B", pb), ("C", pc)):
        sk.name(0, name, [p])
    return _up


def _sphere_octant(sk: Sketch, centre: tuple[float, float, float], radius: float, n: int,
                   equator: tuple[int, int, int] | None = None) -> dict[str, list[int]]:
    """The octant x, y >= 0 above ``centre`` of a sphere, as three patches meeting at the
    octant's centre point; every patch edge is a great-circle arc.

    ``equator``: existing points (on x, at 45 degrees, on y) to share with a neighbour.
    Returns the patch surfaces and the curves of its equator, x = 0 and y = 0 boundaries.
    """
    c = np.asarray(centre)
    s2, s3 = 1 / math.sqrt(2), 1 / math.sqrt(3)

    def at(direction: tuple[float, float, float]) -> int:
        return sk.point(c + radius * np.asarray(direction))

    o = sk.point(c)
    ex, em, ey = equator or (at((1, 0, 0)), at((s2, s2, 0)), at((0, 1, 0)))
    pole, mx, my, mid = at((0, 0, 1)), at((s2, 0, s2)), at((0, s2, s2)), at((s3, s3, s3))
    surfaces = [
        sk.patch([sk.arc(ex, o, em, n), sk.arc(em, o, mid, n), sk.arc(mid, o, mx, n),
                  sk.arc(mx, o, ex, n)], sphere_centre=o),
        sk.patch([sk.arc(em, o, ey, n), sk.arc(ey, o, my, n), sk.arc(my, o, mid, n),
                  sk.arc(mid, o, em, n)], sphere_centre=o),
        sk.patch([sk.arc(mx, o, mid, n), sk.arc(mid, o, my, n), sk.arc(my, o, pole, n),
                  sk.arc(pole, o, mx, n)], sphere_centre=o),
    ]
    return {
        "surfaces": surfaces,
        "equator": [sk.arc(ex, o, em, n), sk.arc(em, o, ey, n)],
        "sym_y": [sk.arc(ex, o, mx, n), sk.arc(mx, o, pole, n)],
        "sym_x": [sk.arc(ey, o, my, n), sk.arc(my, o, pole, n)],
        "points": [ex, ey, pole],
    }


def hemisphere(sk: Sketch, g: Hemisphere, mesh: MeshOptions, thickness: float) -> Hint:
    n = mesh.divisions["patch"]
    if g.hole_deg > 0:
        return _holed_hemisphere(sk, g.radius, math.radians(g.hole_deg), n)
    octant = _sphere_octant(sk, (0.0, 0.0, 0.0), g.radius, n)
    for name in ("equator", "sym_x", "sym_y"):
        sk.name(1, name, octant[name])
    for name, p in zip(("equator_x", "equator_y", "pole"), octant["points"]):
        sk.name(0, name, [p])
    return lambda x: x


def _holed_hemisphere(sk: Sketch, radius: float, hole: float, n: int) -> Hint:
    """The quarter hemisphere with a polar hole of half-angle ``hole`` (rad): two patches
    split at 45 degrees, each n x n, bounded by the equator, two meridians and the hole's
    circle of latitude."""
    s2 = 1 / math.sqrt(2)
    o, ring_centre = sk.point((0.0, 0.0, 0.0)), sk.point((0.0, 0.0, radius * math.cos(hole)))
    ring = radius * math.sin(hole)
    ex, em, ey = sk.point((radius, 0, 0)), sk.point((radius * s2, radius * s2, 0)), sk.point((0, radius, 0))
    hx, hm, hy = (sk.point((ring * cx, ring * cy, radius * math.cos(hole))) for cx, cy in ((1, 0), (s2, s2), (0, 1)))
    sk.patch([sk.arc(ex, o, em, n), sk.arc(em, o, hm, n), sk.arc(hm, ring_centre, hx, n), sk.arc(hx, o, ex, n)],
             sphere_centre=o)
    sk.patch([sk.arc(em, o, ey, n), sk.arc(ey, o, hy, n), sk.arc(hy, ring_centre, hm, n), sk.arc(hm, o, em, n)],
             sphere_centre=o)
    sk.name(1, "equator", [sk.arc(ex, o, em, n), sk.arc(em, o, ey, n)])
    sk.name(1, "sym_y", [sk.arc(ex, o, hx, n)])
    sk.name(1, "sym_x", [sk.arc(ey, o, hy, n)])
    sk.name(1, "hole", [sk.arc(hx, ring_centre, hm, n), sk.arc(hm, ring_centre, hy, n)])
    for name, p in (("equator_x", ex), ("equator_y", ey), ("hole_x", hx), ("hole_y", hy)):
        sk.name(0, name, [p])
    return lambda x: x


def tube(sk: Sketch, g: Tube, mesh: MeshOptions, thickness: float) -> Hint:
    n, n_axial = mesh.divisions["around"] // 2, mesh.divisions["axial"]
    r = g.inner_radius + thickness / 2
    s2 = 1 / math.sqrt(2)
    rings = []
    for z in (0.0, g.length):
        centre = sk.point((0.0, 0.0, z))
        rings.append((centre, sk.point((r, 0.0, z)), sk.point((r * s2, r * s2, z)), sk.point((0.0, r, z))))
    (o0, x0, m0, y0), (o1, x1, m1, y1) = rings
    wall = [
        sk.patch([sk.arc(x0, o0, m0, n), sk.line(m0, m1, n_axial), sk.arc(m1, o1, x1, n),
                  sk.line(x1, x0, n_axial)]),
        sk.patch([sk.arc(m0, o0, y0, n), sk.line(y0, y1, n_axial), sk.arc(y1, o1, m1, n),
                  sk.line(m1, m0, n_axial)]),
    ]
    sk.name(2, "wall", wall)
    sk.name(1, "sym_y", [sk.line(x0, x1, n_axial)])
    sk.name(1, "sym_x", [sk.line(y0, y1, n_axial)])
    sk.name(1, "z0", [sk.arc(x0, o0, m0, n), sk.arc(m0, o0, y0, n)])
    sk.name(0, "z0_x", [x0])
    sk.name(0, "z0_y", [y0])
    if g.cap == "hemisphere":
        cap = _sphere_octant(sk, (0.0, 0.0, g.length), r, n, equator=(x1, m1, y1))
        sk.name(2, "cap", cap["surfaces"])
        sk.name(1, "sym_y", cap["sym_y"])
        sk.name(1, "sym_x", cap["sym_x"])
        sk.name(0, "pole", [cap["points"][2]])
    else:
        sk.name(1, "end", [sk.arc(x1, o1, m1, n), sk.arc(m1, o1, y1, n)])

    def outward(x: np.ndarray) -> np.ndarray:
        axis_point = np.zeros_like(x)
        axis_point[:, 2] = np.clip(x[:, 2], 0.0, g.length)
        return x - axis_point

    return outward


def aortic_valve(sk: Sketch, g: AorticValve, mesh: MeshOptions, thickness: float) -> Hint:
    """Meshed flat here, leaflet k (from 0) as the unit square at x = 2k (x the way from
    commissure to commissure, y from the attachment to the free edge, the coaptation
    band above y = 1/2), in four patches so that the middles are points;
    :func:`onto_valve` maps the nodes afterwards."""
    half, n_belly, n_band = mesh.divisions["around"] // 2, mesh.divisions["belly"], mesh.divisions["coaptation"]
    for k in range(g.LEAFLETS):
        rows = [[sk.point((2 * k + 0.5 * i, y, 0.0)) for i in range(3)] for y in (0.0, 0.5, 1.0)]
        surfaces = []
        for (low, high), n in (((0, 1), n_belly), ((1, 2), n_band)):
            for i in range(2):
                a, b, c, d = rows[low][i], rows[low][i + 1], rows[high][i + 1], rows[high][i]
                surfaces.append(sk.patch([sk.line(a, b, half), sk.line(b, c, n), sk.line(c, d, half),
                                          sk.line(d, a, n)], flat=True))
        sk.name(2, f"leaflet_{k + 1}", surfaces)
        root = [sk.line(rows[0][i], rows[0][i + 1], half) for i in range(2)]
        sides = [sk.line(rows[j][i], rows[j + 1][i], n) for i in (0, 2) for j, n in ((0, n_belly), (1, n_band))]
        sk.name(1, "attachment", root + sides)
        free = [sk.line(rows[2][i], rows[2][i + 1], half) for i in range(2)]
        sk.name(1, "free_edge", free)
        sk.name(1, f"free_edge_{k + 1}", free)
        sk.name(0, f"centre_{k + 1}", [rows[2][1]])
        sk.name(0, f"nadir_{k + 1}", [rows[0][1]])

    def aortic_side(x: np.ndarray) -> np.ndarray:
        """Up and out toward the leaflet's own sinus: e_k + z."""
        centre = np.radians(90.0 + 120.0 * _leaflet_of(x))
        return np.column_stack([np.cos(centre), np.sin(centre), np.ones(len(x))])

    return aortic_side


def _leaflet_of(x: np.ndarray) -> np.ndarray:
    """(n,) the leaflet (0, 1, 2) whose sector holds each mapped position (n, 3)."""
    angle = np.degrees(np.arctan2(x[:, 1], x[:, 0]))
    return np.round((angle - 90.0) / 120.0).astype(int) % 3


def valve_points(g: AorticValve, k: np.ndarray, u: np.ndarray, y: np.ndarray, ring: bool = False) -> np.ndarray:
    """Positions (n, 3) on leaflet k (n,) at u (n,) in [0, 1] from commissure to
    commissure and y (n,) in [0, 1] from the attachment (0) over the belly to the
    coaptation band (1/2) and the free edge (1) (:class:`AorticValve`). ``ring``: the
    attachment an arc of the base circle at z = 0 (an atrioventricular valve's annulus),
    its ends the gap apart, instead of the root's cusps rising to the posts."""
    half, rc, rb, cc = 0.5 * g.gap, g.commissure_radius, g.base_radius, g.coaptation_height
    centre = np.radians(90.0 + 120.0 * k)
    # the free edge: two straight branches gap / 2 off the planes between leaflets
    first = u <= 0.5
    branch = centre + np.where(first, -1.0, 1.0) * np.pi / 3.0
    inward = branch + np.where(first, 0.5, -0.5) * np.pi  # toward the leaflet's centre line
    s_commissure, s_apex = math.sqrt(rc**2 - half**2), half / (2.0 * math.cos(math.pi / 6.0))
    s = np.where(first, s_commissure + (s_apex - s_commissure) * 2.0 * u,
                 s_apex + (s_commissure - s_apex) * (2.0 * u - 1.0))
    free = np.column_stack([s * np.cos(branch) + half * np.cos(inward), s * np.sin(branch) + half * np.sin(inward),
                            np.full(len(u), g.height)])
    band_foot = free - [0.0, 0.0, cc]
    # the attachment, from half the band foot's height under the commissures down to z = 0 mid-leaflet
    offset = math.asin(half / (rb if ring else rc))
    around = (centre - np.pi / 3.0 + offset) + (2.0 * np.pi / 3.0 - 2.0 * offset) * u
    w = np.ones(len(u)) if ring else np.sin(np.pi * u) ** 2  # level at the posts: the leaflet's corners there are square
    radius = rc + (rb - rc) * w
    attached = np.column_stack([radius * np.cos(around), radius * np.sin(around), 0.5 * (g.height - cc) * (1.0 - w)])
    points = band_foot + (2.0 * y - 1.0)[:, None] * (free - band_foot)
    belly = y < 0.5
    control = np.column_stack([band_foot[:, :2], attached[:, 2]])  # leaves the root flat, meets the band upright
    points[belly] = _evenly_along(attached[belly], control[belly], band_foot[belly], 2.0 * y[belly])
    return points


def _evenly_along(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, share: np.ndarray) -> np.ndarray:
    """The points (n, 3) ``share`` (n,) of the way along each quadratic Bezier p0, p1, p2
    (n, 3), by arc length (a root's control point may sit on p0, which bunches the
    parameter there)."""
    t = np.linspace(0.0, 1.0, 257)
    curve = ((1 - t)[None, :, None] ** 2 * p0[:, None] + 2 * (t * (1 - t))[None, :, None] * p1[:, None]
             + t[None, :, None] ** 2 * p2[:, None])  # (n, T, 3)
    length = np.concatenate([np.zeros((len(p0), 1)),
                             np.cumsum(np.linalg.norm(np.diff(curve, axis=1), axis=2), axis=1)], axis=1)
    out = np.empty_like(p0)
    for i in range(len(p0)):
        at = np.interp(share[i] * length[i, -1], length[i], t)
        out[i] = (1 - at) ** 2 * p0[i] + 2 * at * (1 - at) * p1[i] + at**2 * p2[i]
    return out


def onto_valve(x: np.ndarray, conn: np.ndarray, g: AorticValve) -> tuple[np.ndarray, list, dict]:
    """Flat leaflet positions (n, 3) (:func:`aortic_valve`) mapped onto the valve; no
    exact normals (the directors average the elements'); cell vectors
    ``along_free_edge`` (ne, 3): each element's unit direction of growing u at its centre."""
    k = np.floor(x[:, 0] / 2.0 + 0.25).astype(int)
    u, y = np.clip(x[:, 0] - 2.0 * k, 0.0, 1.0), np.clip(x[:, 1], 0.0, 1.0)
    mapped = valve_points(g, k, u, y)
    c = conn[:, 8]
    return mapped, [], {"along_free_edge": along_free_edge(g, k[c], u[c], y[c])}


def along_free_edge(g: AorticValve, k: np.ndarray, u: np.ndarray, y: np.ndarray, ring: bool = False) -> np.ndarray:
    """(n, 3) the unit direction of growing u (commissure to commissure, where a leaflet's
    collagen runs) on leaflet k (n,) at u, y (n,) (:func:`valve_points`, ``ring`` as
    there), by central differences within [0, 1]."""
    step = 1e-6
    along = (valve_points(g, k, np.minimum(u + step, 1.0), y, ring) - valve_points(g, k, np.maximum(u - step, 0.0), y, ring))
    return along / np.linalg.norm(along, axis=1, keepdims=True)



BUILDERS = {
    "rectangle": rectangle,
    "cylindrical_panel": cylindrical_panel,
    "twisted_strip": twisted_strip,
    "annular_sector": annular_sector,
    "plate_with_hole": plate_with_hole,
    "tube": tube,
    "hemisphere": hemisphere,
    "aortic_valve": aortic_valve,
}

#: Builders that mesh flat and map the nodes onto their surface: (positions (n, 3), conn,
#: geometry) -> (mapped positions, surface normals as for :func:`combine_surface_normals`,
#: cell vectors by name).
MAPPED = {"twisted_strip": twist_onto_helicoid, "aortic_valve": onto_valve}
