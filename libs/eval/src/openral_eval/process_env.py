"""An env that lives in a process of its own, driven through shared memory.

:class:`ProcessEnv` is a gymnasium env whose ``step`` and ``reset`` run in a worker
process: the action and the observation travel through shared memory (gymnasium's own
layout for the space), the reward and the ends through shared numbers, the info (and the
reset's seed and options) pickled into a shared buffer, and two semaphores say "go" and
"done". No pipe carries a step: a round trip costs the caller a few microseconds of
Python and one wake-up of each process.

The worker builds its env itself, from a picklable factory, in a process started by
``forkserver`` (nothing of the caller's GL contexts or threads is inherited). A step that
raises in the worker raises :class:`WorkerError` here with the worker's one line; a
worker that dies raises it too (never a hang: the wait checks the process). A worker
ends itself within :data:`CALLER_POLL_S` of the caller's death, even by SIGKILL.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import threading
import time
from collections.abc import Callable
from typing import Any, SupportsFloat

import gymnasium
import numpy as np
from gymnasium.vector.utils import (
    create_shared_memory,
    read_from_shared_memory,
)

from openral_eval.batch_slots import BatchSlots

EnvFn = Callable[[], gymnasium.Env[Any, Any]]
INFO_BYTES = 1 << 20
"""Room for one pickled info (or a reset's seed and options, or an error) [bytes]."""
CALLER_POLL_S = 1.0
"""How often a worker checks that the process that made it still lives [s]."""
POLL_S = 1.0
"""How often a wait for the worker checks that it still lives [s]."""
SPIN_S = 0.002
"""How long a wait polls before it sleeps [s]: a step's answer (or the next step) usually
comes within it, and a sleeping process takes tens of microseconds to wake."""
STEP, RESET, CLOSE = 1, 2, 3
FAILED, SAME_INFO = -1, 1
"""A worker's status besides 0: its env raised; its info is the one it sent last."""


class WorkerError(RuntimeError):
    """The worker's env raised, or the worker died (one line)."""


class _Shared:
    """What caller and worker share for one env."""

    def __init__(self, context: Any, spaces: tuple[gymnasium.Space[Any], gymnasium.Space[Any]]):
        observation_space, action_space = spaces
        self.spaces = spaces
        self.observation = create_shared_memory(observation_space, n=1, ctx=context)
        self.action = create_shared_memory(action_space, n=1, ctx=context)
        self.numbers = context.RawArray("d", 4)  # reward, terminated, truncated, status
        self.buffer = context.RawArray("B", INFO_BYTES)
        self.length: Any = context.RawValue("q", 0)
        self.command: Any = context.RawValue("i", 0)
        self.go = context.Semaphore(0)
        self.done = context.Semaphore(0)

    def put(self, value: object) -> None:
        data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
        if len(data) > INFO_BYTES:
            raise WorkerError(f"{len(data)} bytes to pass; at most {INFO_BYTES}")
        memoryview(self.buffer).cast("B")[: len(data)] = data
        self.length.value = len(data)

    def take(self) -> Any:
        return pickle.loads(self.taken())

    def taken(self) -> bytes:
        """The bytes :meth:`put` wrote last."""
        return bytes(memoryview(self.buffer).cast("B")[: self.length.value])


class _InfoSender:
    """A worker's infos to the caller: pickled, and not written again when they are the
    bytes sent last (the caller keeps those: most steps' infos are the last step's)."""

    def __init__(self, shared: _Shared) -> None:
        self.shared, self.last = shared, b""

    def send(self, info: object, numbers: np.ndarray) -> None:
        data = pickle.dumps(info, protocol=pickle.HIGHEST_PROTOCOL)
        if data == self.last:
            numbers[3] = SAME_INFO
            return
        self.shared.put(info)  # bytes too many raise before anything is written
        self.last = data

    def forget(self) -> None:
        """The buffer now holds something else (an error, a caller's reset arguments)."""
        self.last = b""


def _watch(caller: int) -> None:
    """End this worker once process ``caller`` is gone (killed, even by SIGKILL: its
    forkserver, this worker's parent, may outlive it)."""
    while True:
        time.sleep(CALLER_POLL_S)
        try:
            os.kill(caller, 0)
        except ProcessLookupError:
            os._exit(1)
        except PermissionError:
            pass  # alive, another user's: cannot be ours, but not gone either


def _serve(make: EnvFn, shared: _Shared, caller: int) -> None:
    """The worker: build the env, then run each command until CLOSE."""
    watch = threading.Thread(target=_watch, args=(caller,), name="openral-watch", daemon=True)
    watch.start()
    env = make()
    observation_space, action_space = shared.spaces
    actions = BatchSlots(read_from_shared_memory(action_space, shared.action, n=1))  # views
    observations = BatchSlots(read_from_shared_memory(observation_space, shared.observation, n=1))
    numbers, infos = np.frombuffer(shared.numbers, dtype=np.float64), _InfoSender(shared)
    while True:
        if not _polled(shared.go):
            shared.go.acquire()
        command = shared.command.value
        try:
            if command == CLOSE:
                env.close()
                shared.done.release()
                return
            if command == RESET:
                seed, options = shared.take()
                infos.forget()
                observation, info = env.reset(seed=seed, options=options)
                reward: SupportsFloat = 0.0
                terminated, truncated = False, False
            else:
                action = actions.row(0)
                observation, reward, terminated, truncated, info = env.step(action)
            observations.write(0, observation)
            numbers[:] = (float(reward), float(terminated), float(truncated), 0.0)
            infos.send(dict(info), numbers)
        except Exception as error:  # told to the caller in one line
            numbers[3] = FAILED
            infos.forget()
            shared.put(f"{type(error).__name__}: {error}")
        shared.done.release()


class ProcessEnv(gymnasium.Env[Any, Any]):
    """The env ``make`` builds, in a worker process (see the module doc)."""

    def __init__(
        self,
        make: EnvFn,
        spaces: tuple[gymnasium.Space[Any], gymnasium.Space[Any]],
        start_method: str = "forkserver",
    ) -> None:
        """``make``: a picklable factory; ``spaces``: its env's (observation, action)
        spaces, as the caller knows them (a probe env built once)."""
        context: Any = multiprocessing.get_context(start_method)
        self.observation_space, self.action_space = spaces
        self._shared = _Shared(context, spaces)
        self._observations = BatchSlots(
            read_from_shared_memory(self.observation_space, self._shared.observation, n=1)
        )
        self._actions = BatchSlots(
            read_from_shared_memory(self.action_space, self._shared.action, n=1)
        )
        self._numbers = np.frombuffer(self._shared.numbers, dtype=np.float64)
        """Reward, terminated, truncated and the worker's status (a view)."""
        self._info = b""
        """The worker's info as it sent it last (pickled)."""
        self._process = context.Process(
            target=_serve, args=(make, self._shared, os.getpid()), daemon=True
        )
        self._process.start()

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        self.post_reset(seed, options)
        observation, _, _, _, info = self.collect()
        return observation, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        self.post_step(action)
        return self.collect()

    def post_step(self, action: Any) -> None:
        """Start a step with ``action`` in the worker; :meth:`collect` its result."""
        self._actions.write(0, action)
        self._post(STEP)

    def post_reset(self, seed: int | None, options: dict[str, Any] | None) -> None:
        """Start a reset in the worker; :meth:`collect` its result (no reward, no end)."""
        self._shared.put((seed, options))
        self._post(RESET)

    def collect(self) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Wait for the command posted last; (observation, reward, terminated, truncated,
        info).

        Raises:
            WorkerError: The env raised, or its process died.
        """
        reward, terminated, truncated, info = self._collected()
        return self._observations.row(0), reward, terminated, truncated, info

    def collect_into(self, batch: BatchSlots, i: int) -> tuple[float, bool, bool, dict[str, Any]]:
        """:meth:`collect`, the observation copied straight into row ``i`` of ``batch``;
        (reward, terminated, truncated, info).

        Raises:
            WorkerError: As :meth:`collect`.
        """
        outcome = self._collected()
        batch.copy_row(self._observations, 0, i)
        return outcome

    def _collected(self) -> tuple[float, bool, bool, dict[str, Any]]:
        shared = self._shared
        self._wait()
        reward, terminated, truncated, status = self._numbers.tolist()
        if status == FAILED:
            raise WorkerError(f"the env in process {self._process.pid} raised {shared.take()}")
        if status != SAME_INFO:
            self._info = shared.taken()
        return reward, bool(terminated), bool(truncated), pickle.loads(self._info)

    def close(self) -> None:
        if self._process.is_alive():
            self._shared.command.value = CLOSE
            self._shared.go.release()
            self._wait()
        self._process.join(5.0)
        if self._process.is_alive():
            self._process.kill()

    def _post(self, command: int) -> None:
        self._shared.command.value = command
        self._shared.go.release()

    def _wait(self) -> None:
        if _polled(self._shared.done):
            return
        while not self._shared.done.acquire(timeout=POLL_S):
            if not self._process.is_alive():
                raise WorkerError(
                    f"the env's process {self._process.pid} died "
                    f"(exit code {self._process.exitcode})"
                )


def _polled(semaphore: Any) -> bool:
    """Take ``semaphore`` if it is released within :data:`SPIN_S` (polling)."""
    deadline = time.perf_counter() + SPIN_S
    while time.perf_counter() < deadline:
        if semaphore.acquire(False):
            return True
    return False
