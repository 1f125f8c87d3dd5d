"""Fields derived from the stress and the fibres, the ones a tissue engineer plots first:
principal stresses and their directions, the stress in a vessel's axes (hoop, axial,
radial), each fibre family's stretch."""

from __future__ import annotations

import numpy as np

from ..deck.schema import WRITTEN_AS
from ..mesh import layer_geometry
from ..model import lamina_axes
from ..solver.simulation import Simulation

#: The vessel stresses written by ``vessel_stress``, in the order of :func:`vessel_frames`' rows.
VESSEL_STRESSES = WRITTEN_AS["vessel_stress"]


def principal_stresses(sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(values (..., 3), directions (..., 3, 3)) of symmetric stresses (..., 3, 3): the
    principal values largest first, and the unit direction of each as a row (its sign
    arbitrary)."""
    values, vectors = np.linalg.eigh(sigma)  # ascending, directions as columns
    return values[..., ::-1], np.swapaxes(vectors, -1, -2)[..., ::-1, :]


def vessel_frames(sim: Simulation, axes, depths: np.ndarray) -> np.ndarray:
    """(ne, nq, len(depths), 3, 3) frames at the current shape, rows (hoop, axial, radial),
    at the in-plane Gauss points of the layers at thickness coordinates ``depths``: hoop
    the vessel ``axes``' circumferential direction (a tube's or a centreline's) projected
    on the lamina, radial the lamina normal, axial the third (:func:`~shellsim.model.lamina_axes`)."""
    model, state, rule = sim.model, sim.state, sim.model.rule
    nq = len(rule.wq)
    frames = np.empty((model.n_elements, nq, len(depths), 3, 3))
    for k, t in enumerate(depths):
        position, jac = layer_geometry(state.x, state.d, state.h, model.conn, rule.N[:nq], rule.dNr[:nq],
                                       rule.dNs[:nq], t)
        frames[:, :, k] = lamina_axes(jac, axes.preferred(position, {}))
    return frames


def normal_components(sigma: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """(..., 3) a_i . sigma a_i of stresses (..., 3, 3) for the rows a_i of ``frames`` (..., 3, 3)."""
    return np.einsum("...ij,...jk,...ik->...i", frames, sigma, frames)
