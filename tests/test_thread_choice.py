"""The kernels' thread count: the CPUs a process may use (affinity, cgroup quota), and the
chooser that runs a scene's steps on whichever of one thread or all is faster now.

The chooser is driven here by a simulated machine (seconds per step for each count) on a
simulated clock, so what it decides depends on no real machine's speed or load."""

from __future__ import annotations

import pytest

from shellsim.threads import ThreadChooser, cgroup_cpus, usable_cpus


class Machine:
    """A simulated machine: ``pace(t)`` gives {threads: seconds per step} at time t."""

    def __init__(self, pace):
        self.pace = pace
        self.now = 0.0
        self.steps = 0

    def clock(self) -> float:
        return self.now

    def run(self, chooser: ThreadChooser, duration: float, block: int = 1000) -> dict[int, float]:
        """Step for ``duration`` simulated seconds in blocks of at most ``block`` steps;
        the seconds spent on each count."""
        spent = dict.fromkeys(chooser.counts, 0.0)
        while self.now < duration:
            count, steps = chooser.plan(block)
            assert 0 < steps <= block, (count, steps)  # a plan asks for some steps, never more than allowed
            seconds = steps * self.pace(self.now)[count]
            self.now += seconds
            self.steps += steps
            spent[count] += seconds
            chooser.record(count, steps, seconds)
        return spent


def chooser_on(machine: Machine) -> ThreadChooser:
    return ThreadChooser(2, clock=machine.clock)


def test_on_an_idle_machine_the_steps_stay_on_every_thread():
    machine = Machine(lambda t: {2: 1e-4, 1: 1.8e-4})
    chooser = chooser_on(machine)
    spent = machine.run(chooser, 600.0)
    assert spent[1] / 600.0 < 0.01  # the probes of one thread: under 1% of the run
    assert chooser.current == 2


def test_on_a_busy_machine_one_thread_takes_over_and_two_are_rarely_tried():
    """Two threads 7x slower than one (measured on this machine at load average 7)."""
    machine = Machine(lambda t: {2: 7e-4, 1: 1e-4})
    chooser = chooser_on(machine)
    spent = machine.run(chooser, 600.0)
    assert chooser.current == 1
    assert spent[2] / 600.0 < 0.02  # probes of 20 ms at one thread's pace, 140 ms on two, every 8 s


def test_the_choice_follows_the_load_as_it_comes_and_goes():
    """Busy from t = 100 s to 400 s: the chooser moves to one thread within its longest
    probe interval, and back after."""
    def pace(t):
        return {2: 7e-4, 1: 1e-4} if 100.0 <= t < 400.0 else {2: 1e-4, 1: 1.8e-4}

    machine = Machine(pace)
    chooser = chooser_on(machine)
    machine.run(chooser, 200.0)
    assert chooser.current == 1
    machine.run(chooser, 500.0)
    assert chooser.current == 2
    # Always on the faster count, 1e4 steps a second. The load's arrival costs about one
    # longest interval and the paces' memory (8 + 5 s) at a seventh of that pace, 11 s of
    # 500, and the probes under 2%: at least 96% of the steps are done.
    assert machine.steps / (1e4 * machine.now) > 0.96


def test_a_run_that_starts_on_the_slow_count_leaves_it_within_a_few_steps():
    """Blocks are short until the current count's pace is known, so a long first block
    (a run's blocks reach thousands of steps) is never spent on the slow count."""
    machine = Machine(lambda t: {2: 7e-3, 1: 1e-3})
    chooser = chooser_on(machine)
    spent = machine.run(chooser, 0.2, block=10_000)
    assert chooser.current == 1
    assert spent[2] < 0.2  # 8 + 8 steps at 7 ms, then the probe of one thread wins


def test_a_single_count_is_never_probed_and_a_fixed_count_is_kept():
    for chooser in (ThreadChooser(1), ThreadChooser(4, choose=False)):
        for _ in range(3):
            count, steps = chooser.plan(50)
            assert (count, steps) == (chooser.counts[0], 50)
            chooser.record(count, steps, 1.0)


def test_the_cgroup_quota_is_read_from_either_version(tmp_path):
    v2, v1 = tmp_path / "cpu.max", tmp_path / "cpu"
    v1.mkdir()
    assert cgroup_cpus(v2, v1) is None  # neither file: no quota
    v2.write_text("max 100000\n")
    assert cgroup_cpus(v2, v1) is None
    v2.write_text("150000 100000\n")
    assert cgroup_cpus(v2, v1) == pytest.approx(1.5)
    v2.unlink()
    (v1 / "cpu.cfs_quota_us").write_text("-1\n")
    (v1 / "cpu.cfs_period_us").write_text("100000\n")
    assert cgroup_cpus(v2, v1) is None
    (v1 / "cpu.cfs_quota_us").write_text("300000\n")
    assert cgroup_cpus(v2, v1) == pytest.approx(3.0)


def test_the_usable_cpus_follow_the_affinity_mask(monkeypatch):
    monkeypatch.setattr("os.sched_getaffinity", lambda pid: {0, 3, 5})
    monkeypatch.setattr("shellsim.threads.cgroup_cpus", lambda: None)
    assert usable_cpus() == 3
    monkeypatch.setattr("shellsim.threads.cgroup_cpus", lambda: 1.5)
    assert usable_cpus() == 2
    monkeypatch.setattr("shellsim.threads.cgroup_cpus", lambda: 0.2)
    assert usable_cpus() == 1


def test_the_critical_step_is_estimated_on_the_count_the_steps_were_chosen_to_run_on(monkeypatch):
    """On a busy machine the chooser takes the steps to one thread; the estimates between
    them follow, rather than stalling on every thread."""
    import numba

    from shellsim.deck import parse_deck
    from shellsim.solver import simulation

    from .conftest import CLAMPED_PLATE, deck_text, prepared

    sim = prepared(parse_deck(deck_text(*CLAMPED_PLATE))).sim
    counts = []
    monkeypatch.setattr(simulation, "critical_time_step",
                        lambda *args: (counts.append(numba.get_num_threads()), (1.0, None))[1])
    sim.threads.current = 1
    sim.critical_time_step()
    assert counts == [1]
