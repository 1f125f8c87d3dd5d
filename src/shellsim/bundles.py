"""The named bundles the compiled layer receives: typed tuples of arrays, built once by
:func:`shellsim.model.build_model` (the scene) or :class:`shellsim.solver.simulation.Simulation`
(the state), and passed whole to every compiled function. The loads' bundles belong to
their kinds (:mod:`shellsim.loads`).

numba compiles a ``NamedTuple`` into a struct whose fields are read by name, and its
on-disk cache keeps working across processes, so no compiled function depends on the
order of a long argument list. Shapes: n nodes, ne elements, npts = 25 points of the
in-plane rule (9 Gauss points, then the 16 membrane tying points), nq = 9 Gauss points,
nt points through the thickness.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba.typed import List


class Rule(NamedTuple):
    """The element's integration and assumed-strain rule (:func:`shellsim.model.integration_rule`).

    N, dNr, dNs (npts, 9): shape functions and their derivatives at the points; tie
    (3, nq, 6), tie_points (3, 6): the tying interpolation of the covariant membrane
    strains rr, ss, rs; wq (nq,): in-plane weights; tz, wt (nt,): thickness points and
    weights; share (nt,): wt over its sum, each layer's share of a through-thickness
    mean; vol_basis (nq, nb): fields the in-plane volumetric strain is projected on
    (plane strain: 1, r, s; otherwise nb = 0).
    """

    N: np.ndarray
    dNr: np.ndarray
    dNs: np.ndarray
    tie: np.ndarray
    tie_points: np.ndarray
    wq: np.ndarray
    tz: np.ndarray
    wt: np.ndarray
    share: np.ndarray
    vol_basis: np.ndarray


class Body(NamedTuple):
    """The mesh as the kernels see it: conn (ne, 9) node numbers; jac0_inv
    (ne, npts, nt, 3, 3) inverse initial Jacobians dX/d(r, s, t)^-1; h0 (n,) initial
    fibre lengths [length]; node_slots (n + 1,) and slots (ne * 9,): for each node, the
    element slots e * 9 + a that hold it, in ascending order (node k's are
    slots[node_slots[k]:node_slots[k + 1]]), so nodal sums of element values are taken
    in one fixed order whatever the number of threads. part (ne,): each element's part
    (its material, an index into :class:`Material`'s per-part fields); the element loops'
    groups hold one part each: group g holds elements group_order[group_start[g]:
    group_start[g + 1]] (at most LANES) of part group_part[g]; density (ne,) [mass/length^3]."""

    conn: np.ndarray
    jac0_inv: np.ndarray
    h0: np.ndarray
    node_slots: np.ndarray
    slots: np.ndarray
    part: np.ndarray
    group_start: np.ndarray
    group_order: np.ndarray
    group_part: np.ndarray
    density: np.ndarray


class Material(NamedTuple):
    """The constitutive path, decided once when the model is built, shared by the model's
    parts, and each part's law and constants (M parts: its fields by part).

    path: SMALL_STRAIN, HYPERELASTIC (Technique 1) or CONVECTED (Techniques 2 and 3) of
    :mod:`shellsim.element.steps` (thesis 3.10); incremental: stress accumulated from
    strain increments (thesis Eq 3.2) instead of computed from the total strain (small
    strain by choice, convected always); push_forward: Technique 2's stretch of the
    accumulated stresses; thickness_update: the fibre lengths follow the normal stretch
    (thesis 3.11). law (M,): each part's hyperelastic law's code
    (:mod:`shellsim.materials.laws`); energy_stress, energy_tangent: each part's S^w and
    CC^w : dE, held for calls through their addresses,
    ``material.energy_stress[part](params[part], E, S)``
    (:func:`~shellsim.materials.laws.held_laws`; the first law's, never called, on the
    other paths); params (M, P): each part's parameters (padded with zeros); incompressible
    (M,): whether the part's law keeps J = 1; axes0 (ne, nq, nt, 3, 3) the elements' initial
    material frames (rows a1, a2, a3; (1, ...) unused otherwise). C (M, 5, 5): each part's
    reduced lamina matrix of the constant tensor [stress] (the other paths); normal_ratio
    (M,): nu / (1 - nu), the normal strain increment per in-plane one of the convected
    path.
    """

    path: int
    incremental: bool
    push_forward: bool
    thickness_update: bool
    law: np.ndarray
    energy_stress: List
    energy_tangent: List
    params: np.ndarray
    incompressible: np.ndarray
    axes0: np.ndarray
    C: np.ndarray
    normal_ratio: np.ndarray


class Curves(NamedTuple):
    """Time curves as padded tables: t, v (C, K) times and factors; length (C,) points
    used; interp, extrap (C,) codes of :mod:`shellsim.curve_tables`."""

    t: np.ndarray
    v: np.ndarray
    length: np.ndarray
    interp: np.ndarray
    extrap: np.ndarray


class Prescribed(NamedTuple):
    """Prescribed translations (P,): x[node, axis] = x0 + value * curve(t)."""

    nodes: np.ndarray
    axes: np.ndarray
    values: np.ndarray
    curves: np.ndarray


class Constraints(NamedTuple):
    """Supports as velocity projections: projector (n, 3, 3) onto the allowed
    translational velocities; rot_free (n, 2): 1 free, 0 fixed rotational DOF;
    prescribed translations."""

    projector: np.ndarray
    rot_free: np.ndarray
    prescribed: Prescribed


class Model(NamedTuple):
    """A scene as the compiled layer sees it (:func:`shellsim.model.build_model`): its
    rule, mesh, material, loads, curves and supports, and the initial shape (n nodes):
    x0, d0 (n, 3) mid-surface and directors, e1f0 (n, 3) fibre-frame first axes;
    mass 'M1' or 'M2' (thesis 3.14); damping [1/s]
    (mass-proportional); relax_from: the time from which every velocity is set to zero
    at each peak of the kinetic energy (dynamic relaxation; inf: never)."""

    rule: Rule
    body: Body
    material: Material
    loads: tuple  # shellsim.loads.Loads: one bundle per load kind (None: the scene has none), from the registry
    curves: Curves
    constraints: Constraints
    x0: np.ndarray
    d0: np.ndarray
    e1f0: np.ndarray
    mass: str
    damping: float
    relax_from: float

    @property
    def h0(self) -> np.ndarray:
        """(n,) initial fibre lengths."""
        return self.body.h0

    @property
    def structure(self) -> tuple:
        """(rule, body, material): what the element loops take of a model, whose own type
        changes with the load kinds a scene has."""
        return self.rule, self.body, self.material

    @property
    def conn(self) -> np.ndarray:
        """(ne, 9) node numbers of each element."""
        return self.body.conn

    @property
    def n_nodes(self) -> int:
        return len(self.x0)

    @property
    def n_elements(self) -> int:
        return len(self.body.conn)


class Shape(NamedTuple):
    """The shell's current shape: x, d (n, 3) mid-surface and unit directors; e1 (n, 3)
    fibre-frame first axes; h (n,) fibre lengths (updated in place when the material asks)."""

    x: np.ndarray
    d: np.ndarray
    e1: np.ndarray
    h: np.ndarray


class Fields(NamedTuple):
    """The state's arrays, updated in place by the time loop (n nodes, ne elements,
    nq x nt integration points): the current shape; v (n, 3), w (n, 2) translational and
    rotational velocities at the last half step; theta (n, 2) accumulated rotations;
    mt, mr (n,) lumped masses; stress (ne, nq, nt, 5) lamina Cauchy stress (s11, s22,
    s12, s13, s23); f_int, f_ext (n, 3), fr_int, fr_ext (n, 2) forces at t;
    prescribed_velocity (P,) of the prescribed translations; work (5,) internal,
    (unused), external, damping and friction work to t; energy (5,) internal work,
    kinetic energy, external, damping and friction work at the start of the last step
    (see :func:`shellsim.solver.explicit.advance`)."""

    shape: Shape
    v: np.ndarray
    w: np.ndarray
    theta: np.ndarray
    mt: np.ndarray
    mr: np.ndarray
    stress: np.ndarray
    f_int: np.ndarray
    fr_int: np.ndarray
    f_ext: np.ndarray
    fr_ext: np.ndarray
    prescribed_velocity: np.ndarray
    work: np.ndarray
    energy: np.ndarray


def slots_by_node(conn: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """(node_slots (n + 1,), slots (ne * 9,)) of :class:`Body`: the element slots
    e * 9 + a of each node in ascending order, as compressed rows."""
    flat = conn.ravel()
    slots = np.argsort(flat, kind="stable").astype(np.int64)
    node_slots = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(flat, minlength=n_nodes), out=node_slots[1:])
    return node_slots, slots
