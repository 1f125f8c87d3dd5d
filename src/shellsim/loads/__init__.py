"""External loads, one file per kind: the compiled kernel that turns a kind's tables
(:class:`shellsim.bundles.Loads`) into nodal forces at a time, and :func:`external_forces`,
which adds them all up."""

from __future__ import annotations

from numba import njit

from ..curve_tables import factor
from ..element.frames import to_rotational
from .edge_pressure import edge_pressure_forces
from .nodal import add_dead_forces, add_dead_moments
from .pressure import pressure_forces


@njit(cache=True)
def external_forces(t, model, shape, f_ext, fr_ext, g, scale_pressure, scale_edges):
    """External forces at time t of every load of ``model`` (:class:`shellsim.bundles.Model`)
    on the current ``shape``: f_ext (n, 3) translational and fr_ext (n, 2) rotational,
    both overwritten. g (n, 3), scale_pressure (P,), scale_edges (E,): scratch, so that
    nothing is allocated per step."""
    loads, curves = model.loads, model.curves
    f_ext[:] = 0.0
    g[:] = 0.0
    add_dead_forces(t, curves, loads.force, f_ext)
    add_dead_moments(t, curves, loads.moment, shape.d, g)
    pressure = loads.pressure
    if pressure.elements.shape[0]:
        for m in range(scale_pressure.shape[0]):
            scale_pressure[m] = pressure.value[m] * factor(curves, pressure.curve[m], t)
        pressure_forces(model.rule, model.body.conn, shape, pressure, scale_pressure, f_ext, g)
    edges = loads.edge_pressure
    if edges.edges.shape[0]:
        for m in range(scale_edges.shape[0]):
            scale_edges[m] = edges.value[m] * factor(curves, edges.curve[m], t)
        edge_pressure_forces(shape, edges, scale_edges, f_ext)
    # director-conjugate forces act on the rotational DOFs through the fibre frame
    to_rotational(g, shape.d, shape.e1, fr_ext)
