"""Pacer: a node's periodic work on one thread of its own, by a deadline schedule.

Under ``deploy sim`` a node does several things on a clock: the control tick (and
``/clock``), ``/joint_states``, a frame request per camera, the viewer's sync. Run as rclpy
timers, each firing wakes the node's executor, which rebuilds its wait set over every
entity of the node in Python before it runs the callback; on the Panda tabletop that cost
more CPU than the callbacks (measured: 60 ms per wall second of a 2-core machine for
~120 wakes/s). A :class:`Pacer` runs the same callbacks on one thread that sleeps until the
next one is due (``time.monotonic``), so the executor wakes only for what arrives from
outside (actions, E-stop, lifecycle and parameter services).

Schedule: each job runs on a grid of its own period anchored at the pacer's start
(``start + k * period_s``, k = 1, 2, …), so jobs whose periods divide one another (a 20 Hz
tick, 50 Hz joint states, 10 Hz cameras) fall due together and share one wake; they then
run in the order they were added. A job never runs before its grid time (less
:data:`MERGE_S`), so it never runs faster than its rate; a job that is late runs once and
its missed grid times are skipped and counted (:attr:`PacedJob.skipped`), never made up.

A callback may return a delay [s] instead of None: it could not do its work now (a camera
whose previous frame is still being rendered) and asks to be called again that much later,
still for the same grid time. The retry never moves past the job's next grid time, so a
job still runs at most once per period; a frame is late by a few milliseconds instead of
lost for a whole period (measured on the Panda tabletop's wrist camera on 2 cores: 6.7-8.4
frames a second at a 10 Hz rate without the retry).

A pacer given a ``priority`` keeps a robot's time, as a ros2_control driver's loop does
(``deploy sim --loop-priority`` standing in for an arm's driver beside ``deploy real``): its
thread asks for real-time round-robin scheduling at that priority, and while it runs
Python's thread switch interval is :data:`~openral_hal.realtime.SWITCH_INTERVAL_S`, so the
loop waits at most that long for Python's lock after each sleep or publish (the default,
5 ms, is half a 100 Hz period). Measured on 2 shared cores, a Panda stand-in driven by
``deploy real`` at 100 Hz: its stream paused past 20 ms 56 times in 20 s without either,
once with both.

A callback that raises is reported to ``on_error`` and the job stays scheduled: a failing
job never ends the thread. :meth:`Pacer.cancel` and :meth:`Pacer.stop` return only once no
callback of theirs is running (except when called from a callback, on the pacer's thread).
"""

from __future__ import annotations

import contextlib
import math
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from openral_hal.realtime import SWITCH_INTERVAL_S, answer_first

from openral_bridge.os_thread import name_os_thread

MERGE_S = 0.001
"""Jobs due within this long after the one that woke the pacer run in the same wake [s]."""
STOP_TIMEOUT_S = 5.0
"""Longest wait for the thread to finish the callback it is running when stopping [s]."""

ErrorFn = Callable[["PacedJob", Exception], None]
"""Told which job raised and what (on the pacer's thread)."""
RefusedFn = Callable[[str], None]
"""Told, in one line, that the thread's real-time priority was refused (on its thread)."""
JobFn = Callable[[], float | None]
"""A job's callback: None when done, or a delay [s] after which to call it again for the
same grid time."""


@dataclass(eq=False)
class PacedJob:
    """One periodic callback of a :class:`Pacer` and what it did."""

    name: str
    period_s: float
    """Its period [s]."""
    callback: JobFn
    due_s: float = math.inf
    """Its next grid time [s, ``time.monotonic``]; inf until the pacer starts."""
    slot: int = 0
    """Index k of its next grid time ``start + k * period_s``."""
    runs: int = 0
    """Calls so far (raised or not)."""
    skipped: int = 0
    """Grid times skipped because the job ran late, never made up."""
    cancelled: bool = field(default=False)


class Pacer:
    """Periodic jobs on one thread (see the module doc); add them before or after
    :meth:`start`."""

    def __init__(
        self,
        *,
        on_error: ErrorFn | None = None,
        name: str = "openral-pacer",
        clock: Callable[[], float] = time.monotonic,
        priority: int = 0,
        on_refused: RefusedFn | None = None,
    ) -> None:
        """Nothing runs until :meth:`start`.

        Args:
            on_error: Told about a callback that raised (default: ignored).
            name: The thread's name (also in the OS, see :mod:`openral_bridge.os_thread`).
            clock: Monotonic wall clock [s].
            priority: Real-time round-robin priority of the thread (1-99; 0: ordinary
                scheduling); see the module doc.
            on_refused: Told when the system refused ``priority`` (the thread then runs
                with ordinary scheduling).
        """
        self._on_error = on_error
        self.priority, self._on_refused = priority, on_refused
        self.real_time = False
        """True once the thread runs at :attr:`priority`."""
        self._clock = clock
        self._jobs: list[PacedJob] = []
        self._jobs_lock = threading.Lock()
        self._running_lock = threading.RLock()
        """Held by the thread while it runs the callbacks of one wake."""
        self._bell = threading.Lock()
        """Locked while nobody rang: the thread waits to acquire it until the next job is
        due (a bare lock wait costs less CPU per wake than an ``Event``'s condition)."""
        self._bell.acquire()
        self._stopping = False
        self._start_s: float | None = None
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    @property
    def running(self) -> bool:
        """True between :meth:`start` and :meth:`stop`."""
        return self._thread.is_alive() and not self._stopping

    @property
    def jobs(self) -> tuple[PacedJob, ...]:
        """The scheduled jobs, in the order they run when due together."""
        with self._jobs_lock:
            return tuple(self._jobs)

    def every(self, period_s: float, callback: JobFn, name: str) -> PacedJob:
        """Schedule ``callback`` once per ``period_s``; its first call is one period after
        :meth:`start` (or the next grid time, when the pacer already runs).

        Raises:
            ValueError: ``period_s`` is not a positive finite number.
        """
        if not (math.isfinite(period_s) and period_s > 0):
            raise ValueError(f"the period of {name!r} must be > 0 s, got {period_s}")
        job = PacedJob(name, float(period_s), callback)
        with self._jobs_lock:
            if self._start_s is not None:
                self._schedule(job, self._clock(), count_skipped=False)
            self._jobs.append(job)
        self._ring()
        return job

    def cancel(self, job: PacedJob) -> None:
        """Unschedule ``job`` (idempotent); it is not called after this returns (a call in
        progress is waited for unless the pacer was told to stop: :meth:`stop` bounds that
        wait). Never call it holding a lock that a job's callback takes."""
        job.cancelled = True
        with self._jobs_lock:
            if job in self._jobs:
                self._jobs.remove(job)
        if not self._stopping:  # a call of it in progress ends first (reentrant on the thread)
            with self._running_lock:
                pass

    def start(self) -> None:
        """Start the thread; every job's grid is anchored now."""
        with self._jobs_lock:
            self._start_s = self._clock()
            for job in self._jobs:
                self._schedule(job, self._start_s, count_skipped=False)
        self._thread.start()

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> bool:
        """Stop after the callback running now (idempotent); no callback runs after it.

        Returns:
            True when the thread has ended (or never started, or this is the thread).
        """
        self._stopping = True
        self._ring()
        if not self._thread.is_alive() or threading.current_thread() is self._thread:
            return True
        self._thread.join(timeout_s)
        return not self._thread.is_alive()

    # -- the pacer's thread ----------------------------------------------------------------

    def _run(self) -> None:
        name_os_thread(self._thread.name)
        switch_s = sys.getswitchinterval()
        if self.priority:
            self.real_time = answer_first(self.priority)
            if self.real_time:
                sys.setswitchinterval(min(switch_s, SWITCH_INTERVAL_S))
            elif self._on_refused is not None:
                self._on_refused(
                    f"{self._thread.name}: real-time priority {self.priority} refused (it needs "
                    "root or CAP_SYS_NICE): the loop runs with ordinary scheduling"
                )
        try:
            self._serve()
        finally:
            if self.real_time:
                sys.setswitchinterval(switch_s)

    def _serve(self) -> None:
        """Run the jobs as they fall due until :meth:`stop`."""
        while not self._stopping:
            with self._jobs_lock:
                jobs = list(self._jobs)
            now = self._clock()
            first = min((job.due_s for job in jobs), default=math.inf)
            if first > now:
                wait_s = min(first - now, threading.TIMEOUT_MAX)
                self._bell.acquire(timeout=-1 if math.isinf(first) else wait_s)
                continue
            limit = now + MERGE_S
            with self._running_lock:
                for job in jobs:
                    if job.due_s <= limit and not self._stopping:
                        self._call(job)

    def _ring(self) -> None:
        """Wake the thread to look at its jobs again (any thread; rings do not queue)."""
        with contextlib.suppress(RuntimeError):  # already rung
            self._bell.release()

    def _call(self, job: PacedJob) -> None:
        """Run one due job and move it to its next grid time after now."""
        if job.cancelled:
            return
        job.runs += 1
        retry_s = None
        try:
            retry_s = job.callback()
        except Exception as error:  # reported; the job and the thread go on
            self._report(job, error)
        now = self._clock()
        if isinstance(retry_s, float) and retry_s > 0.0:  # anything else: done
            assert self._start_s is not None
            next_grid_s = self._start_s + (job.slot + 1) * job.period_s
            if now + retry_s < next_grid_s - MERGE_S:
                job.due_s = now + retry_s  # the same grid time, a little later
                return
        self._schedule(job, now, count_skipped=True)

    def _report(self, job: PacedJob, error: Exception) -> None:
        if self._on_error is not None:
            with contextlib.suppress(Exception):  # a broken reporter must not end the thread
                self._on_error(job, error)

    def _schedule(self, job: PacedJob, now_s: float, *, count_skipped: bool) -> None:
        """Move ``job`` to its first grid time after its current one and after ``now_s``;
        with ``count_skipped``, the grid times passed over are counted."""
        assert self._start_s is not None
        late = math.floor((now_s - self._start_s) / job.period_s) + 1
        following = max(job.slot + 1, late)
        if count_skipped:
            job.skipped += following - job.slot - 1
        job.slot = following
        job.due_s = self._start_s + following * job.period_s
