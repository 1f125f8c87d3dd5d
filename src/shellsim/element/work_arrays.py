"""The work arrays of an element group, in the three bundles the response's phases hand
on: :class:`Group` (the group's data and results), :class:`Points` (what one phase
computes for the next, at every point) and :class:`Scratch` (one point's temporaries).
Every array carries the group's lanes last (G = :data:`shellsim.lanes.LANES`)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from ..fixed_shape import fixed_trailing
from ..lanes import LANES


class Group(NamedTuple):
    """An element group as gathered and its results (G = LANES lanes, nq Gauss points, nt
    layers, npts points): members (G,) element numbers; part (1,) the part (material)
    they all belong to; xe, de, ue, ve (9, 3, G)
    positions, directors and the field's increments; he (9, G) fibre lengths; jac0
    (npts, nt, 3, 3, G) inverse initial Jacobians; axes0 (nq, nt, 3, 3, G) initial
    material frames (Technique 1); state_stress (nq, nt, 5, G) the state's lamina stresses
    (the product's initial stress). Results: stress (nq, nt, 5, G) lamina stresses (read
    first when incremental); stretch (nq, G) normal stretches; fe, ge (9, 3, G) nodal forces."""

    members: np.ndarray
    part: np.ndarray
    xe: np.ndarray
    de: np.ndarray
    ue: np.ndarray
    ve: np.ndarray
    he: np.ndarray
    jac0: np.ndarray
    axes0: np.ndarray
    state_stress: np.ndarray
    stress: np.ndarray
    stretch: np.ndarray
    fe: np.ndarray
    ge: np.ndarray


class Points(NamedTuple):
    """What the phases hand on, at every point and layer (npts, nt, ...): Q, jinv_all
    (3, 3, G) lamina frames and inverse Jacobians, G (2, 3, G) tangents g_r, g_s, A
    (2, 2, G) their lamina components, DV (G) volumes, EPS (5, G) lamina strains,
    cov_shear and TS (2, G) covariant shears and their tying-point stresses; cbar, T
    (npts, 3, G) membrane means and tying weights. At the Gauss points (nq, nt, ...): SW
    (3, G) volume-weighted in-plane stresses, FP, LP (3, 3, G) deformation and field
    gradients, EPS0 (5, G) strains before the tying; Bab (nq, 3, G)."""

    Q: np.ndarray
    jinv_all: np.ndarray
    G: np.ndarray
    A: np.ndarray
    DV: np.ndarray
    EPS: np.ndarray
    cov_shear: np.ndarray
    TS: np.ndarray
    cbar: np.ndarray
    T: np.ndarray
    SW: np.ndarray
    FP: np.ndarray
    LP: np.ndarray
    EPS0: np.ndarray
    Bab: np.ndarray


class Scratch(NamedTuple):
    """Temporaries of one point, meaningless between phases: jac, F, eg, v, plane, glob,
    local, sg (3, 3, G); gN, gM (9, 3, G); s5 (5, G); cov, delta (3, G); det (G,); ones
    (G,) of 1.0; the stress update's M (11, 3, 3, G), Emean (3, 3, G), pressure, volume,
    normal (G,); the projection's Mb (nb, nb), rhs (nb,)."""

    jac: np.ndarray
    F: np.ndarray
    eg: np.ndarray
    v: np.ndarray
    plane: np.ndarray
    glob: np.ndarray
    local: np.ndarray
    sg: np.ndarray
    gN: np.ndarray
    gM: np.ndarray
    s5: np.ndarray
    cov: np.ndarray
    delta: np.ndarray
    det: np.ndarray
    ones: np.ndarray
    M: np.ndarray
    Emean: np.ndarray
    pressure: np.ndarray
    volume: np.ndarray
    normal: np.ndarray
    Mb: np.ndarray
    rhs: np.ndarray


#: The trailing lengths of the work arrays, after their point and layer axes: one value,
#: two, three or a lamina vector of five per lane; the tangents' 2 x 2 lamina components
#: and the two tangents; a 3 x 3 tensor; a vector and a value at each of the nine nodes.
#: :func:`group_arrays` makes the arrays with them and :func:`fixed_lanes` views them so.
LANE, PAIR, TRIPLE, LAMINA = (LANES,), (2, LANES), (3, LANES), (5, LANES)
PAIR_PAIR, TANGENTS, TENSOR = (2, 2, LANES), (2, 3, LANES), (3, 3, LANES)
NODAL, NODE_VALUES = (9, 3, LANES), (9, LANES)


@njit(cache=True, error_model="numpy")
def group_arrays(npts, nt, nq, nb):
    """(:class:`Group`, :class:`Points`, :class:`Scratch`) for npts points, nt layers, nq
    Gauss points and nb volumetric fields."""
    every, gauss = (npts, nt), (nq, nt)  # every point and layer; the Gauss points'
    group = Group(
        members=np.zeros(LANE, dtype=np.int64), part=np.zeros(1, dtype=np.int64), xe=np.empty(NODAL),
        de=np.empty(NODAL), ue=np.zeros(NODAL), ve=np.zeros(NODAL), he=np.empty(NODE_VALUES),
        jac0=np.empty(every + TENSOR), axes0=np.empty(gauss + TENSOR), state_stress=np.zeros(gauss + LAMINA),
        stress=np.zeros(gauss + LAMINA), stretch=np.ones((nq,) + LANE), fe=np.empty(NODAL), ge=np.empty(NODAL))
    points = Points(
        Q=np.empty(every + TENSOR), jinv_all=np.empty(every + TENSOR), G=np.empty(every + TANGENTS),
        A=np.empty(every + PAIR_PAIR), DV=np.empty(every + LANE), EPS=np.empty(every + LAMINA),
        cov_shear=np.empty(every + PAIR), TS=np.empty(every + PAIR), cbar=np.empty((npts,) + TRIPLE),
        T=np.empty((npts,) + TRIPLE), SW=np.empty(gauss + TRIPLE), FP=np.empty(gauss + TENSOR),
        LP=np.empty(gauss + TENSOR), EPS0=np.empty(gauss + LAMINA), Bab=np.empty((nq,) + TRIPLE))
    scratch = Scratch(
        jac=np.empty(TENSOR), F=np.empty(TENSOR), eg=np.empty(TENSOR), v=np.empty(TENSOR), plane=np.zeros(TENSOR),
        glob=np.empty(TENSOR), local=np.empty(TENSOR), sg=np.empty(TENSOR), gN=np.empty(NODAL), gM=np.empty(NODAL),
        s5=np.empty(LAMINA), cov=np.empty(TRIPLE), delta=np.empty(TRIPLE), det=np.empty(LANE), ones=np.ones(LANE),
        M=np.empty((11,) + TENSOR), Emean=np.empty(TENSOR), pressure=np.empty(LANE), volume=np.empty(LANE),
        normal=np.empty(LANE), Mb=np.empty((nb, nb)), rhs=np.empty(nb))
    return group, points, scratch


@njit(cache=True, inline="always")
def fixed_lanes(group, points, scratch):
    """(group, points, scratch) with every work array's trailing axes of lengths known to
    the compiled code (:func:`shellsim.fixed_shape.fixed_trailing`: the lane loops then
    vectorise), views for use inside the calling function only; scratch.Mb and rhs as
    they are."""
    f = fixed_trailing
    group = Group(
        members=f(group.members, LANE), part=group.part, xe=f(group.xe, NODAL), de=f(group.de, NODAL),
        ue=f(group.ue, NODAL), ve=f(group.ve, NODAL), he=f(group.he, NODE_VALUES), jac0=f(group.jac0, TENSOR),
        axes0=f(group.axes0, TENSOR), state_stress=f(group.state_stress, LAMINA), stress=f(group.stress, LAMINA),
        stretch=f(group.stretch, LANE), fe=f(group.fe, NODAL), ge=f(group.ge, NODAL))
    points = Points(
        Q=f(points.Q, TENSOR), jinv_all=f(points.jinv_all, TENSOR), G=f(points.G, TANGENTS),
        A=f(points.A, PAIR_PAIR), DV=f(points.DV, LANE), EPS=f(points.EPS, LAMINA),
        cov_shear=f(points.cov_shear, PAIR), TS=f(points.TS, PAIR), cbar=f(points.cbar, TRIPLE),
        T=f(points.T, TRIPLE), SW=f(points.SW, TRIPLE), FP=f(points.FP, TENSOR), LP=f(points.LP, TENSOR),
        EPS0=f(points.EPS0, LAMINA), Bab=f(points.Bab, TRIPLE))
    scratch = Scratch(
        jac=f(scratch.jac, TENSOR), F=f(scratch.F, TENSOR), eg=f(scratch.eg, TENSOR), v=f(scratch.v, TENSOR),
        plane=f(scratch.plane, TENSOR), glob=f(scratch.glob, TENSOR), local=f(scratch.local, TENSOR),
        sg=f(scratch.sg, TENSOR), gN=f(scratch.gN, NODAL), gM=f(scratch.gM, NODAL), s5=f(scratch.s5, LAMINA),
        cov=f(scratch.cov, TRIPLE), delta=f(scratch.delta, TRIPLE), det=f(scratch.det, LANE),
        ones=f(scratch.ones, LANE), M=f(scratch.M, TENSOR), Emean=f(scratch.Emean, TENSOR),
        pressure=f(scratch.pressure, LANE), volume=f(scratch.volume, LANE), normal=f(scratch.normal, LANE),
        Mb=scratch.Mb, rhs=scratch.rhs)
    return group, points, scratch
