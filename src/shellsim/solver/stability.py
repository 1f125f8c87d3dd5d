"""Where a static path loses stability: the count of negative pivots of the tangent at the
converged states (its inertia, by Sylvester's law the count of its negative eigenvalues),
and the places where that count changes.

A stable equilibrium has a positive definite tangent. Where the count rises, the path
passed a critical point: a limit point, where the load passes a maximum (only arc length
gets past one), or a bifurcation, where another path branches off while the load goes on
the same way (a straight strip past its Euler load stays straight, unstably, unless an
imperfection leads it onto the buckled branch). The two are told apart by the load: at a
limit point its change along the path turns back (Crisfield 1997, Non-linear Finite
Element Analysis of Solids and Structures, vol. 2, section 21.3).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Observation:
    """The tangent's negative pivots at a converged state: its clock t and load time."""

    t: float
    load_time: float
    negative_pivots: int


class StabilityWatch:
    """The negative pivots at the converged states of a static path, in order."""

    def __init__(self):
        self.observations: list[Observation] = []
        self.noted: list[dict] = []  # the events the solver reports itself (jumps, the path unloaded)

    def observe(self, t: float, load_time: float, negative_pivots: int | None) -> None:
        """Record the count at the converged state at clock t (None: unknown, the factors
        pivoted off the diagonal); a state seen already keeps its first count."""
        if negative_pivots is None or (self.observations and self.observations[-1].t == t):
            return
        self.observations.append(Observation(t, load_time, negative_pivots))

    def jumped(self, t: float, load_time_from: float, load_time_to: float, ratio: float) -> None:
        """Record a load step from the converged state at clock t that moved the shape
        ``ratio`` times as far as its tangent predicted: it may have jumped over a
        snap-through, which it did not follow."""
        self.noted.append({"kind": "jump", "t_from": t, "load_time_from": load_time_from,
                           "load_time_to": load_time_to, "ratio": ratio})

    def unloaded(self, t: float, load_time: float, end_time: float) -> None:
        """Record that the path came back, at clock t, to the load time below which the
        loads do not change: it ends there, short of the clock's ``end_time``."""
        self.noted.append({"kind": "unloaded", "t_from": t, "t_to": t, "load_time_from": load_time,
                           "load_time_to": load_time, "end_time": end_time})

    def events(self) -> list[dict]:
        """Each change of the count: the converged states it lies between (clock and load
        time), the counts before and after, and its kind, 'limit point' where the load's
        change turns back within a step of it, 'bifurcation' where the count rises with no
        such turn, 'restabilised' where it falls with none; each 'jump' (:meth:`jumped`)
        and the path's return to loads that hold, 'unloaded' (:meth:`unloaded`), in the
        order of their clock times."""
        seen, found = self.observations, []
        for i in range(1, len(seen)):
            before, after = seen[i - 1], seen[i]
            if after.negative_pivots == before.negative_pivots:
                continue
            loads = [o.load_time for o in seen[max(i - 2, 0):i + 2]]
            changes = [b - a for a, b in zip(loads, loads[1:]) if b != a]
            turned = any(a * b < 0.0 for a, b in zip(changes, changes[1:]))
            kind = "limit point" if turned else (
                "bifurcation" if after.negative_pivots > before.negative_pivots else "restabilised")
            found.append({"kind": kind, "t_from": before.t, "t_to": after.t, "load_time_from": before.load_time,
                          "load_time_to": after.load_time, "negative_pivots_from": before.negative_pivots,
                          "negative_pivots_to": after.negative_pivots})
        return sorted(found + self.noted, key=lambda event: event["t_from"])


def describe(event: dict) -> str:
    """One line for the console about a stability event of :meth:`StabilityWatch.events`."""
    where = f"between load time {event['load_time_from']:.6g} and {event['load_time_to']:.6g}"
    if event["kind"] == "jump":
        return (f"jump {where}: the load step moved the shape {event['ratio']:.3g} times as far as the tangent at "
                "its start predicted, so the path may snap through there, passed by a jump rather than followed; "
                "solver.static.control = \"arc_length\" follows it")
    if event["kind"] == "unloaded":
        return (f"the path came back to load time {event['load_time_from']:.6g} at clock t = {event['t_from']:.6g}, "
                f"and the loads do not change below it: the run ends there, short of solver.end_time = "
                f"{event['end_time']:.6g}, with every step converged")
    counts = f"{event['negative_pivots_from']} -> {event['negative_pivots_to']} negative pivots"
    if event["kind"] == "bifurcation" and event["negative_pivots_from"] == 0:
        return (f"bifurcation passed {where} ({counts}): the tangent stiffness is no longer positive definite, "
                "so the path computed beyond it is unstable; another path branches off there, which any "
                "imperfection (a small transverse load or a perturbed shape) leads onto")
    if event["kind"] == "bifurcation":
        return f"bifurcation passed {where} ({counts}): one more path branches off there"
    if event["kind"] == "limit point":
        return f"limit point passed {where} ({counts}): the load turns back there"
    return f"stable again {where} ({counts})"
