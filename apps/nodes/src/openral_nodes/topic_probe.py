"""Receive messages of any type present in the graph: the core of ``openral ros echo``.

The node must be spun by someone else (a :class:`~openral_nodes.runtime.Spinner`); the
callbacks here only hand messages to the calling thread through a bounded queue. QoS is
"best available": reliability and durability match what the discovered publishers offer,
so a latched (transient-local) topic such as ``/openral/action_spec`` is delivered too.
"""

from __future__ import annotations

import queue
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager, suppress
from typing import Any

from openral_core.errors import OpenralError
from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_best_available, qos_profile_sensor_data

from openral_nodes.topic_graph import TopicInfo, message_class

QUEUE_DEPTH = 10
"""Messages buffered for the reader; newer ones are dropped when it falls behind."""
RATE_QOS: QoSProfile = qos_profile_sensor_data
"""Rate measurement: best effort (matches any publisher) and volatile (a latched
message already published is not replayed and counted)."""


class NoMessage(OpenralError):
    """A topic exists but delivered nothing in time."""

    def __init__(self, info: TopicInfo, timeout_s: float) -> None:
        super().__init__(
            f"no message on {info.name} ({', '.join(info.types)}, {info.publishers} "
            f"publisher(s)) within {timeout_s:g} s"
        )


class Inbox:
    """Messages of one topic, in arrival order, for a thread that is not the spinner's."""

    def __init__(self, info: TopicInfo) -> None:
        self.info = info
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=QUEUE_DEPTH)

    def put(self, msg: Any) -> None:
        """Subscription callback: enqueue, dropping ``msg`` when the reader is behind."""
        with suppress(queue.Full):
            self._queue.put_nowait(msg)

    def get(self, timeout_s: float) -> Any:
        """The next message; raise NoMessage after ``timeout_s`` [s]."""
        try:
            return self._queue.get(timeout=max(timeout_s, 0.0))
        except queue.Empty:
            raise NoMessage(self.info, timeout_s) from None


@contextmanager
def subscribe(node: Node, info: TopicInfo) -> Iterator[Inbox]:
    """Subscribe ``node`` to ``info`` (first advertised type) for the ``with`` block."""
    inbox = Inbox(info)
    subscription = node.create_subscription(
        message_class(info.types[0], info.name), info.name, inbox.put, qos_profile_best_available
    )
    try:
        yield inbox
    finally:
        node.destroy_subscription(subscription)


def measure_rates(
    node: Node, topics: Sequence[TopicInfo], window_s: float
) -> dict[str, float | None]:
    """Receive rate [Hz] of each topic over ``window_s``.

    None when fewer than two messages arrived or the type is not importable here.
    """
    arrivals: dict[str, list[float]] = {info.name: [] for info in topics}
    subscriptions = []
    for info in topics:
        try:
            cls = message_class(info.types[0], info.name)
        except OpenralError:
            continue
        callback = _stamper(arrivals[info.name])
        subscriptions.append(node.create_subscription(cls, info.name, callback, RATE_QOS))
    try:
        time.sleep(window_s)
    finally:
        for subscription in subscriptions:
            node.destroy_subscription(subscription)
    return {name: _rate(stamps) for name, stamps in arrivals.items()}


def _stamper(stamps: list[float]) -> Callable[[Any], None]:
    def stamp(_msg: Any) -> None:
        stamps.append(time.monotonic())

    return stamp


def _rate(stamps: list[float]) -> float | None:
    if len(stamps) < 2 or stamps[-1] <= stamps[0]:
        return None
    return (len(stamps) - 1) / (stamps[-1] - stamps[0])
