"""Central-difference time integration (thesis 2.2.6.1, Eqs 3.1-3.2), compiled with numba.

One call of :func:`advance` takes many steps and returns at a requested time (the steps
before it are made equal so that it lands there) or after a number of steps; Python only chooses those
times, re-estimates the critical step and records results in between.

Scheme (velocities at half steps, variable step sizes):
    v(n+1/2) = [(1 - c/2) v(n-1/2) + dt_avg M^-1 (f_ext - f_int)(n)] / (1 + c/2),
    c = damping * dt_avg,  dt_avg = (dt(n-1/2) + dt(n+1/2)) / 2   (start-up: dt(-1/2) = 0),
    x(n+1) = x(n) + dt(n+1/2) v(n+1/2);  directors rotated by dt(n+1/2) w(n+1/2).
Constraints act on the velocities (projection), prescribed translations set them.
Energies: internal and external work by the trapezoidal rule over each step's
increments, kinetic energy of the half-step velocities, work of the damping forces.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..deck.curves import curve_value
from ..element import kernels
from ..element.frames import rotate_director

#: Indices into the work and energy arrays: internal work, kinetic energy, external work,
#: damping work.
INTERNAL, KINETIC, EXTERNAL, DAMPED = range(4)


@njit(cache=True)
def _factor(index, time, curve_t, curve_v, curve_len, curve_interp, curve_extrap):
    if index < 0:
        return 1.0
    n = curve_len[index]
    return curve_value(curve_t[index, :n], curve_v[index, :n], curve_interp[index], curve_extrap[index], time)


@njit(cache=True)
def forces(t, x, d, h, e1, dx, dd, conn, N, dNr, dNs, tie, tie_points, wq, tz, wt, jac0_inv, C, vol_basis, material, incremental, stress,
           dead_force, dead_force_curve, dead_moment, dead_moment_curve, pressure_elements, pressure_face, pressure_value,
           pressure_curve, edge_edges, edge_outward, edge_value, edge_curve,
           curve_t, curve_v, curve_len, curve_interp, curve_extrap, f_int, fr_int, f_ext, fr_ext):
    """Internal and external forces at time t: f_* (n, 3) translational, fr_* (n, 2)
    rotational. See :func:`shellsim.element.kernels.internal_forces` for the arguments."""
    kernels.internal_forces(x, d, h, e1, conn, N, dNr, dNs, tie, tie_points, wq, tz, wt, jac0_inv, C, vol_basis, material, incremental,
                            dx, dd, stress, f_int, fr_int)
    n = x.shape[0]
    f_ext[:] = 0.0
    g = np.zeros((n, 3))
    for k in range(dead_force_curve.shape[0]):
        c = _factor(dead_force_curve[k], t, curve_t, curve_v, curve_len, curve_interp, curve_extrap)
        for node in range(n):
            for i in range(3):
                f_ext[node, i] += c * dead_force[k, node, i]
    # A moment M turns the director by M x d: its director-conjugate force is M x d.
    for k in range(dead_moment_curve.shape[0]):
        c = _factor(dead_moment_curve[k], t, curve_t, curve_v, curve_len, curve_interp, curve_extrap)
        for node in range(n):
            mx, my, mz = c * dead_moment[k, node, 0], c * dead_moment[k, node, 1], c * dead_moment[k, node, 2]
            g[node, 0] += my * d[node, 2] - mz * d[node, 1]
            g[node, 1] += mz * d[node, 0] - mx * d[node, 2]
            g[node, 2] += mx * d[node, 1] - my * d[node, 0]
    if pressure_elements.shape[0]:
        scale = np.empty(pressure_elements.shape[0])
        for m in range(scale.shape[0]):
            scale[m] = pressure_value[m] * _factor(pressure_curve[m], t, curve_t, curve_v, curve_len,
                                                   curve_interp, curve_extrap)
        kernels.pressure_forces(x, d, h, conn, pressure_elements, pressure_face, scale, N, dNr, dNs, wq, f_ext, g)
    if edge_edges.shape[0]:
        scale = np.empty(edge_edges.shape[0])
        for m in range(scale.shape[0]):
            scale[m] = edge_value[m] * _factor(edge_curve[m], t, curve_t, curve_v, curve_len,
                                               curve_interp, curve_extrap)
        kernels.edge_pressure_forces(x, d, h, edge_edges, edge_outward, scale, f_ext)
    # Director-conjugate forces act on the rotational DOFs through the current fibre
    # frame: -e1f.g, -e2f.g.
    kernels._to_rotational(g, d, e1, fr_ext)


@njit(cache=True)
def advance(t, t_stop, max_steps, dt, dt_prev, x, x0, d, e1, h, v, w, theta, mt, mr, projector,
            rot_free, prescribed_nodes, prescribed_axes, prescribed_values, prescribed_curves,
            prescribed_velocity, damping,
            conn, N, dNr, dNs, tie, tie_points, wq, tz, wt, jac0_inv, C, vol_basis, material, incremental, stress,
            dead_force, dead_force_curve, dead_moment, dead_moment_curve, pressure_elements, pressure_face, pressure_value,
            pressure_curve, edge_edges, edge_outward, edge_value, edge_curve,
            curve_t, curve_v, curve_len, curve_interp, curve_extrap,
            f_int, fr_int, f_ext, fr_ext, work, energy):
    """Take central-difference steps of size ``dt`` until ``t_stop`` or ``max_steps``.

    On entry the forces f_int, fr_int, f_ext, fr_ext must be those at time t; on return
    they are those at the returned time. ``dt_prev`` is the previous step (0 before the
    first step, which makes it the start-up half step). All state arrays are updated in
    place. ``work`` (4,) accumulates internal, external and damping work to the current
    time; ``energy`` (4,) is the balance at the start of the last step taken, whose
    kinetic energy 1/2 v(n-1/2) M v(n+1/2) is the one central differences conserve
    exactly with the trapezoidal works (a linear undamped system keeps
    internal + kinetic - external constant to round-off). Returns (t, dt_prev, steps).
    """
    n = x.shape[0]
    dx = np.zeros((n, 3))
    dd = np.zeros((n, 3))
    d_old = np.empty(3)
    a = np.empty(3)
    steps = 0
    while steps < max_steps and t < t_stop:
        # Equal steps no longer than dt up to t_stop: a single shortened last step would
        # alternate long and short steps at every stop, which pumps energy into the
        # highest modes when dt is near the critical step.
        remaining = t_stop - t
        step = remaining / max(1.0, np.ceil(remaining / dt - 1e-9))
        dt_avg = 0.5 * (dt_prev + step)
        c = damping * dt_avg
        work_ext = 0.0
        work_int = 0.0
        kinetic = 0.0
        for node in range(n):
            # translations: velocity update, constraint projection
            for i in range(3):
                a[i] = ((1.0 - 0.5 * c) * v[node, i] + dt_avg * (f_ext[node, i] - f_int[node, i]) / mt[node]) / (1.0 + 0.5 * c)
            for i in range(3):
                v_new = projector[node, i, 0] * a[0] + projector[node, i, 1] * a[1] + projector[node, i, 2] * a[2]
                kinetic += 0.5 * mt[node] * v[node, i] * v_new
                v[node, i] = v_new
            for j in range(2):
                w_new = rot_free[node, j] * ((1.0 - 0.5 * c) * w[node, j]
                                             + dt_avg * (fr_ext[node, j] - fr_int[node, j]) / mr[node]) / (1.0 + 0.5 * c)
                kinetic += 0.5 * mr[node] * w[node, j] * w_new
                w[node, j] = w_new
        for p in range(prescribed_nodes.shape[0]):
            node, i = prescribed_nodes[p], prescribed_axes[p]
            target = x0[node, i] + prescribed_values[p] * _factor(
                prescribed_curves[p], t + step, curve_t, curve_v, curve_len, curve_interp, curve_extrap)
            v_new = (target - x[node, i]) / step
            # the support's reaction (inertia less applied forces) works on the motion
            reaction = (mt[node] * (v_new - prescribed_velocity[p]) / dt_avg
                        - (f_ext[node, i] - f_int[node, i]))
            work_ext += reaction * v_new * step
            kinetic += 0.5 * mt[node] * (prescribed_velocity[p] * v_new - v[node, i] * v[node, i])
            v[node, i] = v_new
            prescribed_velocity[p] = v_new
        energy[INTERNAL] = work[INTERNAL]
        energy[KINETIC] = kinetic
        energy[EXTERNAL] = work[EXTERNAL]
        energy[DAMPED] = work[DAMPED]
        for node in range(n):
            for i in range(3):
                dx[node, i] = step * v[node, i]
                x[node, i] += dx[node, i]
            d_old[:] = d[node]
            rotate_director(d[node], e1[node], step * w[node, 0], step * w[node, 1])
            for i in range(3):
                dd[node, i] = d[node, i] - d_old[i]
            theta[node, 0] += step * w[node, 0]
            theta[node, 1] += step * w[node, 1]
        # trapezoidal work: first half with the forces at t, second with those at t + step
        for node in range(n):
            for i in range(3):
                work_ext += 0.5 * f_ext[node, i] * dx[node, i]
                work_int += 0.5 * f_int[node, i] * dx[node, i]
            for j in range(2):
                work_ext += 0.5 * fr_ext[node, j] * step * w[node, j]
                work_int += 0.5 * fr_int[node, j] * step * w[node, j]
        t += step
        forces(t, x, d, h, e1, dx, dd, conn, N, dNr, dNs, tie, tie_points, wq, tz, wt, jac0_inv, C, vol_basis, material, incremental, stress,
               dead_force, dead_force_curve, dead_moment, dead_moment_curve, pressure_elements, pressure_face, pressure_value,
               pressure_curve, edge_edges, edge_outward, edge_value, edge_curve,
               curve_t, curve_v, curve_len, curve_interp, curve_extrap, f_int, fr_int, f_ext, fr_ext)
        damped = 0.0
        for node in range(n):
            for i in range(3):
                work_ext += 0.5 * f_ext[node, i] * dx[node, i]
                work_int += 0.5 * f_int[node, i] * dx[node, i]
                damped += damping * mt[node] * v[node, i] * dx[node, i]
            for j in range(2):
                work_ext += 0.5 * fr_ext[node, j] * step * w[node, j]
                work_int += 0.5 * fr_int[node, j] * step * w[node, j]
                damped += damping * mr[node] * w[node, j] * w[node, j] * step
        work[INTERNAL] += work_int
        work[EXTERNAL] += work_ext
        work[DAMPED] += damped
        dt_prev = step
        steps += 1
        if not np.isfinite(work_int + work_ext + kinetic):
            energy[INTERNAL] = work[INTERNAL]  # let the caller see the failure at once
            break
    return t, dt_prev, steps
