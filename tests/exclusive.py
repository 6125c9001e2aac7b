"""Tests that measure real time run alone, also when pytest-xdist spreads the suite.

A test marked ``exclusive`` (rates, latencies, a graph keeping real time) holds an
exclusive lock for its setup, call and teardown; every other test holds the same lock
shared. So on a 2-core machine no other test competes with a measurement, while everything
else runs on both cores. A turnstile lock keeps a waiting measurement from being starved:
while it waits, no other test starts. Outside xdist there is nothing to share, and nothing
is locked.
"""

from __future__ import annotations

import atexit
import fcntl
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

LOCK_DIR_ENV = "OPENRAL_TEST_LOCK_DIR"


def lock_dir() -> Path:
    """The folder of the locks, made once by the controlling process (inherited by the
    workers through the environment)."""
    folder = os.environ.get(LOCK_DIR_ENV)
    if not folder:
        folder = tempfile.mkdtemp(prefix="openral-test-locks-")
        os.environ[LOCK_DIR_ENV] = folder
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return Path(folder)


@contextmanager
def turn(exclusive: bool) -> Iterator[None]:
    """Hold the suite's lock: alone when ``exclusive``, else with other shared holders."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        yield
        return
    folder = lock_dir()
    turnstile: IO[bytes]
    with (folder / "turnstile").open("ab") as turnstile, (folder / "suite").open("ab") as suite:
        fcntl.flock(turnstile, fcntl.LOCK_EX)
        fcntl.flock(suite, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
        fcntl.flock(turnstile, fcntl.LOCK_UN)
        try:
            yield
        finally:
            fcntl.flock(suite, fcntl.LOCK_UN)
