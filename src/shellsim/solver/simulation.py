"""The state of a running scene and the operations on it: masses, critical step, advancing
in time. Holds arrays only; the time loop itself is compiled (:mod:`.explicit`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..element import kernels
from ..element.sampling import point_tensors
from ..errors import NumericalError
from ..model import Model
from . import explicit
from .timestep import critical_time_step


@dataclass
class State:
    """Solution at time t (shapes: n nodes, ne elements, nq x nt integration points).

    x, d [n, 3]: mid-surface positions, unit directors; e1 [n, 3]: fibre-frame first axes;
    h [n]: fibre lengths; v [n, 3], w [n, 2]: translational and rotational velocities at
    the last half step; theta [n, 2]: accumulated rotations; mt, mr [n]: lumped masses;
    stress [ne, nq, nt, 5]: lamina Cauchy stress (s11, s22, s12, s13, s23);
    f_int, f_ext [n, 3], fr_int, fr_ext [n, 2]: forces at t;
    work [4]: internal, (unused), external and damping work to t;
    energy [4]: internal work, kinetic energy, external work, damping work at the start of
        the last step (see :func:`shellsim.solver.explicit.advance`).
    """

    t: float
    x: np.ndarray
    d: np.ndarray
    e1: np.ndarray
    h: np.ndarray
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
    work: np.ndarray = field(default_factory=lambda: np.zeros(4))
    energy: np.ndarray = field(default_factory=lambda: np.zeros(4))
    dt_prev: float = 0.0
    steps: int = 0


class Simulation:
    """A model and its state, advanced by central differences."""

    def __init__(self, model: Model):
        self.model = model
        n, ne, nq, nt = model.n_nodes, model.n_elements, len(model.wq), len(model.tz)
        self.state = State(
            t=0.0, x=model.x0.copy(), d=model.d0.copy(), e1=model.e1f0.copy(), h=model.h0.copy(),
            v=np.zeros((n, 3)), w=np.zeros((n, 2)), theta=np.zeros((n, 2)),
            mt=np.zeros(n), mr=np.zeros(n), stress=np.zeros((ne, nq, nt, 5)),
            f_int=np.zeros((n, 3)), fr_int=np.zeros((n, 2)), f_ext=np.zeros((n, 3)), fr_ext=np.zeros((n, 2)),
            prescribed_velocity=np.zeros(len(model.prescribed_nodes)),
        )
        self._eigenvector: np.ndarray | None = None
        self.update_masses()
        self.evaluate_forces()

    def update_masses(self) -> None:
        """Lumped masses on the current configuration (M1 or M2, thesis 3.14)."""
        m, s = self.model, self.state
        kernels.lumped_masses(s.x, s.d, s.h, m.conn, m.N, m.dNr, m.dNs, m.wq, m.tz, m.wt, m.density,
                              m.mass == "M1", s.mt, s.mr)

    def volume(self, initial: bool = False) -> float:
        """Volume of the shell body now (or at the start) [length^3]: int dv over every
        element, the translational M2 masses at unit density."""
        m, s = self.model, self.state
        x, d, h = (m.x0, m.d0, m.h0) if initial else (s.x, s.d, s.h)
        mt, mr = np.empty(m.n_nodes), np.empty(m.n_nodes)
        kernels.lumped_masses(x, d, h, m.conn, m.N, m.dNr, m.dNs, m.wq, m.tz, m.wt, 1.0, False, mt, mr)
        return float(mt.sum())

    def point_tensors(self, elements=slice(None), points=slice(None)) -> tuple[np.ndarray, ...]:
        """(lamina stress, global Cauchy stress, Green-Lagrange strain) now at the
        integration points of ``elements`` and in-plane ``points`` (slices), each
        (elements, points, nt, 3, 3); see :func:`shellsim.element.sampling.point_tensors`."""
        m, s = self.model, self.state
        nq = len(m.wq)
        conn = m.conn[elements]
        N, dNr, dNs = m.N[:nq][points], m.dNr[:nq][points], m.dNs[:nq][points]
        out = [np.empty((len(conn), len(N), len(m.tz), 3, 3)) for _ in range(3)]
        point_tensors(s.x, s.d, s.h, conn, N, dNr, dNs, m.tz, m.jac0_inv[elements][:, :nq][:, points],
                      s.stress[elements][:, points], *out)
        return tuple(out)

    def critical_time_step(self) -> float:
        """dt_critical = 2 / omega_max at the current state (warm-started Lanczos)."""
        dt, self._eigenvector = critical_time_step(self, self._eigenvector)
        return dt

    def _arguments(self) -> tuple:
        m, s = self.model, self.state
        return (m.conn, m.N, m.dNr, m.dNs, m.tie, m.tie_points, m.wq, m.tz, m.wt, m.jac0_inv, m.C, m.vol_basis, m.material, m.incremental, s.stress,
                m.dead_force, m.dead_force_curve, m.dead_moment, m.dead_moment_curve, m.pressure_elements, m.pressure_face,
                m.pressure_value, m.pressure_curve, m.edge_pressure_edges, m.edge_pressure_outward,
                m.edge_pressure_value, m.edge_pressure_curve, m.curve_t, m.curve_v, m.curve_len,
                m.curve_interp, m.curve_extrap)

    def evaluate_forces(self) -> None:
        """Internal and external forces and the stresses at the current state and time."""
        s = self.state
        zero = np.zeros_like(s.x)
        explicit.forces(s.t, s.x, s.d, s.h, s.e1, zero, zero, *self._arguments(),
                        s.f_int, s.fr_int, s.f_ext, s.fr_ext)

    def advance(self, t_stop: float, dt: float, max_steps: int) -> int:
        """Step with ``dt`` until ``t_stop`` (landing on it) or ``max_steps``; returns the
        number of steps taken."""
        s = self.state
        try:
            s.t, s.dt_prev, steps = self._advance(t_stop, dt, max_steps)
        except (ZeroDivisionError, FloatingPointError) as error:
            # a director or frame collapsed: the state has degenerated beyond recovery
            raise NumericalError(f"the run broke down at t = {s.t:.6g} after {s.steps} steps: "
                                 f"a degenerate state ({error}); the motion had become unstable") from None
        s.steps += steps
        return steps

    def _advance(self, t_stop: float, dt: float, max_steps: int) -> tuple[float, float, int]:
        m, s = self.model, self.state
        return explicit.advance(
            s.t, t_stop, max_steps, dt, s.dt_prev, s.x, m.x0, s.d, s.e1, s.h, s.v, s.w, s.theta,
            s.mt, s.mr, m.projector, m.rot_free, m.prescribed_nodes, m.prescribed_axes,
            m.prescribed_values, m.prescribed_curves, s.prescribed_velocity, m.damping,
            *self._arguments(), s.f_int, s.fr_int, s.f_ext, s.fr_ext, s.work, s.energy)
