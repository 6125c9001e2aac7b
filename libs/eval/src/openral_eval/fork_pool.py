"""A pool of forked worker processes in which a dead worker costs only its own episode.

The standard library's process pools break as a whole when one worker dies (every
episode in flight is lost with it, so an innocent episode sharing a pool with one that
crashes its process would be recorded as dead too). Here each worker has a pipe of its
own and runs one episode at a time:

- a worker that dies (its pipe closes) is replaced by a new fork, and only the episode it
  was running is tried again, at most ``retries`` times, then recorded with an error;
- workers are forked from this process (start method ``fork``), so they inherit whatever
  it has built (the sweep's scenes) and start in milliseconds; or, when this process holds
  state a fork cannot carry (a GL context: the rasteriser's threads are not forked, so a
  child's first render waits for them forever), from a fresh server process (start method
  ``forkserver``), so they build what they need themselves;
- a new worker reports when it is up, and an episode's time starts when it is handed to
  a worker that is up; a worker still on one episode after ``timeout_s`` of wall time (a
  policy that hangs) is killed and replaced; that episode is given up at once (it would
  hang again);
- they ignore Ctrl-C (this process decides when they stop) and are killed when their
  parent dies, even by ``SIGKILL`` (a ``forkserver`` exits when this process does).
"""

from __future__ import annotations

import ctypes
import math
import multiprocessing
import signal
import time
from collections import deque
from collections.abc import Callable, Sequence
from contextlib import suppress
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from multiprocessing.context import ForkContext, ForkServerContext
from multiprocessing.process import BaseProcess
from typing import Literal

from openral_core.errors import OpenralError

from openral_eval import episode
from openral_eval.episode import EpisodeResult, EpisodeSpec, StepCount

Run = Callable[[EpisodeSpec], EpisodeResult]
StartMethod = Literal["fork", "forkserver"]
_PR_SET_PDEATHSIG = 1
READY = "ready"
"""What a worker sends once it is up, before its first episode."""
START_TIMEOUT_S = 120.0
"""Longest a new worker may take to be up [s]."""


class WorkerStartError(OpenralError):
    """A worker process of the pool could not start."""


GiveUp = Callable[[EpisodeSpec, int, float], EpisodeResult]
"""The result recorded for an episode given up (its worker died too often, or hung), from
its spec, the steps it got through and its wall time [s] on its last try."""


@dataclass
class _Worker:
    process: BaseProcess
    pipe: Connection
    steps: StepCount
    """Steps of its episode so far (shared with the worker: :data:`episode.step_count`)."""
    spec: EpisodeSpec | None = None
    started: float = 0.0
    """When it was handed its episode (``time.monotonic``) [s]."""


def _serve(run: Run, pipe: Connection, inherited: Sequence[Connection], steps: StepCount) -> None:
    """A worker's loop: receive a spec, send its result; stop at ``None`` or a closed pipe.
    Its episodes count their steps into ``steps``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    episode.step_count = steps
    with suppress(AttributeError, OSError):  # Linux: die with the parent, not finish an
        ctypes.CDLL(None).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)  # episode nobody reads
    for other in inherited:  # the parent's ends, so that a parent's death closes our pipe
        other.close()
    try:
        pipe.send(READY)  # an episode's time starts once a worker is up, not while it starts
        while (spec := pipe.recv()) is not None:
            pipe.send(run(spec))
    except (EOFError, BrokenPipeError):
        return


def _await_ready(worker: _Worker) -> None:
    """Wait for a new worker's :data:`READY` (a fork: milliseconds; a ``forkserver``
    child: its imports, a second or more on a loaded machine).

    Raises:
        WorkerStartError: It died or stayed silent for :data:`START_TIMEOUT_S`.
    """
    try:
        if worker.pipe.poll(START_TIMEOUT_S) and worker.pipe.recv() == READY:
            return
        why = f"did not start within {START_TIMEOUT_S:g} s"
    except (EOFError, OSError):
        worker.process.join(START_TIMEOUT_S)
        why = f"died while starting (exit code {worker.process.exitcode})"
    worker.process.kill()
    worker.pipe.close()
    raise WorkerStartError(f"a sweep worker process {why}")


def _hand_out(worker: _Worker, queue: deque[EpisodeSpec]) -> None:
    """Give an idle worker the next episode, if there is one."""
    if worker.spec is None and queue:
        worker.spec, worker.started = queue.popleft(), time.monotonic()
        worker.steps.value = 0
        with suppress(OSError):  # it died idle: its death is found when its pipe is read
            worker.pipe.send(worker.spec)


class ForkPool:
    """``workers`` forked processes running ``run`` (a module-level function, for
    ``forkserver``) on one spec each at a time, each spec for at most ``timeout_s`` of wall
    time (``math.inf``: no limit)."""

    def __init__(
        self,
        run: Run,
        workers: int,
        retries: int,
        start: StartMethod = "fork",
        timeout_s: float = math.inf,
    ) -> None:
        if workers < 1:
            raise ValueError(f"a pool needs at least one worker, not {workers}")
        if not timeout_s > 0.0:
            raise ValueError(f"an episode's time limit must be positive, not {timeout_s}")
        self._run, self._retries, self._start = run, retries, start
        self._timeout_s = timeout_s
        self._context: ForkContext | ForkServerContext = (
            multiprocessing.get_context("fork")
            if start == "fork"
            else multiprocessing.get_context("forkserver")
        )
        self._workers: list[_Worker] = []
        for _ in range(workers):
            self._workers.append(self._fork())
        for worker in self._workers:
            _await_ready(worker)

    def _fork(self) -> _Worker:
        mine, theirs = self._context.Pipe()
        inherited = [mine, *(worker.pipe for worker in self._workers)]
        if self._start != "fork":  # nothing is inherited; sending our ends would copy them
            inherited = []
        steps = self._context.RawValue("q", 0)
        process = self._context.Process(
            target=_serve, args=(self._run, theirs, inherited, steps), daemon=True
        )
        process.start()
        theirs.close()
        return _Worker(process, mine, steps)

    def run(
        self,
        specs: Sequence[EpisodeSpec],
        on_result: Callable[[EpisodeResult], None],
        died: GiveUp,
        timed_out: GiveUp | None = None,
    ) -> None:
        """Every spec, each result to ``on_result`` as it arrives; a spec whose worker died
        more than ``retries`` times gets ``died(spec, steps, wall_s)`` instead, and one that
        ran over the time limit ``timed_out(...)`` (``died`` when not given)."""
        queue, attempts = deque(specs), dict.fromkeys(specs, 0)
        while queue or any(worker.spec for worker in self._workers):
            for worker in self._workers:
                _hand_out(worker, queue)
            busy = [worker for worker in self._workers if worker.spec is not None]
            wait([worker.pipe for worker in busy], self._wait_s(busy))
            for worker in busy:
                if not worker.pipe.poll():
                    if worker.spec and time.monotonic() - worker.started > self._timeout_s:
                        worker.process.kill()  # no second try: it would hang again
                        give_up = timed_out or died
                        self._replace(worker, queue, attempts, on_result, give_up, retry=False)
                    continue
                try:
                    result = worker.pipe.recv()
                except (EOFError, OSError):  # the worker died mid-episode
                    self._replace(worker, queue, attempts, on_result, died)
                    continue
                worker.spec = None
                _hand_out(worker, queue)  # its next episode first, then the bookkeeping
                on_result(result)

    def _wait_s(self, busy: Sequence[_Worker]) -> float | None:
        """How long to wait for a result before the first busy worker's time is up [s]
        (None: no limit)."""
        if math.isinf(self._timeout_s) or not busy:
            return None
        first = min(worker.started for worker in busy) + self._timeout_s
        return max(first - time.monotonic(), 0.0)

    def _replace(
        self,
        worker: _Worker,
        queue: deque[EpisodeSpec],
        attempts: dict[EpisodeSpec, int],
        on_result: Callable[[EpisodeResult], None],
        give_up: GiveUp,
        *,
        retry: bool = True,
    ) -> None:
        """Fork a new worker in the dead one's place; try its episode again (at most
        ``retries`` times, never when ``retry`` is False) or give it up."""
        spec = worker.spec
        assert spec is not None
        progress = (int(worker.steps.value), time.monotonic() - worker.started)
        worker.pipe.close()
        worker.process.join()
        self._workers[self._workers.index(worker)] = replacement = self._fork()
        _await_ready(replacement)
        attempts[spec] += 1
        if not retry or attempts[spec] > self._retries:
            on_result(give_up(spec, *progress))
        else:
            queue.appendleft(spec)

    def __enter__(self) -> ForkPool:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop every worker: an idle one when it reads the end, a busy one (the sweep was
        interrupted) at once."""
        for worker in self._workers:
            if worker.spec is not None:
                worker.process.kill()
            with suppress(OSError):
                worker.pipe.send(None)
            worker.pipe.close()
        for worker in self._workers:
            worker.process.join(timeout=5.0)
            if worker.process.is_alive():
                worker.process.kill()
                worker.process.join()
