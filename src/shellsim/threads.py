"""How many threads the kernels run on.

At most the CPUs this process may use: its affinity mask and its cgroup's CPU quota (a
container or a batch job given 2 of a node's 64 cores), not the machine's count that numba
starts from. Within that, a run's steps use whichever of one thread or all of them is
faster now (:class:`ThreadChooser`): on a machine other work keeps busy, the threads of a
parallel loop wait at its end for the one the scheduler took away, and two threads ran 7x
slower than one. How long a waiting thread spins before it sleeps is set where the
package starts (:mod:`shellsim`, GOMP_SPINCOUNT): spinning threads held the CPUs the late
one needed. The results do not depend on the count (:mod:`shellsim.element.assembly`).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path

#: Where a cgroup v2 and a cgroup v1 keep the CPU quota (microseconds per period).
CGROUP_V2_MAX = Path("/sys/fs/cgroup/cpu.max")
CGROUP_V1 = Path("/sys/fs/cgroup/cpu")


def cgroup_cpus(v2_max: Path = CGROUP_V2_MAX, v1: Path = CGROUP_V1) -> float | None:
    """The CPUs the cgroup's quota grants (quota / period), or None without a quota."""
    try:
        quota, period = v2_max.read_text().split()[:2]
        return None if quota == "max" else int(quota) / int(period)
    except (OSError, ValueError):
        pass
    try:
        quota = int((v1 / "cpu.cfs_quota_us").read_text())
        period = int((v1 / "cpu.cfs_period_us").read_text())
    except (OSError, ValueError):
        return None
    return quota / period if quota > 0 and period > 0 else None


def usable_cpus() -> int:
    """The CPUs this process may use: its affinity, within its cgroup's quota (at least 1)."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # no affinity on this platform
        cpus = os.cpu_count() or 1
    quota = cgroup_cpus()
    if quota is not None:
        cpus = min(cpus, math.ceil(quota))
    return max(1, cpus)


def limit_to_usable_cpus() -> int:
    """Keep the calling thread's kernels within the usable CPUs (numba starts from the
    machine's count, or NUMBA_NUM_THREADS when the user set it); returns the count."""
    import numba

    count = max(1, min(numba.get_num_threads(), usable_cpus()))
    numba.set_num_threads(count)
    return count


#: The threads :func:`over_threads` runs ranges on, made at its first use.
_POOL: ThreadPoolExecutor | None = None


def over_threads(run_range: Callable[[int, int], None], count: int) -> None:
    """``run_range(first, last)`` over 0..count-1, shared out as contiguous ranges over as
    many threads as the kernels may use now (:func:`kernel_threads`). For a compiled loop
    that releases the interpreter's lock (``nogil``), called from Python: where no
    compiled caller needs it, this spares the compiling of a parallel loop."""
    import numba

    global _POOL
    threads = max(1, min(numba.get_num_threads(), count))
    bounds = [count * i // threads for i in range(threads + 1)]
    if threads > 1 and _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=usable_cpus(), thread_name_prefix="shellsim")
    others = [_POOL.submit(run_range, first, last) for first, last in zip(bounds[1:-1], bounds[2:])]
    try:
        run_range(bounds[0], bounds[1])  # the first range on the calling thread
    finally:
        for other in others:
            other.result()


@contextmanager
def kernel_threads(count: int) -> Iterator[None]:
    """The calling thread's kernels run on ``count`` threads inside the block."""
    import numba

    before = numba.get_num_threads()
    numba.set_num_threads(count)
    try:
        yield
    finally:
        numba.set_num_threads(before)


#: Steps of each block before the chooser knows the current count's pace.
FIRST_BLOCK_STEPS = 8


class ThreadChooser:
    """Chooses, block by block of steps, between one thread and ``most``: it runs at its
    current count and, from its second timed block on and then every ``probe_interval``
    seconds, tries the other count on a block of about ``probe_seconds`` at the current
    pace, switching when the other count's pace is the better. A count's pace is its
    seconds over its steps, both fading with the time stepped (``memory`` seconds): on a
    loaded machine a parallel loop runs fast for a while and then stalls, so a short probe
    that caught no stall does not outweigh the stalls its count had. A probe that loses
    waits twice as long before the next, up to ``longest_interval``: where the other
    count is 7x slower the probes cost under 2% of the run, and a change of load is
    followed within about ``longest_interval`` + ``memory`` seconds.

    Use: ``count, steps = chooser.plan(max_steps)``, run at most ``steps`` steps on
    ``count`` threads, then ``chooser.record(count, steps_taken, seconds)``. With
    ``choose`` False it always answers ``most`` (a measurement of that count)."""

    def __init__(self, most: int, choose: bool = True, probe_interval: float = 1.0, probe_seconds: float = 0.02,
                 longest_interval: float = 8.0, memory: float = 5.0, clock: Callable[[], float] = time.perf_counter):
        self.counts = (most, 1) if choose and most > 1 else (most,)
        self.current = most
        self.probe_interval = probe_interval
        self.probe_seconds = probe_seconds
        self.longest_interval = longest_interval
        self.memory = memory
        self.clock = clock
        self._interval = probe_interval
        self._next_probe: float | None = None  # set after the first block (which may compile)
        self._seconds = dict.fromkeys(self.counts, 0.0)  # fading sums of each count's blocks
        self._steps = dict.fromkeys(self.counts, 0.0)

    @property
    def other(self) -> int:
        """The count a probe tries."""
        return self.counts[1] if self.current == self.counts[0] else self.counts[0]

    def pace(self, count: int) -> float:
        """Seconds per step on ``count`` threads as measured (inf before any block)."""
        return self._seconds[count] / self._steps[count] if self._steps[count] else math.inf

    def plan(self, max_steps: int) -> tuple[int, int]:
        """(threads, steps) for the next block of at most ``max_steps`` steps: the current
        count, or a probe of the other count on a few steps."""
        if len(self.counts) == 1:
            return self.current, max_steps
        if not self._steps[self.current]:  # short blocks until a pace is known: the count may be the slow one
            return self.current, min(max_steps, FIRST_BLOCK_STEPS)
        if self.clock() < self._next_probe:
            return self.current, max_steps
        return self.other, min(max_steps, max(4, int(self.probe_seconds / self.pace(self.current))))

    def record(self, count: int, steps: int, seconds: float) -> None:
        """A block of ``steps`` steps took ``seconds`` on ``count`` threads."""
        if steps <= 0 or len(self.counts) == 1:
            return
        if self._next_probe is None:  # the first block may hold the kernels' compilation;
            self._next_probe = self.clock()  # the first probe follows the next block
            return
        fade = math.exp(-seconds / self.memory)
        for c in self.counts:
            self._seconds[c] *= fade
            self._steps[c] *= fade
        self._seconds[count] += seconds
        self._steps[count] += steps
        if count != self.current:
            if self.pace(count) < self.pace(self.current):
                self.current = count
                self._interval = self.probe_interval
            else:
                self._interval = min(2.0 * self._interval, self.longest_interval)
            self._next_probe = self.clock() + self._interval
