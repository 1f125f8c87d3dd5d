"""Deck tables every model reader makes the same way: a support from the degrees of
freedom a file holds, and pressure loads from faces that push along or against each
element's own normal in the file."""

from __future__ import annotations

import numpy as np

from .shell_mesh import ShellMesh

AXES = "xyz"


def support_table(name: str, translations: set[int], rotations: set[int]) -> tuple[dict | None, str | None]:
    """The ``[[boundary]]`` on set ``name`` holding the global translations (1-3) and
    rotations (4-6) given, and what could not be said (a rotation held alone).

    All six: clamped; one translation with the two rotations that tilt its plane:
    symmetry; otherwise the translations fixed and the director fixed (three rotations)
    or kept in the plane normal to the one free rotation axis (two).
    """
    if len(translations) == 3 and len(rotations) == 3:
        return {"type": "clamped", "set": name}, None
    for axis in range(3):
        if translations == {axis + 1} and rotations == {4, 5, 6} - {axis + 4}:
            return {"type": "symmetry", "set": name, "normal": [float(axis == i) for i in range(3)]}, None
    entry: dict = {"type": "fixed", "set": name, "translations": [AXES[d - 1] for d in sorted(translations)]}
    problem = None
    if len(rotations) == 3:
        entry["director"] = "fixed"
    elif len(rotations) == 2:  # free only about one axis: the director turns in the plane normal to it
        free = ({4, 5, 6} - rotations).pop() - 4
        entry["director_plane_normal"] = [float(free == i) for i in range(3)]
    elif len(rotations) == 1:
        problem = (f"on '{name}' the rotation about {AXES[min(rotations) - 4]} alone is held; a director has no "
                   "such single rotation: left free (state the support with director_plane_normal in the deck)")
    if not translations and len(entry) == 3:
        return None, problem
    return entry, problem


def pressure_loads(shells: ShellMesh, elements: np.ndarray, along: np.ndarray, magnitude: float,
                   whole: tuple[str, str] | None, wanted: str, extra: dict) -> list[dict]:
    """Pressure ``magnitude`` on the mid-surface (the reference surface of other programs'
    shells) of ``elements`` (k,), pushing along (+1) or against (-1) each one's normal in the
    file (``along`` (k,)): one load for the elements whose director is that normal, one for
    those orienting turned, with opposite signs. A load covering the whole set the file
    named (``whole``, a ``shells.set_of`` key) is on that set; else on a new one ``wanted``."""
    sign = along * shells.side[elements]
    loads = []
    for s in (-1.0, 1.0):
        chosen = np.unique(elements[sign == s])
        if not len(chosen):
            continue
        if whole in shells.set_of and np.array_equal(shells.sets[shells.set_of[whole]].elements, chosen):
            name = shells.set_of[whole]
        else:
            name = shells.add_set(None, wanted, shells.surface_set(chosen))
        loads.append({"type": "pressure", "set": name, "value": s * magnitude, "face": "mid"} | extra)
    return loads
