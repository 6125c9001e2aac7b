"""rclpy plumbing shared by the openral nodes and commands: a context and a spinning executor.

Every openral process gets its own rclpy :class:`~rclpy.context.Context` (never the global
one) with no rclpy signal handlers, so Ctrl-C is ours to handle, and one
:class:`~rclpy.executors.SingleThreadedExecutor`: the idle-step hand-off between the sensor
bridge and ``/openral/safe_action`` relies on callbacks never running concurrently, and the
multi-threaded executor of rclpy 7.1 busy-loops on two cores.

Example::

    with ros_session(domain_id=7) as context, Spinner(context) as spinner:
        node = MyNode(context=context)
        spinner.add_node(node)
        spinner.call(node.trigger_configure)  # runs on the executor thread
"""

from __future__ import annotations

import fcntl
import math
import os
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import TracebackType
from typing import IO, Any, TypeVar

import rclpy
from openral_core.errors import OpenralError
from rclpy.context import Context
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental.events_executor import EventsExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

_InvalidHandle: type[Exception] = rclpy_implementation.InvalidHandle
"""rclpy's error for an entity used after it was destroyed (not exported elsewhere)."""

T = TypeVar("T")

REPORT_EVERY_S = 2.0
"""At most one line per this many seconds about callbacks that raise [s]."""
SPIN_PERIOD_S = 0.5
"""Longest wait of one ``spin_once`` [s]; bounds how late a stop request (Ctrl-C, a
signal) is noticed. Each timeout is an executor wake that rebuilds its wait set, so a
longer period costs an idle graph less CPU."""


DOMAIN_LOCK = "openral-ros-domain-{id}.lock"
"""Lock file (in the temp dir) that marks a ROS domain id as claimed by a live process."""
_claimed: dict[int, IO[str]] = {}


class RosRuntimeError(OpenralError):
    """The ROS runtime could not do what was asked (a call on a stopped spinner, a timeout)."""


def claim_domain_id(ids: range = range(1, 100)) -> int:
    """Claim a ROS domain id no other openral process holds, until this process exits.

    Each claim is an exclusive lock on a file in the temp dir (released by the OS when the
    process ends), so parallel test runs and benchmarks never share a graph. FastDDS ports
    stay valid for ids below 102.

    Raises:
        RosRuntimeError: Every id in ``ids`` is claimed.
    """
    start = os.getpid() % len(ids)
    for offset in range(len(ids)):
        domain = ids[(start + offset) % len(ids)]
        if domain in _claimed:
            continue
        handle = (Path(tempfile.gettempdir()) / DOMAIN_LOCK.format(id=domain)).open("w")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        _claimed[domain] = handle
        return domain
    raise RosRuntimeError(f"every ROS domain id in {ids} is claimed by another process")


@contextmanager
def ros_session(domain_id: int | None = None, args: list[str] | None = None) -> Iterator[Context]:
    """A fresh rclpy context, initialised without signal handlers and shut down on exit.

    Args:
        domain_id: ROS domain id; None keeps ``ROS_DOMAIN_ID`` (or 0).
        args: ROS command-line arguments (``--ros-args ...``); None for none.
    """
    context = Context()
    rclpy.init(
        args=args,
        context=context,
        domain_id=domain_id,
        signal_handler_options=SignalHandlerOptions.NO,
    )
    try:
        yield context
    finally:
        context.try_shutdown()


class Spinner:
    """A single-threaded executor spinning its nodes on a background thread.

    Stop it (or leave the ``with`` block) before destroying its nodes. Work that must not
    race the node's callbacks (lifecycle transitions, reading HAL state) goes through
    :meth:`call`, which runs it on the executor thread.
    """

    def __init__(self, context: Context, *, events: bool = False) -> None:
        """``events``: spin with rclpy's EventsExecutor (callbacks queued by the middleware
        instead of a wait set rebuilt every turn: far less CPU for many fast topics)."""
        self.context = context
        self.executor: Executor = (
            EventsExecutor(context=context) if events else SingleThreadedExecutor(context=context)
        )
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()

    def add_node(self, node: Node) -> None:
        """Spin ``node`` too (allowed while running)."""
        self.executor.add_node(node)

    def remove_node(self, node: Node) -> None:
        """Stop spinning ``node``; its callbacks no longer run after the current one."""
        self.executor.remove_node(node)

    @property
    def running(self) -> bool:
        """True while the spin thread is alive."""
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> Spinner:
        """Start the spin thread; returns self."""
        if self.running:
            return self
        self._stop.clear()
        self._thread = threading.Thread(target=self._spin, name="openral-spin", daemon=True)
        self._thread.start()
        return self

    def stop(self, timeout_s: float = 5.0) -> None:
        """Stop spinning, shut the executor down and join the thread (idempotent).

        Raises:
            RosRuntimeError: The spin thread did not end within ``timeout_s`` [s].
        """
        self._stop.set()
        self.executor.wake()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join(timeout_s)
            if thread.is_alive():
                raise RosRuntimeError(f"the spin thread did not stop within {timeout_s} s")
        self.executor.shutdown(timeout_sec=timeout_s)

    def call(self, function: Callable[..., T], *args: Any, timeout_s: float = 30.0) -> T:
        """Run ``function(*args)`` on the executor thread and return its result.

        Runs it directly when the spinner is not running (nothing can race it then). After
        a timeout the queued call may still run later.

        Raises:
            RosRuntimeError: No result within ``timeout_s`` [s].
            Exception: Whatever ``function`` raised.
        """
        if not self.running or threading.current_thread() is self._thread:
            return function(*args)
        done = threading.Event()
        outcome: list[Any] = []

        def run() -> None:
            try:
                outcome.append((True, function(*args)))
            except Exception as error:  # handed to the caller below
                outcome.append((False, error))
            finally:
                done.set()

        self.executor.create_task(run)
        if not done.wait(timeout_s):
            name = getattr(function, "__name__", repr(function))
            raise RosRuntimeError(f"{name} did not finish within {timeout_s} s on the spin thread")
        ok, value = outcome[0]
        if not ok:
            raise value
        result: T = value
        return result

    def __enter__(self) -> Spinner:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.stop()

    def _spin(self) -> None:
        spin_until(self.executor, self._stop)


def spin_until(
    executor: Executor,
    stop: threading.Event,
    *,
    timeout_s: float | None = None,
) -> bool:
    """Spin ``executor`` on the calling thread until ``stop`` is set or ``timeout_s`` passes.

    A callback that raises does not end the spinning (rclpy re-raises it from
    ``spin_once``): it is reported in one line on stderr, at most once per
    :data:`REPORT_EVERY_S`, and the executor goes on serving everything else. An entity
    destroyed by another thread while this one waited on it (rclpy's ``InvalidHandle``: a
    probe's subscriptions ending after their window, say) is no failure and is not reported.

    Returns:
        True when ``stop`` was set, False when the timeout elapsed or the context ended.
    """
    deadline = None if timeout_s is None else time.monotonic() + timeout_s
    reported = -math.inf
    while not stop.is_set() and executor.context.ok():
        left = SPIN_PERIOD_S if deadline is None else deadline - time.monotonic()
        if left <= 0:
            return False
        try:
            executor.spin_once(timeout_sec=min(SPIN_PERIOD_S, left))
        except ExternalShutdownException:  # the context was shut down under us
            return False
        except _InvalidHandle:  # destroyed by another thread while we waited on it
            continue
        except Exception as error:  # a callback's bug: said, never the end of the executor
            if time.monotonic() - reported >= REPORT_EVERY_S:
                reported = time.monotonic()
                sys.stderr.write(
                    f"openral: a ROS callback failed ({type(error).__name__}: {error}); "
                    "the executor goes on\n"
                )
    return stop.is_set()
