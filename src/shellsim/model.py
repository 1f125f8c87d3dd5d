"""Deck + Mesh -> Model (:class:`shellsim.bundles.Model`): the arrays the compiled kernels
see, and nothing else.

Boundary conditions become, per node, a projector on the translational velocity and a
free/fixed flag for each of the two rotational DOFs, with the nodal fibre frame turned so
that a director constraint is one of those DOFs (symmetry plane or edge support: e1f is
the plane's normal, whose rotation is fixed). Loads become the tables of their kinds
(:func:`shellsim.loads.build_loads`), each with the index of its time curve.
"""

from __future__ import annotations

import math

import numpy as np

from .bundles import Body, Constraints, Curves, Material, Model, Prescribed, Rule, Shape, slots_by_node
from .curve_tables import EXTRAPOLATION, INTERPOLATION, held_from
from .deck import Deck
from .errors import MeshError, id_list, place
from .element.frames import initial_fibre_frame
from .element.steps import CONVECTED, HYPERELASTIC, SMALL_STRAIN
from .element.shape import NODE_RS, gauss_rule, gauss_rule_2d, shape, shape_derivatives
from .loads import DECK_KEYS, LoadScene, build_loads
from .element.groups import part_groups
from .materials.laws import held_laws, law_of
from .materials.linear import reduced_lamina_matrix
from .mesh import Mesh, inverse_jacobians, layer_geometry

AXES = {"x": 0, "y": 1, "z": 2}


def integration_rule(points_through_thickness: int, plane_strain: bool = False) -> Rule:
    """The element's :class:`~shellsim.bundles.Rule`.

    N, dNr, dNs (25, 9): shape functions and derivatives at the 3 x 3 Gauss points (rows
    0-8, thesis 3.15) and at the membrane tying points (rows 9-24): 2 x 3 points
    (r = +-1/sqrt 3, s on the 3-point rule) for the covariant strain c_rr, 3 x 2 for c_ss
    and 2 x 2 for c_rs. tie (3, 9, 6): weights interpolating each component at the
    integration points from its tying points, Lagrange linear along the 2-point direction
    and quadratic along the 3-point one; tie_points (3, 6): their row numbers (rs uses 4;
    the rest carry weight 0). wq (9,): in-plane weights; tz, wt: thickness rule;
    vol_basis: :func:`volumetric_basis`.
    """
    rs, wq = gauss_rule_2d(3)
    g2, _ = gauss_rule(2)
    g3, _ = gauss_rule(3)
    sets = [
        [(r, s) for s in g3 for r in g2],  # c_rr: 2 along r, 3 along s
        [(r, s) for s in g2 for r in g3],  # c_ss: 3 along r, 2 along s
        [(r, s) for s in g2 for r in g2],  # c_rs: 2 x 2
    ]
    points = [rs]
    tie = np.zeros((3, len(rs), 6))
    tie_points = np.zeros((3, 6), dtype=np.int64)
    row = len(rs)
    for c, tying in enumerate(sets):
        tying = np.asarray(tying)
        points.append(tying)
        tie_points[c, :len(tying)] = np.arange(row, row + len(tying))
        row += len(tying)
        for m, (rm, sm) in enumerate(tying):
            tie[c, :, m] = _lagrange(rs[:, 0], rm, np.unique(tying[:, 0])) * _lagrange(rs[:, 1], sm, np.unique(tying[:, 1]))
    points = np.vstack(points)
    dN = shape_derivatives(points)
    tz, wt = gauss_rule(points_through_thickness)
    N = shape(points)
    return Rule(N=N, dNr=np.ascontiguousarray(dN[:, :, 0]), dNs=np.ascontiguousarray(dN[:, :, 1]), tie=tie,
                tie_points=tie_points, wq=wq, tz=tz, wt=wt, share=wt / wt.sum(),
                vol_basis=volumetric_basis(plane_strain, N[:len(wq)]))


def _lagrange(x: np.ndarray, node: float, nodes: np.ndarray) -> np.ndarray:
    """The Lagrange polynomial on ``nodes`` that is 1 at ``node``, at x."""
    out = np.ones_like(x)
    for other in nodes:
        if other != node:
            out *= (x - other) / (node - other)
    return out


def build_model(deck: Deck, mesh: Mesh) -> Model:
    """Flatten ``deck`` and ``mesh`` into a :class:`Model`."""
    rule = integration_rule(deck.section.points_through_thickness, deck.section.plane_strain)
    conn = mesh.conn.astype(np.int64)
    node_slots, slots = slots_by_node(conn, mesh.n_nodes)
    part = element_parts(deck, mesh)
    group_start, group_order, group_part = part_groups(part)
    body = Body(conn=conn, jac0_inv=inverse_jacobians(mesh, rule.N, rule.dNr, rule.dNs, rule.tz),
                h0=mesh.thickness.copy(), node_slots=node_slots, slots=slots, part=part, group_start=group_start,
                group_order=group_order, group_part=group_part,
                density=np.array([m.density for m in deck.material])[part])
    constraints, e1f0 = _boundary_conditions(deck, mesh)
    curves = _curve_tables(deck)
    initial = Shape(x=mesh.x, d=mesh.director, e1=e1f0, h=mesh.thickness)
    loads = build_loads({key: getattr(deck, key) for key in DECK_KEYS},
                        LoadScene(mesh=mesh, rule=rule, body=body, initial=initial, curves=curves,
                                  curve_index=deck.curve_index))
    return Model(
        rule=rule, body=body, material=_material(deck, mesh, rule, part), loads=loads, curves=curves,
        constraints=constraints, x0=mesh.x.copy(), d0=mesh.director.copy(), e1f0=e1f0, mass=deck.solver.mass, damping=deck.solver.damping,
        relax_from=relax_from(deck, curves),
    )


def relax_from(deck: Deck, curves) -> float:
    """When kinetic damping starts (inf: the deck relaxes nothing): once every contact's
    moving curve (a rigid tool's motion) has stopped. A reset stops the nodes a tool is
    pushing while it goes on: it then runs into them, and the penalty's impulse folded a
    crushed ring's elements."""
    if deck.solver.relaxation is None:
        return math.inf
    moving = [deck.curve_index(table.moving_curve) for table in deck.contact if table.moving_curve is not None]
    return held_from(curves, moving)


def element_parts(deck: Deck, mesh: Mesh) -> np.ndarray:
    """(ne,) each element's material, its place in ``deck.material``: all the first's for
    a deck of one material without sets, else the one whose sets hold it. Raises
    MeshError naming the elements no material covers, or two do."""
    if len(deck.material) == 1 and not deck.material[0].sets:
        return np.zeros(mesh.n_elements, dtype=np.int64)
    covers = np.zeros((len(deck.material), mesh.n_elements), dtype=bool)
    for i, material in enumerate(deck.material):
        for name in material.sets:
            covers[i, mesh.sets[name].elements] = True
    centres = mesh.x[mesh.conn[:, 8]]
    for elements, what in ((np.flatnonzero(covers.sum(axis=0) == 0), "in no material's sets"),
                           (np.flatnonzero(covers.sum(axis=0) > 1), "in the sets of several materials")):
        if len(elements):
            owners = sorted({i for e in elements for i in np.flatnonzero(covers[:, e])})
            raise MeshError(f"{len(elements)} element(s) are {what}"
                            + (f" ({', '.join(f'material[{i}]' for i in owners)})" if owners else "")
                            + f": elements {id_list(elements + 1)} (the first at {place(centres[elements[0]])}); "
                            "every element has exactly one material")
    return np.argmax(covers, axis=0).astype(np.int64)


def _material(deck: Deck, mesh: Mesh, rule: Rule, part: np.ndarray) -> Material:
    """The kernels' :class:`~shellsim.bundles.Material`, each of its per-part fields one
    row per deck material (the deck has refused the paths the element cannot run, and
    parts of different paths).

    A linear elastic material without a technique is the small-strain path, with
    Technique 1 it is St. Venant-Kirchhoff; a hyperelastic one runs Technique 1 (total
    formulation, zero normal stress by J = 1). Technique 1 needs the material frames at
    the Gauss points of the initial shape, each element's from its material's axes.
    """
    materials, section = deck.material, deck.section
    nq, count = len(rule.wq), len(deck.material)
    path = {None: SMALL_STRAIN, 1: HYPERELASTIC}.get(section.technique, CONVECTED)
    if path != HYPERELASTIC:  # no law: the first law's functions, held and never called
        energy_stress, energy_tangent = held_laws([0])
        plane_strain = section.plane_strain and path == SMALL_STRAIN
        return Material(
            path=path, incremental=path == CONVECTED or section.formulation == "incremental",
            push_forward=section.technique == 2, thickness_update=path == CONVECTED and deck.thickness_update,
            law=np.zeros(count, dtype=np.int64), energy_stress=energy_stress, energy_tangent=energy_tangent,
            params=np.zeros((count, 1)), incompressible=np.zeros(count, dtype=bool),
            axes0=np.zeros((1, nq, len(rule.tz), 3, 3)),  # the kernels index it only for Technique 1
            C=np.array([reduced_lamina_matrix(m.E, m.nu, plane_strain) for m in materials]),
            normal_ratio=np.array([m.nu / (1.0 - m.nu) if path == CONVECTED else 0.0 for m in materials]))
    laws = [law_of(m.model) for m in materials]
    params = [law.parameters(m) for m, (_, law) in zip(materials, laws)]
    padded = np.zeros((count, max(len(p) for p in params)))
    for i, p in enumerate(params):
        padded[i, :len(p)] = p
    axes0 = np.empty((mesh.n_elements, nq, len(rule.tz), 3, 3))
    for i, m in enumerate(materials):
        elements = np.flatnonzero(part == i)
        axes0[elements] = _frames_of(m, mesh, rule, elements)
    energy_stress, energy_tangent = held_laws([code for code, _ in laws])
    return Material(path=HYPERELASTIC, incremental=False, push_forward=False, thickness_update=deck.thickness_update,
                    law=np.array([code for code, _ in laws], dtype=np.int64), energy_stress=energy_stress,
                    energy_tangent=energy_tangent, params=padded,
                    incompressible=np.array([law.INCOMPRESSIBLE for _, law in laws]), axes0=axes0,
                    C=np.zeros((count, 5, 5)), normal_ratio=np.zeros(count))


def _frames_of(material, mesh: Mesh, rule: Rule, elements: np.ndarray) -> np.ndarray:
    """The initial material frames of ``material``'s ``elements``: of its axes, or, where a
    law its constants make isotropic cannot lay them (a mesh field missing, an axis along
    a normal), of the elements' own directions, which its stress does not depend on."""
    nq = len(rule.wq)

    def frames(axes) -> np.ndarray:
        return material_frames(mesh, axes, rule.N[:nq], rule.dNr[:nq], rule.dNs[:nq], rule.tz, elements)

    try:
        return frames(getattr(material, "axes", None))
    except MeshError:
        if not getattr(material, "isotropic", False):
            raise
        return frames(None)


def material_frames(mesh: Mesh, axes, N, dNr, dNs, tz, elements: np.ndarray | None = None) -> np.ndarray:
    """(m, nq, nt, 3, 3) initial material frames at the Gauss points of the ``elements``
    (m,) (all by default), rows (a1, a2, a3): :func:`lamina_axes` of the axes' preferred
    direction (:class:`shellsim.materials.axes.TurnedAxes`; g_r for an isotropic law), a1
    then turned about a3 by the layer's ``axes.angle_deg``."""
    elements = np.arange(mesh.n_elements) if elements is None else elements
    conn, cell_vectors = mesh.conn[elements], {name: v[elements] for name, v in mesh.cell_vectors.items()}
    out = np.empty((len(elements), len(N), len(tz), 3, 3))
    turns = np.zeros(len(tz)) if axes is None else axes.angles(tz)
    for k, t in enumerate(tz):
        position, jac = layer_geometry(mesh.x, mesh.director, mesh.thickness, conn, N, dNr, dNs, t)
        preferred = jac[..., 0] if axes is None else axes.preferred(position, cell_vectors)
        if axes is not None:
            _refuse_along_normal(axes, jac, preferred, mesh.x[conn[:, 8]])
        frames = lamina_axes(jac, preferred)
        a1 = np.cos(turns[k]) * frames[..., 0, :] + np.sin(turns[k]) * frames[..., 1, :]
        out[:, :, k] = np.stack([a1, np.cross(frames[..., 2, :], a1), frames[..., 2, :]], axis=-2)
    return out


#: The sine of the angle between a given fibre direction and the lamina normal below which
#: the direction is taken to lie along the normal (about 0.6 degrees): its projection on
#: the lamina, axis 1, is then set by round-off.
ALONG_NORMAL = 1e-2


def _refuse_along_normal(axes, jac: np.ndarray, preferred: np.ndarray, centres: np.ndarray) -> None:
    """Raise MeshError where ``preferred`` (ne, q, 3), the direction the axes give, lies
    along the lamina normal of ``jac`` (ne, q, 3, 3): naming the key, the count of points
    and elements and the first element's place (``centres`` (ne, 3)). A rule about an
    axis (``MAY_MEET_NORMAL``) gives no direction on the axis itself (a tube's cap), where
    axis 1 falls back to the element's own; elsewhere its direction along the normal
    means the axis lies in the shell, and the fibres would be laid by round-off."""
    normal = np.cross(jac[..., 0], jac[..., 1])
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    size = np.linalg.norm(preferred, axis=-1)
    along = np.linalg.norm(np.cross(preferred, normal), axis=-1) < ALONG_NORMAL * size
    if axes.MAY_MEET_NORMAL:
        along &= size > 1e-6 * size.max(initial=0.0)  # on the axis: no direction, the fallback's place
    if not along.any():
        return
    elements = np.flatnonzero(along.any(axis=1))
    key = {"fixed": f"material.axes.direction = {place(getattr(axes, 'direction', ()))}",
           "mesh": f"material.axes.field = '{getattr(axes, 'field', '')}'"}.get(
        axes.kind, f"the {axes.kind} material.axes' circumferential direction")
    advice = ("the axis lies in the shell there: give the vessel's own axis, or fixed or mesh axes"
              if axes.MAY_MEET_NORMAL else "give a direction in the shell's plane")
    raise MeshError(f"{key} lies along the shell's normal at {int(along.sum())} of {along.size} points, in "
                    f"elements {id_list(elements + 1)} (element {elements[0] + 1} at "
                    f"{place(centres[elements[0]])}): material axis 1 is its projection on the shell, "
                    f"which is not defined there; {advice}")


def lamina_axes(jac: np.ndarray, preferred: np.ndarray) -> np.ndarray:
    """(..., 3, 3) orthonormal frames, rows (a1, a2, a3), at points with Jacobians ``jac``
    (..., 3, 3; columns g_r, g_s, g_t): a3 the lamina normal g_r x g_s / |.|, a1
    ``preferred`` (..., 3) projected on the lamina (g_r where it is normal to the lamina,
    e.g. on a tube's axis), a2 = a3 x a1."""
    g_r, g_s = jac[..., 0], jac[..., 1]
    normal = np.cross(g_r, g_s)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    a1 = preferred - np.sum(preferred * normal, axis=-1, keepdims=True) * normal
    size = np.linalg.norm(a1, axis=-1, keepdims=True)
    fallback = g_r - np.sum(g_r * normal, axis=-1, keepdims=True) * normal
    a1 = np.where(size > 1e-9 * np.linalg.norm(preferred, axis=-1, keepdims=True) + 1e-300, a1, fallback)
    a1 /= np.linalg.norm(a1, axis=-1, keepdims=True)
    return np.stack([a1, np.cross(normal, a1), normal], axis=-2)


def volumetric_basis(plane_strain: bool, N_gauss: np.ndarray) -> np.ndarray:
    """(nq, nb) fields for the volumetric strain at the nq Gauss points.

    In plane strain a nearly incompressible material makes the volumetric strain a
    penalty, which the 9-node element's 9 sampling points lock under (Test 7 with
    nu = 0.4999: -67% radial displacement); projecting it on (1, r, s) per element and
    layer gives the stable Q9/P3 element. Plane stress (a shell) relieves the constraint
    through the thickness strain, so no projection there (nb = 0).
    """
    if not plane_strain:
        return np.zeros((len(N_gauss), 0))
    rs = N_gauss @ NODE_RS  # the points' natural coordinates, interpolated
    return np.column_stack([np.ones(len(rs)), rs])


def _point_field(mesh: Mesh, name: str, user: str) -> np.ndarray:
    """The mesh's scalar point field ``name`` (n,); MeshError naming ``user`` and the fields
    there are when it has none of that name."""
    if name not in mesh.point_fields:
        known = ", ".join(f"'{f}'" for f in sorted(mesh.point_fields)) or "none (only a mesh file carries fields)"
        raise MeshError(f"{user}: field '{name}' is not a scalar point field of the mesh; it has {known}")
    return mesh.point_fields[name]


def _boundary_conditions(deck: Deck, mesh: Mesh) -> tuple[Constraints, np.ndarray]:
    """The supports as :class:`~shellsim.bundles.Constraints`, and the initial fibre frames
    (n, 3) turned so that a director constraint is one rotational DOF."""
    n = mesh.n_nodes
    constrained: list[list[np.ndarray]] = [[] for _ in range(n)]
    planes: list[list[np.ndarray]] = [[] for _ in range(n)]
    director_fixed = np.zeros(n, dtype=bool)
    prescribed: dict[str, list] = {"nodes": [], "axes": [], "values": [], "curves": []}
    axes = np.eye(3)
    for bc in deck.boundary:
        nodes = mesh.sets[bc.set].nodes
        if bc.type == "clamped":
            directions, plane, fixed = list(axes), None, True
        elif bc.type == "fixed":
            directions = [axes[AXES[a]] for a in bc.translations]
            plane = None if bc.director_plane_normal is None else np.asarray(bc.director_plane_normal)
            fixed = bc.director == "fixed"
        elif bc.type == "symmetry":
            directions, plane, fixed = [np.asarray(bc.normal)], np.asarray(bc.normal), False
        else:  # prescribed
            directions, plane, fixed = [axes[AXES[bc.translation]]], None, False
            share = np.ones(n) if bc.field is None else _point_field(mesh, bc.field, f"boundary set '{bc.set}'")
            for node in nodes:
                prescribed["nodes"].append(node)
                prescribed["axes"].append(AXES[bc.translation])
                prescribed["values"].append(bc.value * share[node])
                prescribed["curves"].append(deck.curve_index(bc.curve))
        for node in nodes:
            constrained[node].extend(directions)
            if plane is not None:
                planes[node].append(plane)
            director_fixed[node] |= fixed
    director_fixed[np.setdiff1d(np.arange(n), mesh.conn)] = True  # a cable's node: no bending
    projector = np.empty((n, 3, 3))
    rot_free = np.ones((n, 2))
    e1f0 = np.empty((n, 3))
    for node in range(n):
        basis = orthonormal(constrained[node])
        projector[node] = np.eye(3) - sum((np.outer(b, b) for b in basis), np.zeros((3, 3)))
        d = mesh.director[node]
        initial_fibre_frame(d, e1f0[node])
        in_plane = orthonormal([p - (p @ d) * d for p in planes[node]])
        if director_fixed[node] or len(in_plane) >= 2:
            rot_free[node] = 0.0
        elif len(in_plane) == 1:
            # Turn the fibre frame so that e1f is the plane's normal: the director may not
            # move along it, which is the first rotational DOF.
            e1f0[node] = in_plane[0]
            rot_free[node, 0] = 0.0
    moved = Prescribed(nodes=np.asarray(prescribed["nodes"], dtype=np.int64),
                       axes=np.asarray(prescribed["axes"], dtype=np.int64),
                       values=np.asarray(prescribed["values"], dtype=float),
                       curves=np.asarray(prescribed["curves"], dtype=np.int64))
    return Constraints(projector=projector, rot_free=rot_free, prescribed=moved), e1f0


def orthonormal(vectors: list[np.ndarray], tol: float = 1e-8) -> list[np.ndarray]:
    """Gram-Schmidt basis of the span of ``vectors`` (dependent ones dropped)."""
    basis: list[np.ndarray] = []
    for v in vectors:
        w = np.asarray(v, dtype=float) - sum(((b @ v) * b for b in basis), np.zeros(3))
        norm = np.linalg.norm(w)
        if norm > tol:
            basis.append(w / norm)
    return basis


def _curve_tables(deck: Deck) -> Curves:
    """The deck's curves as padded tables, numbered as :meth:`shellsim.deck.Deck.curve_index`;
    a static solve or a preload appends the linear ramp from 0 at t = 0 to 1 at its end
    that loads without a curve follow: on beyond the end of a static run, where an
    arc-length path may take the load time, held after a preload."""
    tables = [curve.table() for curve in deck.curves.values()]
    end = deck.solver.ramp_end
    if end is not None:
        beyond = EXTRAPOLATION["linear" if deck.solver.method == "static" else "constant"]
        tables.append((np.array([0.0, end]), np.array([0.0, 1.0]), INTERPOLATION["linear"], beyond))
    size = max([len(times) for times, *_ in tables], default=1)
    t = np.zeros((max(len(tables), 1), size))
    v = np.zeros_like(t)
    length = np.ones(max(len(tables), 1), dtype=np.int64)
    interp = np.zeros(max(len(tables), 1), dtype=np.int64)
    extrap = np.zeros_like(interp)
    for i, (times, values, interp[i], extrap[i]) in enumerate(tables):
        length[i] = len(times)
        t[i, :len(times)], v[i, :len(times)] = times, values
    return Curves(t=t, v=v, length=length, interp=interp, extrap=extrap)
