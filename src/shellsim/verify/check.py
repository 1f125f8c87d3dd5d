"""A run's probe histories against the deck's [reference] values."""

from __future__ import annotations

import numpy as np

from ..deck.schema import Reference


def first_peak(times: np.ndarray, values: np.ndarray) -> tuple[float, float]:
    """(time, value) of the first peak of a history that starts from rest.

    The value is the largest excursion from values[0] before the history falls back
    below half of it (ripples of higher modes riding on the rise are not a peak). The time
    is the middle of the first half-cycle: halfway between the instants the excursion
    crosses half the peak on the way up and on the way down. For a step response
    w_st (1 - cos wt) that is exactly the peak time pi/w; unlike the instant of the
    maximum, which a flat top leaves to the ripples, it is set by the steep flanks.
    """
    excursion = np.abs(values - values[0])
    best = 0
    for i in range(1, len(values)):
        if excursion[i] > excursion[best]:
            best = i
        elif excursion[best] > 0 and excursion[i] < 0.5 * excursion[best]:
            fall = i
            break
    else:
        raise ValueError("the history has no first peak (it never falls back to half its excursion)")
    half = 0.5 * excursion[best]
    rise = best
    while rise > 0 and excursion[rise - 1] >= half:
        rise -= 1

    def crossing(i: int, j: int) -> float:  # where the excursion passes half between samples i, j
        return float(np.interp(half, sorted([excursion[i], excursion[j]]),
                               [times[i], times[j]] if excursion[i] <= excursion[j] else [times[j], times[i]]))

    up = crossing(rise - 1, rise) if rise > 0 else float(times[0])
    down = crossing(fall - 1, fall)
    return 0.5 * (up + down), float(values[best])


def measure(reference: Reference, times: np.ndarray, values: np.ndarray) -> float:
    """The number ``reference.measure`` takes from a probe history."""
    kind = reference.measure
    if kind == "final":
        return float(values[-1])
    if kind == "max":
        return float(values.max())
    if kind == "min":
        return float(values.min())
    if kind == "max_abs":
        return float(np.abs(values).max())
    if kind == "at_time":
        if reference.time > times[-1]:
            raise ValueError(f"the history ends at t = {times[-1]:.6g}, before the reference's time {reference.time:.6g}")
        return float(np.interp(reference.time, times, values))
    peak_time, peak_value = first_peak(times, values)
    if kind == "first_peak_time":
        return peak_time
    return abs(peak_value - values[0]) / 2.0  # amplitude: half the first excursion


def check(reference: Reference, times: np.ndarray, values: np.ndarray) -> dict:
    """The summary entry of one reference: quantity, probe, measure, computed, expected,
    error (absolute and percent), tolerance (percent or absolute), passed and source; when
    the history cannot give the measure, computed and the errors are None and ``note``
    says why. Every entry has the same keys."""
    entry = {"quantity": reference.quantity, "probe": reference.probe, "measure": reference.measure,
             "computed": None, "expected": reference.expected, "error": None, "error_percent": None,
             "tolerance_percent": reference.tolerance_percent, "tolerance": reference.tolerance,
             "passed": False, "source": reference.source}
    if not len(values):
        return entry | {"note": "the run recorded no samples to measure"}
    try:
        computed = measure(reference, times, values)
    except ValueError as error:
        return entry | {"note": str(error)}
    error = computed - reference.expected
    error_percent = 100.0 * error / reference.expected if reference.expected else None
    if reference.tolerance is not None:
        passed = abs(error) <= reference.tolerance
    else:
        passed = abs(error_percent) <= reference.tolerance_percent
    return entry | {"computed": computed, "error": error, "error_percent": error_percent, "passed": bool(passed)}
