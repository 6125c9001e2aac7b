"""Running many episodes: in this process, in a local process pool, or as Ray tasks.

All three run the same :func:`~openral_eval.episode.run_episode` on the same specs, so the
same (scene, seed, policy) gives the same result anywhere; only the wall times differ.

- ``workers == 1``: one after another in this process.
- ``workers > 1``: a pool of that many processes, forked from this one once every scene
  of the sweep is built here (so a worker starts in milliseconds with the scenes ready,
  instead of importing and composing for a second or more). Nothing in this process has
  rendered (no GL context is inherited): each worker renders offscreen on its own. A
  worker that dies takes the pool with it: the episodes it had not finished are run again
  in a new pool, at most :data:`RETRIES` times, then recorded with an error.
- Ray (the optional ``ray`` extra): ``address`` ``local`` starts a Ray instance on this
  machine with ``workers`` CPUs; any other address joins that cluster (whose nodes must
  have openral installed; the head must accept a connection within
  :data:`JOIN_TIMEOUT_S`). Each episode is one task of one CPU, retried :data:`RETRIES`
  times when its worker dies. Ray's usage report is off (nothing leaves the machine).

Every finished episode goes to ``on_result`` on this process's main thread, as soon as it
ends, in whatever order episodes end.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import socket
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from types import ModuleType

from openral_core.errors import OpenralError

from openral_eval.episode import EpisodeResult, EpisodeSpec, run_episode, scene_for

RETRIES = 2
"""Extra attempts of an episode whose worker process died."""
OnResult = Callable[[EpisodeResult], None]


class SweepError(OpenralError):
    """A sweep could not start (Ray missing or unreachable)."""


def run_serial(specs: Sequence[EpisodeSpec], on_result: OnResult) -> None:
    """Every episode in this process, in order."""
    for spec in specs:
        on_result(run_episode(spec))


def run_pool(specs: Sequence[EpisodeSpec], workers: int, on_result: OnResult) -> None:
    """Every episode in a pool of ``workers`` processes (see the module doc)."""
    pending, attempts = list(specs), 0
    while pending and attempts <= RETRIES:
        pending = _pool_pass(pending, workers, on_result)
        attempts += 1
    for spec in pending:
        on_result(EpisodeResult.unfinished(spec, "its worker process died, every time it ran"))


def _pool_pass(specs: list[EpisodeSpec], workers: int, on_result: OnResult) -> list[EpisodeSpec]:
    """Run ``specs`` in one pool; returns those whose worker died with the pool."""
    for path in sorted({spec.scene for spec in specs}):
        scene_for(path)  # built before the fork: every worker inherits it
    context = multiprocessing.get_context("fork")
    with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        running: dict[Future[EpisodeResult], EpisodeSpec] = {}
        queue = list(reversed(specs))
        broken: list[EpisodeSpec] = []
        while queue or running:
            while queue and len(running) < 2 * workers:  # a little ahead, never all at once
                spec = queue.pop()
                running[pool.submit(run_episode, spec)] = spec
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                spec = running.pop(future)
                try:
                    on_result(future.result())
                except BrokenProcessPool:
                    broken.append(spec)
            if broken:
                return broken + [running[f] for f in running] + list(reversed(queue))
    return []


def run_ray(specs: Sequence[EpisodeSpec], address: str, workers: int, on_result: OnResult) -> None:
    """Every episode as a Ray task (see the module doc).

    Raises:
        SweepError: Ray is not installed, or the cluster at ``address`` cannot be joined.
    """
    with ray_session(address, workers) as ray:
        from ray.exceptions import RayError

        task = ray.remote(num_cpus=1, max_retries=RETRIES)(run_episode)
        waiting = {task.remote(spec): spec for spec in specs}
        while waiting:
            finished, _ = ray.wait(list(waiting), num_returns=1)
            for ref in finished:
                spec = waiting.pop(ref)
                try:
                    on_result(ray.get(ref))
                except RayError as error:
                    on_result(
                        EpisodeResult.unfinished(spec, f"Ray gave up on it: {type(error).__name__}")
                    )


@contextmanager
def ray_session(address: str, workers: int) -> Iterator[ModuleType]:
    """Ray for the block: a new local instance with ``workers`` CPUs (``address``
    ``local``) or the cluster at ``address``; shut down (or left) after the block.

    Raises:
        SweepError: Ray is not installed, or the cluster at ``address`` cannot be joined.
    """
    try:
        import ray
    except ImportError:
        raise SweepError(
            "--ray needs Ray: install openral with the 'ray' extra (pip install 'openral[ray]')"
        ) from None
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # offline: no usage report
    # quiet: Ray's start-up lines would interleave with the sweep's own report
    try:
        if address == "local":
            ray.init(
                num_cpus=workers,
                include_dashboard=False,
                log_to_driver=False,
                logging_level=logging.ERROR,
            )
        else:
            check_ray_address(address)
            ray.init(address=address, log_to_driver=False, logging_level=logging.ERROR)
    except (ConnectionError, RuntimeError, ValueError) as error:
        raise SweepError(f"cannot start or join Ray at {address!r}: {error}") from None
    try:
        yield ray
    finally:
        ray.shutdown()


JOIN_TIMEOUT_S = 5.0
"""How long a cluster's head has to accept a TCP connection before ``--ray ADDRESS`` fails.

Ray's own join keeps retrying for many minutes when nothing listens at the address."""


def check_ray_address(address: str) -> None:
    """Fail fast unless something accepts a connection at ``address`` (``[ray://]HOST:PORT``;
    ``auto`` is left to Ray, which finds a local cluster or fails at once).

    Raises:
        SweepError: the address is malformed, or nothing answers within :data:`JOIN_TIMEOUT_S`.
    """
    if address == "auto":
        return
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise SweepError(
            f"--ray {address!r}: expected 'local', 'auto' or a cluster's HOST:PORT "
            "(e.g. 10.0.0.5:6379)"
        )
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=JOIN_TIMEOUT_S).close()
    except TimeoutError:
        raise SweepError(
            f"cannot join Ray at {address!r}: nothing answers within {JOIN_TIMEOUT_S:g} s"
        ) from None
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise SweepError(f"cannot join Ray at {address!r}: nothing answers ({reason})") from None
