"""Pacer: periodic jobs on one thread by a deadline schedule (real thread, real clock; a
late job is simulated by moving the pacer's clock, never by a sleep)."""

from __future__ import annotations

import itertools
import math
import threading
import time
from collections.abc import Callable, Iterator

import pytest
from openral_bridge.pacer import MERGE_S, PacedJob, Pacer

WAIT_S = 15.0


def wait_until(predicate: Callable[[], bool], what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {WAIT_S} s waiting for {what}")
        time.sleep(0.005)


def _grid_slots(pacer: Pacer, period: float, times: list[float]) -> list[int]:
    """The grid period each call time falls in (a call may run up to MERGE_S early); a job
    that never runs twice in one period has strictly increasing slots, however late a call
    was on a loaded machine (gaps between calls can then be shorter than a period)."""
    start = pacer._start_s
    assert start is not None
    return [math.floor((t - start + MERGE_S) / period) for t in times]


@pytest.fixture
def pacers() -> Iterator[list[Pacer]]:
    """Pacers a test made; each is stopped (and must have ended) afterwards."""
    made: list[Pacer] = []
    yield made
    for pacer in made:
        assert pacer.stop()


def test_jobs_due_together_run_in_one_wake_in_the_order_they_were_added(
    pacers: list[Pacer],
) -> None:
    calls: list[tuple[str, int]] = []
    wakes = [0]
    pacer = Pacer()
    pacers.append(pacer)

    def count_wake() -> None:
        wakes[0] += 1

    # added first, on the finest grid: it runs first in every wake and numbers it
    pacer.every(0.01, count_wake, "wake")
    pacer.every(0.01, lambda: calls.append(("fast", wakes[0])), "fast")
    pacer.every(0.02, lambda: calls.append(("slow", wakes[0])), "slow")
    pacer.start()
    wait_until(lambda: sum(name == "slow" for name, _ in calls) >= 10, "ten slow calls")
    assert pacer.stop()
    for index, (name, wake) in enumerate(calls):
        if name == "slow":  # always right after the fast job of the same wake
            assert index > 0 and calls[index - 1] == ("fast", wake)


def test_first_call_is_one_period_after_start_and_none_after_stop(pacers: list[Pacer]) -> None:
    called = threading.Event()
    times: list[float] = []
    pacer = Pacer()
    pacers.append(pacer)
    pacer.every(0.05, lambda: (times.append(time.monotonic()), called.set()), "job")
    started = time.monotonic()
    pacer.start()
    assert called.wait(WAIT_S)
    assert times[0] - started >= 0.05 - 0.002  # never early (within the merge window)
    assert pacer.stop() and not pacer.running
    count = len(times)
    time.sleep(0.15)  # three periods: a live job would have run
    assert len(times) == count


def test_a_late_job_skips_the_grid_times_it_missed_and_counts_them(pacers: list[Pacer]) -> None:
    offset = [0.0]
    period = 0.02
    job_runs: list[float] = []

    def clock() -> float:
        return time.monotonic() + offset[0]

    def job() -> None:
        job_runs.append(clock())
        if len(job_runs) == 3:  # this call "took" 2.5 periods
            offset[0] += 2.5 * period

    pacer = Pacer(clock=clock)
    pacers.append(pacer)
    paced = pacer.every(period, job, "job")
    pacer.start()
    wait_until(lambda: len(job_runs) >= 6, "six calls")
    assert pacer.stop()
    assert paced.skipped >= 2  # counted, and not made up: no burst after the late call
    slots = _grid_slots(pacer, period, job_runs)
    assert all(b > a for a, b in itertools.pairwise(slots)), slots  # never twice a period


def test_a_raising_job_is_reported_and_keeps_its_schedule(pacers: list[Pacer]) -> None:
    errors: list[tuple[str, str]] = []
    runs = [0]

    def broken() -> None:
        runs[0] += 1
        raise RuntimeError("boom")

    def broken_reporter(job: PacedJob, error: Exception) -> None:
        errors.append((job.name, str(error)))
        raise ValueError("the reporter fails too")

    pacer = Pacer(on_error=broken_reporter)
    pacers.append(pacer)
    pacer.every(0.01, broken, "broken")
    pacer.start()
    wait_until(lambda: runs[0] >= 3, "three calls")
    assert pacer.running
    assert errors[0] == ("broken", "boom")


def test_cancel_waits_for_a_call_in_progress_and_stops_the_job(pacers: list[Pacer]) -> None:
    inside, release = threading.Event(), threading.Event()
    runs = [0]

    def slow() -> None:
        runs[0] += 1
        inside.set()
        assert release.wait(WAIT_S)

    pacer = Pacer()
    pacers.append(pacer)
    job = pacer.every(0.01, slow, "slow")
    pacer.start()
    assert inside.wait(WAIT_S)
    cancelled = threading.Event()
    canceller = threading.Thread(target=lambda: (pacer.cancel(job), cancelled.set()))
    canceller.start()
    assert not cancelled.wait(0.05)  # the call in progress holds it
    release.set()
    assert cancelled.wait(WAIT_S)
    canceller.join()
    count = runs[0]
    time.sleep(0.05)
    assert runs[0] == count and pacer.jobs == ()


def test_a_job_can_cancel_itself_and_jobs_can_be_added_while_running(
    pacers: list[Pacer],
) -> None:
    pacer = Pacer()
    pacers.append(pacer)
    runs: dict[str, int] = {"once": 0, "late": 0}
    jobs: dict[str, PacedJob] = {}

    def once() -> None:
        runs["once"] += 1
        pacer.cancel(jobs["once"])

    jobs["once"] = pacer.every(0.01, once, "once")
    pacer.start()
    jobs["late"] = pacer.every(0.01, lambda: runs.__setitem__("late", runs["late"] + 1), "late")
    wait_until(lambda: runs["late"] >= 5, "calls of a job added while running")
    assert runs["once"] == 1 and pacer.jobs == (jobs["late"],)


@pytest.mark.parametrize("period", [0.0, -1.0, float("inf"), float("nan")])
def test_a_period_that_is_not_positive_and_finite_is_refused(period: float) -> None:
    with pytest.raises(ValueError, match="must be > 0 s"):
        Pacer().every(period, lambda: None, "bad")


def test_stop_without_start_and_twice_is_fine() -> None:
    pacer = Pacer()
    assert pacer.stop() and pacer.stop()


def test_a_job_that_asks_again_is_called_soon_for_the_same_grid_time(
    pacers: list[Pacer],
) -> None:
    """A refused frame (the previous one still in flight) is requested again soon, within
    the same period, not a whole period later; retries cost no grid time."""
    period, retry = 0.1, 0.01
    calls: list[float] = []
    done: list[float] = []

    def job() -> float | None:
        calls.append(time.monotonic())
        if len(calls) % 4 == 0:  # three refusals, then done, each grid time
            done.append(calls[-1])
            return None
        return retry

    pacer = Pacer()
    pacers.append(pacer)
    paced = pacer.every(period, job, "camera")
    pacer.start()
    wait_until(lambda: len(done) >= 4, "four grid times served after retries")
    assert pacer.stop()
    assert paced.skipped == 0  # retries cost no grid time
    slots = _grid_slots(pacer, period, calls[:16])
    assert [len(set(slots[i : i + 4])) for i in range(0, 16, 4)] == [1, 1, 1, 1], slots
    assert all(b == a + 1 for a, b in itertools.pairwise(slots[::4])), slots  # every period


def test_a_retry_never_runs_past_the_next_grid_time(pacers: list[Pacer]) -> None:
    """A retry later than the next grid time, or a value that is no delay, is a job done."""
    period = 0.05
    calls: list[float] = []
    pacer = Pacer()
    pacers.append(pacer)
    late = pacer.every(period, lambda: calls.append(time.monotonic()) or 10.0, "stubborn")
    odd: list[int] = []
    tuple_job = pacer.every(period, lambda: (odd.append(1), "not a delay"), "tuple")
    pacer.start()
    wait_until(lambda: len(calls) >= 6 and len(odd) >= 6, "six calls of each")
    assert pacer.stop()
    slots = _grid_slots(pacer, period, calls)
    assert all(b > a for a, b in itertools.pairwise(slots)), slots  # no faster than its rate
    assert late.runs == len(calls) and tuple_job.runs == len(odd)


def _on_pacer_thread(pacer: Pacer) -> tuple[int, int, float]:
    """(scheduling policy, priority, switch interval [s]) seen from a job of ``pacer``."""
    seen: list[tuple[int, int, float]] = []

    def look() -> None:
        import os
        import sys

        tid = threading.get_native_id()
        policy = os.sched_getscheduler(tid)
        seen.append((policy, os.sched_getparam(tid).sched_priority, sys.getswitchinterval()))

    job = pacer.every(0.01, look, "look")
    wait_until(lambda: bool(seen), "a job's look at its thread")
    pacer.cancel(job)
    return seen[0]


def test_a_priority_the_system_refuses_is_told_in_one_line_and_changes_nothing(
    pacers: list[Pacer],
) -> None:
    import os
    import sys

    told: list[str] = []
    before = sys.getswitchinterval()
    pacer = Pacer(priority=100, on_refused=told.append)  # beyond 1-99: refused everywhere
    pacers.append(pacer)
    pacer.start()
    policy, _, switch_s = _on_pacer_thread(pacer)
    assert policy == os.SCHED_OTHER and switch_s == before and not pacer.real_time
    assert len(told) == 1 and "real-time priority 100 refused" in told[0], told


def test_a_granted_priority_holds_while_the_pacer_runs_and_the_switch_interval_comes_back(
    pacers: list[Pacer],
) -> None:
    """As root (CI, this machine) the priority is granted; elsewhere the refusal must be
    told instead, and the thread left ordinary."""
    import os
    import sys

    from openral_hal.realtime import SWITCH_INTERVAL_S

    told: list[str] = []
    before = sys.getswitchinterval()
    pacer = Pacer(priority=7, on_refused=told.append)
    pacers.append(pacer)
    pacer.start()
    policy, priority, switch_s = _on_pacer_thread(pacer)
    if pacer.real_time:
        assert (policy, priority, switch_s) == (os.SCHED_RR, 7, min(before, SWITCH_INTERVAL_S))
        assert not told
    else:
        assert policy == os.SCHED_OTHER and switch_s == before and len(told) == 1
    assert pacer.stop()
    assert sys.getswitchinterval() == before
