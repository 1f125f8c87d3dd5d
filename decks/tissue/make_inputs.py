"""Writes the inputs of the tissue scenes, from formulas (no data downloaded):

- ``carotid_segment.stl``: a curved, tapered vessel segment, the mid-surface of a wall
  bent along a circular arc of radius 40 mm through 70 degrees, its radius tapering from
  4.0 mm to 3.2 mm (the size of a human internal carotid artery), 64 x 40 facet pairs;
- ``carotid_pulse.csv``: one cardiac cycle (0.8 s) of the pressure above diastole, in
  mmHg, 0 to 40 (80-120 mmHg with the diastolic pressure): a synthetic pulse shaped like a
  carotid waveform (systolic peak, dicrotic notch, diastolic decay), sums of Gaussians.

Run ``python decks/tissue/make_inputs.py`` to write them again.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
#: Centreline: arc radius, sweep (m, rad); lumen radii at the two ends (m).
ARC_RADIUS, SWEEP = 0.040, np.radians(70.0)
RADIUS_IN, RADIUS_OUT = 0.0040, 0.0032
AROUND, ALONG = 64, 40


def centreline(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points (k, 3) and unit tangents (k, 3) of the centreline at arc fractions s (k,):
    an arc in the x-z plane starting at the origin along +z, bending toward +x."""
    angle = s * SWEEP
    points = np.column_stack([ARC_RADIUS * (1 - np.cos(angle)), np.zeros_like(s), ARC_RADIUS * np.sin(angle)])
    tangents = np.column_stack([np.sin(angle), np.zeros_like(s), np.cos(angle)])
    return points, tangents


def vessel() -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 3) and triangles (m, 3) of the segment's surface."""
    s = np.linspace(0.0, 1.0, ALONG + 1)
    centre, tangent = centreline(s)
    normal = np.cross(tangent, [0.0, 1.0, 0.0])  # in the bending plane
    binormal = np.tile([0.0, 1.0, 0.0], (len(s), 1))
    radius = RADIUS_IN + (RADIUS_OUT - RADIUS_IN) * s
    phi = np.linspace(0.0, 2 * np.pi, AROUND, endpoint=False)
    points = (centre[:, None] + radius[:, None, None] * (np.cos(phi)[None, :, None] * normal[:, None]
                                                          + np.sin(phi)[None, :, None] * binormal[:, None]))
    triangles = []
    for j in range(ALONG):
        for i in range(AROUND):
            a, b = j * AROUND + i, j * AROUND + (i + 1) % AROUND
            triangles += [[a, b, b + AROUND], [a, b + AROUND, a + AROUND]]
    return points.reshape(-1, 3), np.array(triangles)


def pulse(t: np.ndarray) -> np.ndarray:
    """Pressure above diastole (mmHg) over one 0.8 s cycle: 0 at both ends."""
    wave = (40.0 * np.exp(-(((t - 0.22) / 0.07) ** 2)) + 17.0 * np.exp(-(((t - 0.42) / 0.08) ** 2))
            - 4.0 * np.exp(-(((t - 0.35) / 0.02) ** 2)))
    return np.clip(wave - wave[0] - (wave[-1] - wave[0]) * t / t[-1], 0.0, None)


def main() -> None:
    import meshio

    points, triangles = vessel()
    meshio.write(HERE / "carotid_segment.stl", meshio.Mesh(points, [("triangle", triangles)]), binary=True)
    t = np.linspace(0.0, 0.8, 81)
    rows = "\n".join(f"{a:.3f}, {b:.3f}" for a, b in zip(t, pulse(t)))
    (HERE / "carotid_pulse.csv").write_text("# time (s), pressure above diastole (mmHg)\ntime, pressure\n" + rows + "\n")


if __name__ == "__main__":
    main()
