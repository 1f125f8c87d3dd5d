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


@njit(cache=True, error_model="numpy")
def group_arrays(npts, nt, nq, nb):
    """(:class:`Group`, :class:`Points`, :class:`Scratch`) for npts points, nt layers, nq
    Gauss points and nb volumetric fields."""
    g = LANES
    group = Group(
        members=np.zeros(g, dtype=np.int64), part=np.zeros(1, dtype=np.int64), xe=np.empty((9, 3, g)),
        de=np.empty((9, 3, g)), ue=np.zeros((9, 3, g)),
        ve=np.zeros((9, 3, g)), he=np.empty((9, g)), jac0=np.empty((npts, nt, 3, 3, g)),
        axes0=np.empty((nq, nt, 3, 3, g)), state_stress=np.zeros((nq, nt, 5, g)), stress=np.zeros((nq, nt, 5, g)),
        stretch=np.ones((nq, g)), fe=np.empty((9, 3, g)), ge=np.empty((9, 3, g)))
    points = Points(
        Q=np.empty((npts, nt, 3, 3, g)), jinv_all=np.empty((npts, nt, 3, 3, g)), G=np.empty((npts, nt, 2, 3, g)),
        A=np.empty((npts, nt, 2, 2, g)), DV=np.empty((npts, nt, g)), EPS=np.empty((npts, nt, 5, g)),
        cov_shear=np.empty((npts, nt, 2, g)), TS=np.empty((npts, nt, 2, g)), cbar=np.empty((npts, 3, g)),
        T=np.empty((npts, 3, g)), SW=np.empty((nq, nt, 3, g)), FP=np.empty((nq, nt, 3, 3, g)),
        LP=np.empty((nq, nt, 3, 3, g)), EPS0=np.empty((nq, nt, 5, g)), Bab=np.empty((nq, 3, g)))
    scratch = Scratch(
        jac=np.empty((3, 3, g)), F=np.empty((3, 3, g)), eg=np.empty((3, 3, g)), v=np.empty((3, 3, g)),
        plane=np.zeros((3, 3, g)), glob=np.empty((3, 3, g)), local=np.empty((3, 3, g)), sg=np.empty((3, 3, g)),
        gN=np.empty((9, 3, g)), gM=np.empty((9, 3, g)), s5=np.empty((5, g)), cov=np.empty((3, g)), delta=np.empty((3, g)),
        det=np.empty(g), ones=np.ones(g), M=np.empty((11, 3, 3, g)), Emean=np.empty((3, 3, g)), pressure=np.empty(g),
        volume=np.empty(g), normal=np.empty(g), Mb=np.empty((nb, nb)), rhs=np.empty(nb))
    return group, points, scratch


@njit(cache=True, inline="always")
def fixed_lanes(group, points, scratch):
    """(group, points, scratch) with every work array's trailing axes of lengths known to
    the compiled code (:func:`shellsim.fixed_shape.fixed_trailing`: the lane loops then
    vectorise), views for use inside the calling function only; scratch.Mb and rhs as
    they are."""
    g, f = LANES, fixed_trailing
    group = Group(
        members=f(group.members, (g,)), part=group.part, xe=f(group.xe, (9, 3, g)), de=f(group.de, (9, 3, g)),
        ue=f(group.ue, (9, 3, g)), ve=f(group.ve, (9, 3, g)), he=f(group.he, (9, g)),
        jac0=f(group.jac0, (3, 3, g)), axes0=f(group.axes0, (3, 3, g)), state_stress=f(group.state_stress, (5, g)),
        stress=f(group.stress, (5, g)), stretch=f(group.stretch, (g,)), fe=f(group.fe, (9, 3, g)),
        ge=f(group.ge, (9, 3, g)))
    points = Points(
        Q=f(points.Q, (3, 3, g)), jinv_all=f(points.jinv_all, (3, 3, g)), G=f(points.G, (2, 3, g)),
        A=f(points.A, (2, 2, g)), DV=f(points.DV, (g,)), EPS=f(points.EPS, (5, g)),
        cov_shear=f(points.cov_shear, (2, g)), TS=f(points.TS, (2, g)), cbar=f(points.cbar, (3, g)),
        T=f(points.T, (3, g)), SW=f(points.SW, (3, g)), FP=f(points.FP, (3, 3, g)), LP=f(points.LP, (3, 3, g)),
        EPS0=f(points.EPS0, (5, g)), Bab=f(points.Bab, (3, g)))
    scratch = Scratch(
        jac=f(scratch.jac, (3, 3, g)), F=f(scratch.F, (3, 3, g)), eg=f(scratch.eg, (3, 3, g)),
        v=f(scratch.v, (3, 3, g)), plane=f(scratch.plane, (3, 3, g)), glob=f(scratch.glob, (3, 3, g)),
        local=f(scratch.local, (3, 3, g)), sg=f(scratch.sg, (3, 3, g)), gN=f(scratch.gN, (9, 3, g)),
        gM=f(scratch.gM, (9, 3, g)), s5=f(scratch.s5, (5, g)), cov=f(scratch.cov, (3, g)),
        delta=f(scratch.delta, (3, g)), det=f(scratch.det, (g,)), ones=f(scratch.ones, (g,)),
        M=f(scratch.M, (11, 3, 3, g)), Emean=f(scratch.Emean, (3, 3, g)), pressure=f(scratch.pressure, (g,)),
        volume=f(scratch.volume, (g,)), normal=f(scratch.normal, (g,)), Mb=scratch.Mb, rhs=scratch.rhs)
    return group, points, scratch
