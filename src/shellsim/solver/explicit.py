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
increments, kinetic energy of the half-step velocities, work of the damping forces, and
the energy friction takes (the work of the contacts' friction forces, negated, apart from
the external work).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ..curve_tables import factor
from ..element.assembly import Assembly, assembly, internal_forces
from ..element.frames import rotate_director
from ..loads import external_forces, friction_forces, has_friction

#: Indices into the work and energy arrays: internal work, kinetic energy, external work
#: (friction's apart), damping work, friction work (the energy friction takes out).
ENERGIES = 5
INTERNAL, KINETIC, EXTERNAL, DAMPED, FRICTION = range(ENERGIES)


#: Nodes per block of the time loop's parallel node loops: a block's energies are summed
#: node by node, then the blocks' in order, the same bits on any number of threads.
NODE_BLOCK = 256


class Workspace(NamedTuple):
    """Scratch of the time loop, allocated once per simulation (n nodes): dx, dd (n, 3)
    the last step's mid-surface and director increments; g (n, 3) director-conjugate
    external forces; parts: the element results before assembly (:class:`shellsim.element.assembly.Assembly`);
    friction: whether the contacts have friction, then f_fr (n, 3), fr_fr (n, 2) its
    forces at t (part of the external ones; (0, 3), (0, 2) without); relax (2,): under
    kinetic damping, the last step's kinetic energy and the count of velocity resets;
    sums (blocks, 3): the node loops' energies block by block (:data:`NODE_BLOCK`)."""

    dx: np.ndarray
    dd: np.ndarray
    g: np.ndarray
    parts: Assembly
    friction: bool
    f_fr: np.ndarray
    fr_fr: np.ndarray
    relax: np.ndarray
    sums: np.ndarray


def workspace(model) -> Workspace:
    """A :class:`Workspace` for ``model`` (:class:`shellsim.bundles.Model`)."""
    n = model.x0.shape[0]
    friction = has_friction(model)
    m = n if friction else 0
    return Workspace(dx=np.zeros((n, 3)), dd=np.zeros((n, 3)), g=np.zeros((n, 3)),
                     parts=assembly(n, len(model.body.conn)), friction=friction,
                     f_fr=np.zeros((m, 3)), fr_fr=np.zeros((m, 2)), relax=np.zeros(2),
                     sums=np.zeros((-(-n // NODE_BLOCK), 3)))


# only ever inlined into the time loop (see shellsim.element.assembly.internal_forces), so
# never compiled, nor cached, on its own; from Python: Simulation.compute_forces, through
# the time loop (advance with ``fresh``) or, in a static run, the element loop
@njit(inline="always")
def forces(response, t, model, fields, space):
    """Internal and external forces at time t into ``fields`` (:class:`shellsim.bundles.Fields`):
    f_* (n, 3) translational, fr_* (n, 2) rotational, and the stresses. The internal
    forces of the incremental formulation take the last step's increments from ``space``;
    ``response``: the element response by its address."""
    internal_forces(response, (model.rule, model.body, model.material), fields.shape, space.dx, space.dd, fields.stress,
                    fields.f_int, fields.fr_int, space.parts)
    applied_forces(t, model, fields, space)


@njit(cache=True, inline="always")
def applied_forces(t, model, fields, space):
    """The external forces at time t on the shape of ``fields``, into its f_ext (n, 3) and
    fr_ext (n, 2): every load's, and the contacts' friction at its velocities."""
    external_forces(t, model, fields.shape, fields.f_ext, fields.fr_ext, space.g)
    if space.friction:
        friction_forces(t, model, fields.shape, fields.v, fields.w, space.f_fr, space.fr_fr, space.g)
        f_ext, fr_ext = fields.f_ext, fields.fr_ext
        f_ext += space.f_fr
        fr_ext += space.fr_fr


@njit(cache=True, inline="always")
def _block(b, n):
    """The nodes first..last-1 of block b of n nodes."""
    return b * NODE_BLOCK, min(n, (b + 1) * NODE_BLOCK)


@njit(cache=True, inline="always")
def _in_order(sums, column):
    """The blocks' sums (blocks, 3) of one column, added in block order."""
    total = 0.0
    for b in range(sums.shape[0]):
        total += sums[b, column]
    return total


@njit(cache=True, inline="always")
def _half_work(f, fr, dx, w, step, node):
    """Half the work at ``node`` of the forces f (n, 3), fr (n, 2) over the translations
    dx (n, 3) and the rotations step * w (n, 2): one half of the trapezoidal rule."""
    work = 0.0
    for i in range(3):
        work += 0.5 * f[node, i] * dx[node, i]
    for j in range(2):
        work += 0.5 * fr[node, j] * step * w[node, j]
    return work


@njit(cache=True, inline="always")
def _weighted_dots(total, node, translations, rotations):
    """``total`` + mass a.b + rotary p.q scale at ``node``, translations (mass, a, b) with
    a, b (n, 3) and rotations (rotary, p, q, scale) with p, q (n, 2), added term by term:
    a block's sum of the kinetic energy or of the damping's work."""
    mass, a, b = translations
    rotary, p, q, scale = rotations
    for i in range(3):
        total += mass * a[node, i] * b[node, i]
    for j in range(2):
        total += rotary * p[node, j] * q[node, j] * scale
    return total


@njit(cache=True, parallel=True)
def half_works(fields, space, step):
    """Half the works of the step ``step`` long that ``space.dx`` and ``fields.w`` make:
    (external, internal, friction's) by the forces in ``fields`` and ``space`` now."""
    f_int, fr_int, f_ext, fr_ext, w = fields.f_int, fields.fr_int, fields.f_ext, fields.fr_ext, fields.w
    f_fr, fr_fr, dx, sums, friction = space.f_fr, space.fr_fr, space.dx, space.sums, space.friction
    n = dx.shape[0]
    for b in prange(sums.shape[0]):
        first, last = _block(b, n)
        external = internal = rubbed = 0.0
        for node in range(first, last):
            external += _half_work(f_ext, fr_ext, dx, w, step, node)
            internal += _half_work(f_int, fr_int, dx, w, step, node)
            if friction:
                rubbed += _half_work(f_fr, fr_fr, dx, w, step, node)
        sums[b, 0], sums[b, 1], sums[b, 2] = external, internal, rubbed
    return _in_order(sums, 0), _in_order(sums, 1), _in_order(sums, 2)


@njit(cache=True, parallel=True)
def kinetic_energy(v, w, mt, mr, sums):
    """1/2 v M v + 1/2 w M_r w of the velocities v (n, 3), w (n, 2), masses mt, mr (n,);
    sums (blocks, 3) scratch."""
    n = v.shape[0]
    for b in prange(sums.shape[0]):
        first, last = _block(b, n)
        energy = 0.0
        for node in range(first, last):
            energy = _weighted_dots(energy, node, (0.5 * mt[node], v, v), (0.5 * mr[node], w, w, 1.0))
        sums[b, 0] = energy
    return _in_order(sums, 0)


@njit(cache=True)
def kinetic_damping(v, w, mt, mr, kinetic, work, relax, sums):
    """Dynamic relaxation by kinetic damping: when the kinetic energy of the new
    velocities v (n, 3), w (n, 2) is below the last step's (a peak has passed), every one
    is set to zero, and ``kinetic``, the step's kinetic energy on record, is taken out as
    damping work. relax (2,): the last step's kinetic energy, the count of resets; sums
    (blocks, 3) scratch. Returns the step's kinetic energy on record."""
    now = kinetic_energy(v, w, mt, mr, sums)
    if now >= relax[0]:
        relax[0] = now
        return kinetic
    v[:] = 0.0
    w[:] = 0.0
    relax[0] = 0.0
    relax[1] += 1.0
    work[DAMPED] += kinetic
    return 0.0


@njit(cache=True, parallel=True)
def update_velocities(fields, projector, rot_free, c, dt_avg, sums):
    """The velocities v (n, 3), w (n, 2) of ``fields`` a step of average length ``dt_avg``
    on, from their forces, damped by c = damping * dt_avg and projected on what the
    supports allow (projector (n, 3, 3), rot_free (n, 2)), in place; sums (blocks, 3)
    scratch. Returns the kinetic energy 1/2 v(n-1/2) M v(n+1/2) that central differences
    conserve."""
    v, w, mt, mr = fields.v, fields.w, fields.mt, fields.mr
    f_int, fr_int, f_ext, fr_ext = fields.f_int, fields.fr_int, fields.f_ext, fields.fr_ext
    n = v.shape[0]
    for b in prange(sums.shape[0]):
        first, last = _block(b, n)
        kinetic = 0.0
        for node in range(first, last):
            a0 = ((1.0 - 0.5 * c) * v[node, 0] + dt_avg * (f_ext[node, 0] - f_int[node, 0]) / mt[node]) / (1.0 + 0.5 * c)
            a1 = ((1.0 - 0.5 * c) * v[node, 1] + dt_avg * (f_ext[node, 1] - f_int[node, 1]) / mt[node]) / (1.0 + 0.5 * c)
            a2 = ((1.0 - 0.5 * c) * v[node, 2] + dt_avg * (f_ext[node, 2] - f_int[node, 2]) / mt[node]) / (1.0 + 0.5 * c)
            for i in range(3):
                v_new = projector[node, i, 0] * a0 + projector[node, i, 1] * a1 + projector[node, i, 2] * a2
                kinetic += 0.5 * mt[node] * v[node, i] * v_new
                v[node, i] = v_new
            for j in range(2):
                w_new = rot_free[node, j] * ((1.0 - 0.5 * c) * w[node, j]
                                             + dt_avg * (fr_ext[node, j] - fr_int[node, j]) / mr[node]) / (1.0 + 0.5 * c)
                kinetic += 0.5 * mr[node] * w[node, j] * w_new
                w[node, j] = w_new
        sums[b, 0] = kinetic
    return _in_order(sums, 0)


@njit(cache=True, parallel=True)
def move(fields, space, step, damping):
    """The shape of ``fields`` moved by its velocities over ``step``, in place: positions,
    directors (rotated, their fibre frames with them) and rotation angles; the moves dx and
    director changes dd (n, 3) into ``space``. Returns the work of mass-proportional
    damping ``damping`` [1/s] over the step, c m v . dx on the translations and
    c m_r w . w step on the rotations."""
    x, d, e1, v, w, theta = fields.shape.x, fields.shape.d, fields.shape.e1, fields.v, fields.w, fields.theta
    mt, mr, dx, dd, sums = fields.mt, fields.mr, space.dx, space.dd, space.sums
    n = x.shape[0]
    for b in prange(sums.shape[0]):
        first, last = _block(b, n)
        damped = 0.0
        for node in range(first, last):
            for i in range(3):
                dx[node, i] = step * v[node, i]
                x[node, i] += dx[node, i]
            d0, d1, d2 = d[node, 0], d[node, 1], d[node, 2]
            rotate_director(d[node], e1[node], step * w[node, 0], step * w[node, 1])
            dd[node, 0], dd[node, 1], dd[node, 2] = d[node, 0] - d0, d[node, 1] - d1, d[node, 2] - d2
            theta[node, 0] += step * w[node, 0]
            theta[node, 1] += step * w[node, 1]
            damped = _weighted_dots(damped, node, (damping * mt[node], v, dx), (damping * mr[node], w, w, step))
        sums[b, 0] = damped
    return _in_order(sums, 0)


@njit(cache=True)
def equal_step(remaining, dt):
    """The step that covers ``remaining`` time in equal steps no longer than ``dt``: a
    single shortened last step would alternate long and short steps at every stop, which
    pumps energy into the highest modes when dt is near the critical step."""
    return remaining / max(1.0, np.ceil(remaining / dt - 1e-9))


@njit(cache=True)
def advance(response, t, t_stop, max_steps, dt, dt_prev, model, fields, space, fresh):  # noqa: PLR0913 (Python's one entry)
    """Take central-difference steps of size ``dt`` until ``t_stop`` or ``max_steps``.

    response: the element response by its address
    (:func:`shellsim.element.response.response_by_address`);
    model: :class:`shellsim.bundles.Model`; fields: :class:`shellsim.bundles.Fields`,
    updated in place; space: a :class:`Workspace`. On entry the forces in ``fields``
    must be those at time t; on return they are those at the returned time. ``dt_prev``
    is the previous step (0 before the first step, which makes it the start-up half
    step). ``fields.work`` (5,) accumulates internal, external, damping and friction work
    (indexed as :data:`INTERNAL` ...) to the current time; ``fields.energy`` (5,) is the
    balance at the start of the last step taken, whose kinetic energy 1/2 v(n-1/2) M v(n+1/2) is the one central differences
    conserve exactly with the trapezoidal works (a linear undamped system keeps
    internal + kinetic - external constant to round-off). Returns (t, dt_prev, steps).
    ``fresh``: the forces are evaluated at t first (``max_steps`` 0: only they), so that
    an explicit run's forces from Python come from the time loop it compiles anyway, not
    from an element loop and loads compiled once more (5-10 s of a first run).
    """
    x, v, w, mt, mr = fields.shape.x, fields.v, fields.w, fields.mt, fields.mr
    f_int, f_ext = fields.f_int, fields.f_ext
    work, energy = fields.work, fields.energy
    projector, rot_free, prescribed = model.constraints.projector, model.constraints.rot_free, model.constraints.prescribed
    prescribed_velocity = fields.prescribed_velocity
    damping = model.damping
    steps = 0
    step = work_ext = work_int = work_fr = kinetic = damped = 0.0  # set by each step's motion, read after its forces
    moved = False  # a step has moved the shape since the forces were evaluated
    # each pass: the forces where the last step (or the caller) left the shape and the step's
    # second half of work with them, then the next step's motion; the forces are evaluated
    # in this one place, as their inlined loads' code compiles once for every caller
    while True:
        if moved or fresh:
            forces(response, t, model, fields, space)
            fresh = False
        if moved:
            # the trapezoidal works' second half, with the forces at the step's end
            external, internal, rubbed = half_works(fields, space, step)
            work_ext += external
            work_int += internal
            work_fr += rubbed
            work[INTERNAL] += work_int
            work[EXTERNAL] += work_ext - work_fr  # the friction forces are among the external ones
            work[DAMPED] += damped
            work[FRICTION] -= work_fr
            dt_prev = step
            steps += 1
            if not np.isfinite(work_int + work_ext + kinetic):
                energy[INTERNAL] = work[INTERNAL]  # let the caller see the failure at once
                break
        moved = False
        if steps >= max_steps or t >= t_stop:
            break
        step = equal_step(t_stop - t, dt)
        dt_avg = 0.5 * (dt_prev + step)
        c = damping * dt_avg
        work_ext = 0.0
        kinetic = update_velocities(fields, projector, rot_free, c, dt_avg, space.sums)
        if t >= model.relax_from:
            kinetic = kinetic_damping(v, w, mt, mr, kinetic, work, space.relax, space.sums)
        for p in range(prescribed.nodes.shape[0]):
            node, i = prescribed.nodes[p], prescribed.axes[p]
            target = model.x0[node, i] + prescribed.values[p] * factor(model.curves, prescribed.curves[p], t + step)
            v_new = (target - x[node, i]) / step
            # the support's reaction (inertia and the damping force it holds off, less the
            # applied forces) works on the motion: it pays the damping work counted there
            reaction = (mt[node] * (v_new - prescribed_velocity[p]) / dt_avg + damping * mt[node] * v_new
                        - (f_ext[node, i] - f_int[node, i]))
            work_ext += reaction * v_new * step
            kinetic += 0.5 * mt[node] * (prescribed_velocity[p] * v_new - v[node, i] * v[node, i])
            v[node, i] = v_new
            prescribed_velocity[p] = v_new
        energy[INTERNAL] = work[INTERNAL]
        energy[KINETIC] = kinetic
        energy[EXTERNAL] = work[EXTERNAL]
        energy[DAMPED] = work[DAMPED]
        energy[FRICTION] = work[FRICTION]
        damped = move(fields, space, step, damping)
        # trapezoidal work: first half with the forces at t, second with those at t + step
        external, work_int, work_fr = half_works(fields, space, step)
        work_ext += external
        t += step
        moved = True
    return t, dt_prev, steps
