"""Fields derived from the stress and the fibres, the ones a tissue engineer plots first:
principal stresses and their directions, the stress in a vessel's axes (hoop, axial,
radial) and in the material's, the second Piola-Kirchhoff stress, each fibre family's
stretch."""

from __future__ import annotations

import numpy as np

from ..deck.output_fields import WRITTEN_AS
from ..mesh import layer_geometry
from ..model import lamina_axes
from ..solver.simulation import Simulation

#: The vessel stresses written by ``vessel_stress``, in the order of :func:`vessel_frames`' rows.
VESSEL_STRESSES = WRITTEN_AS["vessel_stress"]


def principal_stresses(sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(values (..., 3), directions (..., 3, 3)) of symmetric stresses (..., 3, 3): the
    principal values largest first, and the unit direction of each as a row (its sign
    arbitrary); NaN where a stress is not a number (the frame of a run that broke down)."""
    finite = np.isfinite(sigma).all(axis=(-2, -1))
    values, vectors = np.full(sigma.shape[:-1], np.nan), np.full(sigma.shape, np.nan)
    values[finite], vectors[finite] = np.linalg.eigh(sigma[finite])  # ascending, directions as columns
    return values[..., ::-1], np.swapaxes(vectors, -1, -2)[..., ::-1, :]


def current_geometry(sim: Simulation, depths) -> tuple[np.ndarray, np.ndarray]:
    """(positions (ne, nq, L, 3), Jacobians dx/d(r, s, t) (ne, nq, L, 3, 3)) at the current
    shape, at the in-plane Gauss points of the L layers at thickness coordinates ``depths``."""
    model, state, rule = sim.model, sim.state, sim.model.rule
    nq = len(rule.wq)
    at_depths = [layer_geometry(state.x, state.d, state.h, model.conn, rule.N[:nq], rule.dNr[:nq], rule.dNs[:nq], t)
                 for t in depths]
    return np.stack([p for p, _ in at_depths], axis=2), np.stack([j for _, j in at_depths], axis=2)


def vessel_frames(sim: Simulation, axes, depths: np.ndarray) -> np.ndarray:
    """(ne, nq, len(depths), 3, 3) frames at the current shape, rows (hoop, axial, radial),
    at the in-plane Gauss points of the layers at thickness coordinates ``depths``: hoop
    the vessel ``axes``' circumferential direction (a tube's or a centreline's) projected
    on the lamina, radial the lamina normal, axial the third (:func:`~shellsim.model.lamina_axes`)."""
    position, jac = current_geometry(sim, depths)
    return lamina_axes(jac, axes.preferred(position, {}))


def normal_components(sigma: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """(..., 3) a_i . sigma a_i of stresses (..., 3, 3) for the rows a_i of ``frames`` (..., 3, 3)."""
    return np.einsum("...ij,...jk,...ik->...i", frames, sigma, frames)


def deformation_gradients(sim: Simulation, layers: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """(F, jac), each (ne, nq, len(layers), 3, 3), at the in-plane integration points of
    the ``layers`` (indices into the thickness rule): the current Jacobian jac = dx/d(r, s,
    t) (:func:`current_geometry`) and the deformation gradient F = jac (dX/d(r, s, t))^-1."""
    nq = len(sim.model.rule.wq)
    _, jac = current_geometry(sim, sim.model.rule.tz[layers])
    return jac @ sim.model.body.jac0_inv[:, :nq][:, :, layers], jac


def second_piola_in(frames0: np.ndarray, F: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """(..., 3, 3) the second Piola-Kirchhoff stress S = J F^-1 sigma F^-T of Cauchy
    stresses sigma (..., 3, 3) at deformation gradients F (..., 3, 3), in the initial
    frames ``frames0`` (..., 3, 3; rows the axes): S_ij = a_i . S a_j."""
    F_inv = np.linalg.inv(F)
    S = np.linalg.det(F)[..., None, None] * F_inv @ sigma @ np.swapaxes(F_inv, -1, -2)
    return frames0 @ S @ np.swapaxes(frames0, -1, -2)


def current_material_frames(frames0: np.ndarray, F: np.ndarray, jac: np.ndarray) -> np.ndarray:
    """(..., 3, 3) the material frames carried to the current shape, rows (a1, a2, a3):
    a1 the initial axis 1 (row 0 of ``frames0``) carried by F and laid on the current
    lamina of Jacobians ``jac``, a3 that lamina's normal (:func:`~shellsim.model.lamina_axes`)."""
    return lamina_axes(jac, np.einsum("...ij,...j->...i", F, frames0[..., 0, :]))
