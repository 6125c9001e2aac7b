"""A running one-node Ray cluster for a block, as another program on this machine would run
it, so that ``openral sim sweep --ray ADDRESS`` can join it.

The head is a separate Python process holding a local ``ray.init``: unlike ``ray start``,
whose ``ray stop`` stops every Ray instance of the machine, it stops alone when its stdin
closes.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager

_HEAD = """
import os, sys, ray
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
ray.init(num_cpus=int(sys.argv[1]), include_dashboard=False)
print(ray.get_runtime_context().gcs_address, flush=True)
sys.stdin.read()
ray.shutdown()
"""


class RayHead:
    """A head process starting; :attr:`address` waits until it has started."""

    def __init__(self, cpus: int) -> None:
        self._process = subprocess.Popen(
            [sys.executable, "-c", _HEAD, str(cpus)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        self._address: str | None = None

    @property
    def address(self) -> str:
        """The cluster's ``HOST:PORT`` (blocks until the head has printed it)."""
        if self._address is None:
            assert self._process.stdout is not None
            self._address = self._process.stdout.readline().strip()
            if not self._address:
                raise RuntimeError("the Ray head ended before it started")
        return self._address

    def stop(self) -> None:
        """Close its stdin and wait for it to shut Ray down."""
        self._process.communicate("", timeout=60)


@contextmanager
def ray_head(cpus: int) -> Iterator[RayHead]:
    """A Ray head with ``cpus`` CPUs for the block (starting while the block runs)."""
    head = RayHead(cpus)
    try:
        yield head
    finally:
        head.stop()
