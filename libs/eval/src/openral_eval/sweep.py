"""Running many episodes: in a local process pool, or as Ray tasks.

Both run the same :func:`~openral_eval.episode.run_episode` on the same specs, so the
same (scene, seed, policy) gives the same result anywhere; only the wall times differ.

- a pool of ``workers`` processes (one is a pool too: a policy that crashes its process
  costs only its episode), forked from this one once every scene
  of the sweep is built here (so a worker starts in milliseconds with the scenes ready,
  instead of importing and composing for a second or more). Nothing in this process has
  rendered (no GL context is inherited): each worker renders offscreen on its own. A
  robosuite scene opens its GL context as it is built, and a forked copy of a GL context
  hangs the child's first render (its rasteriser threads are not forked), so a sweep with
  one starts its workers from a fresh ``forkserver`` process instead, each building its
  scenes on first use. A worker that dies costs only the episode it was running, which
  runs again in a new worker, at most :data:`RETRIES` times, then is recorded with an error
  (:mod:`openral_eval.fork_pool`). An episode still running after ``timeout_s`` of wall
  time (a policy that hangs) is recorded with a ``timeout:`` error and its worker replaced.
- Ray (the optional ``ray`` extra; :mod:`openral_eval.ray_session`): ``address``
  ``local`` starts a Ray instance on this machine with ``workers`` CPUs; any other address
  joins that cluster. Each episode is one task of one CPU, retried :data:`RETRIES` times
  when its worker dies; at most one task per CPU of the cluster runs at a time, so an
  episode still running ``timeout_s`` after it was submitted is cancelled (its worker
  killed) and recorded with the same ``timeout:`` error.

Every finished episode goes to ``on_result`` on this process's main thread, as soon as it
ends, in whatever order episodes end. ``on_ready`` is called once, when every worker is up
with the sweep's scenes built (after the forks for the pool; after
Ray has started and one warm-up task per CPU has built the scenes): what comes before it is
start-up, a fixed cost; what comes after it is the episodes.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from types import ModuleType

from openral_core.errors import OpenralError
from openral_core.loader import load_scene
from openral_core.models import Backend

from openral_eval.episode import EpisodeResult, EpisodeSpec, run_episode, scene_for
from openral_eval.fork_pool import ForkPool, StartMethod
from openral_eval.ray_session import ray_session

RETRIES = 2
"""Extra attempts of an episode whose worker process died."""
OnResult = Callable[[EpisodeResult], None]
OnReady = Callable[[], None]


def _nothing() -> None:
    """The default ``on_ready``."""


def run_pool(
    specs: Sequence[EpisodeSpec],
    workers: int,
    on_result: OnResult,
    on_ready: OnReady = _nothing,
    timeout_s: float = math.inf,
) -> None:
    """Every episode in a :class:`~openral_eval.fork_pool.ForkPool` of ``workers``
    processes, forked once the scenes are built here or started from a fresh process when
    one of them cannot cross a fork (see the module doc)."""
    paths = _scene_paths(specs)
    start: StartMethod = "fork" if all(_inheritable(path) for path in paths) else "forkserver"
    if start == "fork":
        build_scenes(paths)  # before the forks: inherited
    with ForkPool(run_episode, workers, RETRIES, start, timeout_s) as pool:
        on_ready()
        pool.run(specs, on_result, _died, partial(_timed_out, timeout_s))


def _inheritable(path: str) -> bool:
    """Whether the scene of ``path`` may be built before the pool forks: one that opens no
    GL context as it is built (not a robosuite one; see the module doc). The caller may
    have built it already (the CLI does, to refuse a bad file before any episode)."""
    try:
        return load_scene(Path(path)).scene.backend is not Backend.robosuite
    except OpenralError:  # every episode of that scene will say why
        return False


def _died(spec: EpisodeSpec, steps: int, wall_s: float) -> EpisodeResult:
    why = "its worker process died, every time it ran"
    return EpisodeResult.unfinished(spec, why, steps, wall_s)


def _timed_out(timeout_s: float, spec: EpisodeSpec, steps: int, wall_s: float) -> EpisodeResult:
    why = f"timeout: still running after {timeout_s:g} s of wall time; its worker was stopped"
    return EpisodeResult.unfinished(spec, why, steps, wall_s)


def run_ray(
    specs: Sequence[EpisodeSpec],
    address: str,
    workers: int,
    on_result: OnResult,
    on_ready: OnReady = _nothing,
    timeout_s: float = math.inf,
) -> None:
    """Every episode as a Ray task (see the module doc).

    Raises:
        openral_eval.ray_session.SweepError: Ray is not installed, or the cluster at
            ``address`` cannot be joined.
    """
    with ray_session(address, workers) as ray:
        paths = _scene_paths(specs)
        _warm_up(ray, paths, len(specs))
        on_ready()
        slots = max(1, int(ray.cluster_resources().get("CPU", workers)))
        tasks = _RayTasks(ray, slots, timeout_s)
        todo = list(reversed(specs))
        while todo or tasks.running:
            while todo and len(tasks.running) < slots:
                tasks.start(todo.pop())
            for result in tasks.next_results():
                on_result(result)


class _RayTasks:
    """The episodes running as Ray tasks, at most one per CPU of the cluster, so each
    starts when it is submitted and its wall-time limit runs from then."""

    def __init__(self, ray: ModuleType, slots: int, timeout_s: float) -> None:
        self.ray, self.timeout_s = ray, timeout_s
        self.task = ray.remote(num_cpus=1, max_retries=RETRIES)(run_episode)
        self.running: dict[object, tuple[EpisodeSpec, float]] = {}
        """Task reference → (its spec, when it was submitted on the monotonic clock [s])."""

    def start(self, spec: EpisodeSpec) -> None:
        self.running[self.task.remote(spec)] = (spec, time.monotonic())

    def next_results(self) -> list[EpisodeResult]:
        """Wait for the next episode to end or the next deadline to pass; the results of
        what ended, and a ``timeout:`` result for each task past its deadline (cancelled,
        its worker process killed)."""
        from ray.exceptions import RayError

        deadline = min(start for _, start in self.running.values()) + self.timeout_s
        wait_s = None if math.isinf(deadline) else max(0.0, deadline - time.monotonic())
        finished, _ = self.ray.wait(list(self.running), num_returns=1, timeout=wait_s)
        results = []
        for ref in finished:
            spec, start = self.running.pop(ref)
            try:
                results.append(self.ray.get(ref))
            except RayError as error:
                why = f"Ray gave up on it: {type(error).__name__}"
                results.append(EpisodeResult.unfinished(spec, why, 0, time.monotonic() - start))
        now = time.monotonic()
        for ref, (spec, start) in list(self.running.items()):
            if now >= start + self.timeout_s:
                self.ray.cancel(ref, force=True)
                del self.running[ref]
                results.append(_timed_out(self.timeout_s, spec, 0, now - start))
        return results


def _scene_paths(specs: Sequence[EpisodeSpec]) -> list[str]:
    """The sweep's scene files, each once, sorted."""
    return sorted({spec.scene for spec in specs})


def build_scenes(paths: Sequence[str]) -> None:
    """Build every scene of ``paths`` in this process (:func:`scene_for`), leaving one that
    fails to the episodes, which record its error."""
    for path in paths:
        try:
            scene_for(path)
        except Exception:  # every episode of that scene will say why
            continue


def _warm_up(ray: ModuleType, paths: list[str], episodes: int) -> None:
    """One task per CPU of the cluster (at most one per episode), each building the scenes
    in its worker, all at once so that each lands in a worker of its own; the episodes
    that follow reuse those workers. A worker that dies here is the episodes' concern."""
    from ray.exceptions import RayError

    cpus = int(ray.cluster_resources().get("CPU", 1))
    warm = ray.remote(num_cpus=1)(build_scenes)
    try:
        ray.get([warm.remote(paths) for _ in range(max(1, min(cpus, episodes)))])
    except RayError:
        return
