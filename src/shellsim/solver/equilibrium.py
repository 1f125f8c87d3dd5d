"""Static equilibrium of a simulation's state: the residual force over the unknowns, the
tangent stiffness assembled sparse, and the state moved by a correction; in an implicit
time step, with the inertia's share of both (:mod:`.implicit`).

The residual is what the time loop computes, f_ext(t) - f_int, for every formulation,
material and load (fibre-length update included), taken over the unknowns of
:mod:`.unknowns`. The tangent is the sum of the elements' own (:mod:`shellsim.element.tangent`),
less the derivative of the loads that turn with the shell (each load kind's own,
:class:`shellsim.loads.LoadTangents`). The incremental formulations measure their strain from the last converged
state, so every evaluation starts from its stresses and fibre lengths.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..element.frames import rotate_directors
from ..element.static_loop import ElementLoop
from ..element.tangent import ELEMENT_DOFS
from ..curve_tables import factor
from ..loads import LoadTangents
from ..model import Model
from .simulation import Simulation
from .tangent_pattern import tangent_pattern
from .unknowns import SLOTS, unknowns

#: Central-difference steps (the loads' tangents, the elements' check): a share of the mean
#: element size, and radians.
STEP_SHARE, STEP_ROTATION = 1e-6, 1e-6
#: Forward-difference steps of the elements' tangents: near sqrt(eps) (see
#: :mod:`shellsim.element.tangent`).
FORWARD_SHARE, FORWARD_ROTATION = 3e-9, 1e-7


class Converged:
    """A copy of the state's shape, rotations and stresses, to go back to."""

    def __init__(self, sim: Simulation):
        s = sim.state
        self.t = s.t
        self.arrays = {name: getattr(s, name).copy() for name in ("x", "d", "e1", "h", "theta", "stress")}

    def restore(self, sim: Simulation) -> None:
        for name, values in self.arrays.items():
            getattr(sim.state, name)[:] = values
        sim.state.t = self.t


class Equilibrium:
    """Residual, tangent and corrections of ``sim``'s state (a :class:`Simulation`)."""

    def __init__(self, sim: Simulation):
        self.sim = sim
        model = sim.model
        self.unknowns = unknowns(model)
        self.incremental = model.material.incremental
        self.converged = Converged(sim)
        conn = model.conn
        #: the mean element size (a diagonal of each), the unit of the difference steps
        self.element_size = float(np.mean(np.linalg.norm(model.x0[conn[:, 2]] - model.x0[conn[:, 0]], axis=1)))
        self.step_u = STEP_SHARE * self.element_size
        self._t = 0.0
        #: the element tangents: the static element loop's, or one of its own beside a time loop
        self._elements = sim.elements or ElementLoop(sim.response)
        self._load_tangents = LoadTangents(model)
        #: where the element blocks go in the tangent
        self.pattern = tangent_pattern(model.conn, self.unknowns)
        self._frames()
        #: the inertia of an implicit time step (:class:`shellsim.solver.implicit.HHT`); None: static
        self.inertia = None

    def _frames(self) -> None:
        """Each element's node frames, to turn its block into the unknowns' directions."""
        u, model = self.unknowns, self.sim.model
        # each node's frame as a (5, 5) block: the translations turned, the rotations kept
        blocks = np.zeros((model.n_nodes, SLOTS, SLOTS))
        blocks[:, :3, :3] = u.frames
        blocks[:, 3, 3] = blocks[:, 4, 4] = 1.0
        # only the elements at a support are turned: on Scordelis-Lo 16 x 16, 46 of 256 in
        # 0.4 ms, where turning all took 1.9 ms of a 0.11 s solve
        turned_nodes = ~np.all(np.isclose(u.frames, np.eye(3)), axis=(1, 2))
        self._turned = np.flatnonzero(turned_nodes[model.conn].any(axis=1))  # (m,) elements
        self._element_blocks = blocks[model.conn[self._turned]]  # (m, 9, 5, 5)

    # --- the state -------------------------------------------------------------------
    def evaluate(self, t: float) -> None:
        """Internal and external forces at the state's shape and load time t, the
        incremental formulations from the converged state."""
        self._t = t
        s, space = self.sim.state, self.sim.workspace
        if self.incremental:
            c = self.converged.arrays
            np.subtract(s.x, c["x"], out=space.dx)
            np.subtract(s.d, c["d"], out=space.dd)
            s.stress[:] = c["stress"]
            s.h[:] = c["h"]
        if self.inertia is not None and self.sim.workspace.friction:
            self.inertia.move_velocities()  # the contacts' friction opposes them
        self.sim.compute_forces(t)

    def residual(self) -> np.ndarray:
        """f_ext - f_int over the unknowns (size,) from the last :meth:`evaluate`."""
        s = self.sim.state
        f, fr = s.f_ext - s.f_int, s.fr_ext - s.fr_int
        if self.inertia is not None:
            f, fr = self.inertia.balanced(f, fr)
        return self.unknowns.gather(self.unknowns.to_local(f, fr))

    def force_scale(self) -> float:
        """The larger of the external and internal force norms over every DOF (supports'
        included, so that a displacement-driven scene has a scale)."""
        s = self.sim.state
        ext = np.sqrt(np.sum(s.f_ext**2) + np.sum(s.fr_ext**2))
        internal = np.sqrt(np.sum(s.f_int**2) + np.sum(s.fr_int**2))
        inertial = self.inertia.inertial_scale() if self.inertia is not None else 0.0
        return float(max(ext, internal, inertial))

    def move(self, correction: np.ndarray) -> None:
        """Add a correction (size,) of the unknowns to the state: translations along the
        nodes' frames, rotations of the directors."""
        s = self.sim.state
        local = self.unknowns.scatter(correction)
        s.x += np.einsum("nij,nj->ni", self.unknowns.frames, local[:, :3])
        nodes = np.flatnonzero(np.any(local[:, 3:] != 0.0, axis=1))
        rotate_directors(s.d, s.e1, nodes, np.ascontiguousarray(local[nodes, 3:]))
        s.theta += local[:, 3:]

    def prescribed_increments(self, t: float) -> np.ndarray:
        """(n_known,) the moves that bring the prescribed translations to their values at t."""
        model, s = self.sim.model, self.sim.state
        p = model.constraints.prescribed
        targets = np.array([model.x0[n, a] + v * factor(model.curves, c, t)
                            for n, a, v, c in zip(p.nodes, p.axes, p.values, p.curves)])
        return targets - s.x[p.nodes, p.axes] if len(p.nodes) else np.zeros(0)

    # --- the tangent -----------------------------------------------------------------
    def tangent(self, central: bool = False) -> sp.csc_matrix:
        """K (n_free, size) = d(f_int - f_ext)/du at the state and load time of the last
        :meth:`evaluate` (its increments and pressures): the free rows, the free columns
        first, then the prescribed ones. The elements' part by forward differences, or by
        central ones when ``central`` (twice the cost; the check of the forward ones)."""
        model, s, space = self.sim.model, self.sim.state, self.sim.workspace
        c = self.converged.arrays
        shape = s.fields.shape
        if self.incremental:  # the increments are measured with the converged lengths
            shape = shape._replace(h=c["h"])
        # every element's block is overwritten, the loads' added in place; made anew for each
        # tangent, so that it is gone while the tangent is factorised (16 kB an element)
        k = np.empty((model.n_elements, ELEMENT_DOFS, ELEMENT_DOFS))
        steps = (self.step_u, STEP_ROTATION) if central else (FORWARD_SHARE * self.element_size, FORWARD_ROTATION)
        converged = (space.dx, space.dd, c["stress"])
        self._elements.tangents(model.structure, shape, converged, steps, central, space.parts, k)
        self._load_tangents(self._t, s.fields.shape, self.step_u, STEP_ROTATION, k)
        if len(self._turned):
            turned, blocks = self._turned, self._element_blocks
            k[turned] = np.einsum("eaij,eaibk,ebkl->eajbl", blocks, k[turned].reshape(len(turned), 9, SLOTS, 9, SLOTS),
                                  blocks, optimize=True).reshape(len(turned), ELEMENT_DOFS, ELEMENT_DOFS)
        tangent = self.pattern.assemble(k)
        del k
        coupled = self._coupled()
        tangent = tangent if coupled is None else (tangent - coupled).tocsc()
        return tangent if self.inertia is None else self.inertia.tangent(tangent, self._free_masses())

    def _free_masses(self) -> np.ndarray:
        """(n_free,) the lumped mass of each free unknown: a node's translational mass, or
        its rotary mass for a rotation."""
        s = self.sim.state
        local = np.column_stack([s.mt, s.mt, s.mt, s.mr, s.mr])
        return self.unknowns.gather(local)[:self.unknowns.n_free]

    def _coupled(self) -> sp.coo_matrix | None:
        """The derivative of the forces that couple nodes sharing no element (contact
        between shells, and its friction in an implicit step) over the unknowns, in the
        nodes' frames; None where there is none."""
        u, s = self.unknowns, self.sim.state
        motion = None if self.inertia is None else (s.v, self.inertia.velocity_rate)
        nodes, blocks = self._load_tangents.couplings(self._t, s.fields.shape, self.step_u, motion)
        if not len(nodes):
            return None
        frames = u.frames[nodes]  # (P, 10, 3, 3): node translations' directions as columns
        blocks = np.einsum("paij,paibk,pbkl->pajbl", frames, blocks.reshape(-1, 10, 3, 10, 3), frames,
                           optimize=True)
        dofs = u.index[nodes][:, :, :3].reshape(len(nodes), 30)
        rows = np.broadcast_to(dofs[:, :, None], (len(nodes), 30, 30)).ravel()
        cols = np.broadcast_to(dofs[:, None, :], (len(nodes), 30, 30)).ravel()
        used = (rows >= 0) & (rows < u.n_free) & (cols >= 0)
        return sp.coo_matrix((blocks.ravel()[used], (rows[used], cols[used])), shape=(u.n_free, u.size))


def warmed(model: Model) -> Equilibrium:
    """The static equilibrium of ``model`` at rest, its residual evaluated and a tangent
    formed once: the kernels a Newton path calls compiled, or loaded from numba's cache,
    before anything that follows is timed."""
    equilibrium = Equilibrium(Simulation(model))
    equilibrium.evaluate(0.0)
    equilibrium.tangent()
    return equilibrium
