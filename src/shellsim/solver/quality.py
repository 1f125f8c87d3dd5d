"""Element quality while a run goes, and what to say when it breaks down.

An element's quality is the smallest ratio, over its Gauss points, of the Jacobian
determinant of the shell body now to the one it had at the start: 1 for a rigid motion,
falling as the element is crushed, 0 or below when it has folded over. Watched at every
critical-step update (a few numpy products per element, nothing in the time loop), it
tells a folding mesh from a time step that is too long.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import id_list, place
from ..mesh import Mesh, body_jacobians, jacobian_determinants

#: Below this ratio an element is badly crushed, at or below 0 folded over.
CRUSHED, FOLDED = 0.1, 0.0
#: Critical-step updates looked back over in a breakdown's message.
LOOK_BACK = 5


@dataclass(frozen=True)
class Worst:
    """The worst element at time t: its index (from 0) and its Jacobian ratio."""

    t: float
    element: int
    ratio: float


class ElementQuality:
    """Jacobian ratios of a mesh's elements, against the mesh as built."""

    def __init__(self, mesh: Mesh):
        self.conn = mesh.conn
        self.initial = jacobian_determinants(mesh)

    def ratios(self, x: np.ndarray, director: np.ndarray, thickness: np.ndarray) -> np.ndarray:
        """(ne,) smallest det J / det J0 over each element's Gauss points, -inf where it is no
        number (a state gone to pieces is the worst); shapes as the mesh's arrays."""
        ratios = (body_jacobians(x, self.conn, director, thickness) / self.initial).min(axis=(1, 2))
        return np.where(np.isnan(ratios), -np.inf, ratios)

    def worst(self, t: float, ratios: np.ndarray) -> Worst:
        """The element with the smallest of ``ratios`` (ne,)."""
        e = int(np.argmin(ratios))
        return Worst(t, e, float(ratios[e]))


#: What to do about a crushed or folded element.
ADVICE = ("The mesh is too coarse there for this deformation, or the load comes on too fast: refine the mesh "
          "around that element, or ramp the load more slowly")


def folding_diagnosis(ratios: np.ndarray, x: np.ndarray, conn: np.ndarray,
                      massless: np.ndarray | None = None) -> str | None:
    """What a breakdown's message says of the mesh: the crushed or folded elements, the worst
    first, with where it is and what to do; else, when nodes ``massless`` (indices) have lumped masses
    no longer positive (the masses on the current shape give way before the Gauss points
    fold), the worst element around them; None when neither. ratios (ne,) of
    :meth:`ElementQuality.ratios`, x (n, 3) the positions to place it by (the mesh as
    built), conn (ne, 9)."""
    crushed = np.flatnonzero(ratios < CRUSHED)
    if not crushed.size:
        return _massless_diagnosis(ratios, x, conn, massless) if massless is not None and massless.size else None
    crushed = crushed[np.argsort(ratios[crushed])]
    worst = crushed[0]
    state = "has folded over" if ratios[worst] <= FOLDED else "is crushed"
    return (f"element {worst + 1} (counting from 1) at {place(x[conn[worst]].mean(axis=0))} {state}: its "
            f"volume ratio det J / det J0 is {ratios[worst]:.3g}; {crushed.size} element(s) are below {CRUSHED:g} "
            f"({id_list(crushed + 1)}). {ADVICE}")


def _massless_diagnosis(ratios: np.ndarray, x: np.ndarray, conn: np.ndarray, massless: np.ndarray) -> str:
    around = np.flatnonzero(np.isin(conn, massless).any(axis=1))
    worst = around[np.argmin(ratios[around])]
    nodes = np.intersect1d(conn[worst], massless)
    return (f"element {worst + 1} (counting from 1) at {place(x[conn[worst]].mean(axis=0))} is distorted beyond "
            f"what its lumped masses bear: the masses of its node(s) {id_list(nodes + 1)} are no longer positive, "
            f"its volume ratio det J / det J0 is {ratios[worst]:.3g}. {ADVICE}")


def step_history(dt_history: list[tuple[float, float, float]]) -> str:
    """How the critical step moved over the last updates, for a breakdown's message."""
    recent = dt_history[-LOOK_BACK:]
    if len(recent) < 2:
        return ""
    (t0, c0, _), (t1, c1, _) = recent[0], recent[-1]
    fall = f" ({c0 / c1:.3g} times smaller)" if c1 < c0 else ""
    return f"; the critical step went from {c0:.4g} to {c1:.4g}{fall} between t = {t0:.6g} and t = {t1:.6g}"
