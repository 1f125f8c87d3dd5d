"""The unloaded shape of an imaged scene (``[solver.imaged]``): the reference from which
loading to the image's load time returns the imaged mesh, by the backward displacement
method (Bols, Degroote, Trachet, Verhegghe, Segers & Vierendeels 2013, J. Biomech.
46:2313-2318), a fixed-point iteration on the reference: X_{k+1} = X_k - (x_k - x_image).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..deck import Deck
from ..errors import NumericalError
from ..mesh import Mesh


@dataclass
class Unloading:
    """What finding the unloaded shape took: each iteration's shape error (the largest
    distance between the loaded and imaged mid-surface nodes over the model's size), and
    the wall time [s]."""

    errors: list[float] = field(default_factory=list)
    seconds: float = 0.0

    def record(self) -> dict:
        return {"iterations": len(self.errors), "shape_errors": self.errors, "wall_time_s": self.seconds}


def unloaded_mesh(scene: Deck, imaged: Mesh, announce: Callable[[str], None]) -> tuple[Mesh, Unloading]:
    """The unloaded reference (positions, directors, fibre lengths) of ``imaged``, the
    shape under ``scene``'s loads at ``solver.imaged.at``, and the iterations' record.
    Raises NumericalError when a static solve fails or the shape error is not within the
    tolerance after the iterations allowed."""
    import time

    from ..model import build_model
    from .run import prepare
    from .static_solve import solve_static

    settings, start = scene.solver.imaged, time.perf_counter()
    size = float(np.ptp(imaged.x, axis=0).max())
    reference, unloading = imaged, Unloading()
    for iteration in range(1, settings.iterations + 1):
        run = prepare(scene, reference, build_model(scene, reference))
        try:
            solve_static(run, until=settings.at)
        except NumericalError as error:
            raise NumericalError(f"finding the unloaded shape, iteration {iteration} (loading the reference to "
                                 f"imaged.at = {settings.at:g}): {error}") from None
        state = run.sim.state
        miss = state.x - imaged.x
        unloading.errors.append(float(np.linalg.norm(miss, axis=1).max() / size))
        announce(f"unloaded shape, iteration {iteration}: loaded shape {unloading.errors[-1]:.2e} of the model's "
                 f"size from the image")
        if unloading.errors[-1] <= settings.tolerance:
            unloading.seconds = time.perf_counter() - start
            return reference, unloading
        director = reference.director - (state.d - imaged.director)
        reference = replace(reference, x=reference.x - miss,
                            director=director / np.linalg.norm(director, axis=1, keepdims=True),
                            thickness=reference.thickness * imaged.thickness / state.h)
    raise NumericalError(f"the unloaded shape was not found in solver.imaged.iterations = {settings.iterations}: "
                         f"the loaded shape is still {unloading.errors[-1]:.2e} of the model's size from the image "
                         f"(tolerance {settings.tolerance:g}; the errors went {', '.join(f'{e:.1e}' for e in unloading.errors[-4:])})")
