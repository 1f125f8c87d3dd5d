"""The state of a running scene and the operations on it: masses, critical step, advancing
in time. Holds arrays only; the time loop itself is compiled (:mod:`.explicit`)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..bundles import Fields, Shape
from ..element.assembly import StiffnessProduct
from ..element.masses import lumped_masses
from ..element.response import group_response, no_response, response_signature
from ..element.sampling import point_tensors
from ..element.static_loop import ElementLoop
from ..compiled_call import TypedCall
from ..compile_beside import CompiledBeside
from ..errors import NumericalError
from ..loads import add_masses, hold_min_steps
from ..model import Model
from ..threads import ThreadChooser, kernel_threads, limit_to_usable_cpus
from . import explicit
from .timestep import critical_time_step


@dataclass
class State:
    """Solution at time t: the arrays (``fields``, :class:`shellsim.bundles.Fields`), read
    by name from the state too (``state.x`` is ``state.fields.shape.x``, ``state.v`` is
    ``state.fields.v``); dt_prev the last step taken (0 before the first); steps taken."""

    t: float
    fields: Fields
    dt_prev: float = 0.0
    steps: int = 0

    def __getattr__(self, name: str):
        fields = self.__dict__.get("fields")
        if fields is None:  # not built yet (copying, unpickling)
            raise AttributeError(name)
        return getattr(fields.shape if name in Shape._fields else fields, name)


class Compiled(NamedTuple):
    """The compiled functions a simulation calls often, each bound to its argument types."""

    advance: TypedCall
    masses: TypedCall
    stiffness: StiffnessProduct
    applied_forces: TypedCall


class Simulation:
    """A model and its state, advanced by central differences. Its forces from Python
    come from the compiled time loop, which an explicit run compiles anyway, or, for a
    ``static`` run, from the element loop, so that a static run compiles no time loop."""

    def __init__(self, model: Model, static: bool = False):
        self.model = model
        n, ne, nq, nt = model.n_nodes, model.n_elements, len(model.rule.wq), len(model.rule.tz)
        shape = Shape(x=model.x0.copy(), d=model.d0.copy(), e1=model.e1f0.copy(), h=model.h0.copy())
        self.state = State(t=0.0, fields=Fields(
            shape=shape, v=np.zeros((n, 3)), w=np.zeros((n, 2)), theta=np.zeros((n, 2)),
            mt=np.zeros(n), mr=np.zeros(n), stress=np.zeros((ne, nq, nt, 5)),
            f_int=np.zeros((n, 3)), fr_int=np.zeros((n, 2)), f_ext=np.zeros((n, 3)), fr_ext=np.zeros((n, 2)),
            prescribed_velocity=np.zeros(len(model.constraints.prescribed.nodes)), work=np.zeros(explicit.ENERGIES),
            energy=np.zeros(explicit.ENERGIES)))
        self.workspace = explicit.workspace(model)
        # on an empty cache the response compiles in a second process while this one
        # compiles the masses and the loops around a stand-in of its type
        response = CompiledBeside(group_response, no_response, response_signature(model.rule, model.material))
        #: the element response, called by its address from every compiled element loop
        self.response = response.held
        self.compiled = Compiled(advance=TypedCall(explicit.advance), masses=TypedCall(lumped_masses),
                                 stiffness=StiffnessProduct(self.response),
                                 applied_forces=TypedCall(explicit.applied_forces))
        #: the internal forces called from Python, where no time loop is compiled
        self.elements = ElementLoop(self.response) if static else None
        #: the critical-step estimator's state, which a checkpoint carries: the last estimate's
        #: eigenvector (5n,), and the generator of the random half of each later estimate's start
        self.eigenvector: np.ndarray | None = None
        self.fresh = np.random.default_rng(0)
        self.threads = ThreadChooser(limit_to_usable_cpus())
        self.mass_factor = 1.0  # every mass scaled by it (mass scaling)
        with response.alongside():
            self.update_masses()
            if response.pending:
                self.evaluate_forces()  # the stand-in's (no internal forces): the loops compile
        self.evaluate_forces()

    def update_masses(self) -> None:
        """Lumped masses on the current configuration (M1 or M2, thesis 3.14), the cables'
        added (those below their min_step made heavier first), all times ``mass_factor``."""
        m, s = self.model, self.state
        self.compiled.masses(m.rule, m.body, s.fields.shape, m.body.density, m.mass == "M1", s.mt, s.mr)
        hold_min_steps(m, s.fields.shape)
        add_masses(m, s.mt, s.mr)
        if self.mass_factor != 1.0:
            s.mt *= self.mass_factor
            s.mr *= self.mass_factor

    def volume(self, initial: bool = False) -> float:
        """Volume of the shell body now (or at the start) [length^3]: int dv over every
        element, the translational M2 masses at unit density."""
        m, s = self.model, self.state
        shape = Shape(x=m.x0, d=m.d0, e1=m.e1f0, h=m.h0) if initial else s.fields.shape
        mt, mr = np.empty(m.n_nodes), np.empty(m.n_nodes)
        self.compiled.masses(m.rule, m.body, shape, np.ones(m.n_elements), False, mt, mr)
        return float(mt.sum())

    def point_tensors(self, elements=slice(None), points=slice(None)) -> tuple[np.ndarray, ...]:
        """(lamina stress, global Cauchy stress, Green-Lagrange strain) now at the
        integration points of ``elements`` and in-plane ``points`` (slices), each
        (elements, points, nt, 3, 3); see :func:`shellsim.element.sampling.point_tensors`."""
        m, s, rule = self.model, self.state, self.model.rule
        nq = len(rule.wq)
        conn = m.conn[elements]
        N, dNr, dNs = rule.N[:nq][points], rule.dNr[:nq][points], rule.dNs[:nq][points]
        out = [np.empty((len(conn), len(N), len(rule.tz), 3, 3)) for _ in range(3)]
        jac0_inv = np.ascontiguousarray(m.body.jac0_inv[elements][:, :nq][:, points])
        point_tensors((s.x, s.d, s.h), conn, (N, dNr, dNs, rule.tz), jac0_inv, s.stress[elements][:, points], tuple(out))
        return tuple(out)

    def critical_time_step(self, on_product: Callable[[int], None] | None = None) -> float:
        """dt_critical = 2 / omega_max at the current state (Lanczos, from the last eigenvector after the first);
        ``on_product(count)`` hears of each stiffness product. Its products run on the
        thread count the steps run on now: on a busy machine, where one thread was
        chosen, all of them stall the estimate as they stalled the steps."""
        with kernel_threads(self.threads.current):
            dt, self.eigenvector = critical_time_step(self, self.eigenvector, on_product, self.fresh)
        return dt

    def evaluate_forces(self) -> None:
        """Internal and external forces and the stresses at the current state and time
        (with no step increment: an incremental stress stays as it is)."""
        self.workspace.dx[:] = 0.0
        self.workspace.dd[:] = 0.0
        self.compute_forces(self.state.t)

    def compute_forces(self, t: float) -> None:
        """Internal and external forces and the stresses at the current shape and load time
        t, the incremental formulation's from the increments in the workspace: what the
        time loop's :func:`~shellsim.solver.explicit.forces` computes, from Python."""
        m, fields, space = self.model, self.state.fields, self.workspace
        if self.elements is None:
            self.compiled.advance(self.response, float(t), float(t), 0, 0.0, float(self.state.dt_prev), m, fields, space,
                                  True)
            return
        self.elements.forces(m.structure, fields.shape, space.dx, space.dd, fields.stress, fields.f_int, fields.fr_int,
                             space.parts)
        self.compiled.applied_forces(float(t), m, fields, space)

    def advance(self, t_stop: float, dt: float, max_steps: int) -> int:
        """Step with ``dt`` until ``t_stop`` (landing on it) or ``max_steps``; returns the
        number of steps taken (fewer when the thread chooser tries a count on a few)."""
        s = self.state
        count, max_steps = self.threads.plan(max_steps)
        start = time.perf_counter()
        try:
            with kernel_threads(count):
                s.t, s.dt_prev, steps = self._advance(t_stop, dt, max_steps)
        except (ZeroDivisionError, FloatingPointError) as error:
            # a director or frame collapsed: the state has degenerated beyond recovery
            raise NumericalError(f"the run broke down at t = {s.t:.6g} after {s.steps} steps: "
                                 f"a degenerate state ({error}); the motion had become unstable") from None
        self.threads.record(count, steps, time.perf_counter() - start)
        s.steps += steps
        return steps

    def _advance(self, t_stop: float, dt: float, max_steps: int) -> tuple[float, float, int]:
        s = self.state
        return self.compiled.advance(self.response, float(s.t), float(t_stop), int(max_steps), float(dt),
                                     float(s.dt_prev), self.model, s.fields, self.workspace, False)
