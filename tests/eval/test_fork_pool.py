"""The sweep's fork pool: its workers never outlive the process that forked them; a
policy that hangs, exits or crashes its process costs only its own episode."""

from __future__ import annotations

import faulthandler
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from openral_eval import fork_pool
from openral_eval.episode import EpisodeResult, EpisodeSpec
from openral_eval.fork_pool import ForkPool

from tests.eval.processes import alive, children

TIMEOUT_S = 2.0
"""The pool's time limit of one episode in these tests [s]."""

DRIVER = """
import time
from openral_eval.episode import EpisodeSpec
from openral_eval import fork_pool
from openral_eval.fork_pool import ForkPool

def slow(spec):
    time.sleep(120)  # an episode far longer than the test

with ForkPool(slow, 2, retries=0) as pool:
    print("forked", flush=True)
    pool.run([EpisodeSpec("scene.yaml", seed, "wave") for seed in (0, 1)], print, print)
"""


def test_workers_busy_with_an_episode_die_with_a_killed_sweep() -> None:
    driver = subprocess.Popen(
        [sys.executable, "-c", DRIVER], stdout=subprocess.PIPE, text=True, cwd=Path.cwd()
    )
    try:
        assert driver.stdout is not None and driver.stdout.readline().strip() == "forked"
        workers = children(driver.pid)
        assert len(workers) == 2 and all(alive(pid) for pid in workers)
        time.sleep(0.2)  # both are inside their episode
        driver.send_signal(signal.SIGKILL)
        driver.wait(timeout=30)
        gone = time.monotonic() + 2.0
        while any(alive(pid) for pid in workers) and time.monotonic() < gone:
            time.sleep(0.02)
        assert not any(alive(pid) for pid in workers)
    finally:
        driver.kill()
        driver.wait()


def _hostile(spec: EpisodeSpec) -> EpisodeResult:
    """Seed 0 ends well; 1 hangs, 2 calls sys.exit, 3 segfaults its process."""
    if spec.seed == 1:
        threading.Event().wait()
    elif spec.seed == 2:
        sys.exit(3)
    elif spec.seed == 3:
        faulthandler.disable()  # pytest's would print this child's stacks into the log
        os.kill(os.getpid(), signal.SIGSEGV)
    return EpisodeResult.unfinished(spec, "")  # a stand-in for a finished episode


def _gave_up(why: str) -> Callable[[EpisodeSpec, int, float], EpisodeResult]:
    return lambda spec, steps, wall_s: EpisodeResult.unfinished(spec, why, steps, wall_s)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_hung_an_exiting_and_a_crashing_policy_each_cost_only_their_episode(
    workers: int,
) -> None:
    specs = [EpisodeSpec("scene.yaml", seed, "hostile") for seed in range(4)]
    specs.append(EpisodeSpec("scene.yaml", 4, "hostile"))  # after them all: still runs
    results: list[EpisodeResult] = []
    started = time.monotonic()
    # forkserver: a fork of this test process would carry the GL contexts and ROS state of
    # the tests run before it here, which a sweep's process never has
    with ForkPool(_hostile, workers, 1, "forkserver", TIMEOUT_S) as pool:
        pool.run(specs, results.append, _gave_up("died"), _gave_up("timeout"))
    by_seed = {result.seed: result.error for result in results}
    assert len(results) == 5
    assert by_seed == {0: "", 1: "timeout", 2: "died", 3: "died", 4: ""}, by_seed
    hung = next(result for result in results if result.seed == 1)
    assert TIMEOUT_S <= hung.wall_time_s < TIMEOUT_S + 10.0  # how long it ran is kept
    assert time.monotonic() - started < TIMEOUT_S + 20.0  # the hung one is not waited twice


def test_a_time_limit_must_be_positive() -> None:
    with pytest.raises(ValueError, match="time limit must be positive"):
        ForkPool(_hostile, 1, retries=0, timeout_s=0.0)


def _dies_at_start(run: object, pipe: object, inherited: object, steps: object) -> None:
    os._exit(7)


def _silent_at_start(run: object, pipe: object, inherited: object, steps: object) -> None:
    time.sleep(30)


def test_a_worker_that_cannot_start_is_one_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fork_pool, "_serve", _dies_at_start)
    with pytest.raises(fork_pool.WorkerStartError, match=r"died while starting \(exit code 7\)"):
        ForkPool(_hostile, 1, retries=0)
    monkeypatch.setattr(fork_pool, "_serve", _silent_at_start)
    monkeypatch.setattr(fork_pool, "START_TIMEOUT_S", 0.5)
    with pytest.raises(fork_pool.WorkerStartError, match=r"did not start within 0\.5 s"):
        ForkPool(_hostile, 1, retries=0)
