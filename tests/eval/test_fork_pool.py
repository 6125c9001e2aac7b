"""The sweep's fork pool: its workers never outlive the process that forked them."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from tests.eval.processes import alive, children

DRIVER = """
import time
from openral_eval.episode import EpisodeSpec
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
