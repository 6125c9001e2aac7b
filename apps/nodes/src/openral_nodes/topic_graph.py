"""What the ROS graph holds: topic names, types and publishers, and their message classes.

Graph queries read rmw's discovery cache, which DDS threads fill in the background, so
they need no executor; waiting is polling that cache every ``POLL_S`` seconds.
"""

from __future__ import annotations

import importlib
import time
from dataclasses import dataclass
from typing import Any

from openral_core.errors import OpenralError
from rclpy.node import Node

HIDDEN_TOPICS = frozenset({"/rosout", "/parameter_events"})
"""Topics every node creates; listed only on request."""
POLL_S = 0.05
"""Interval between discovery-cache reads while waiting (s)."""


@dataclass(frozen=True)
class TopicInfo:
    """One topic as the graph reports it."""

    name: str
    types: tuple[str, ...]
    publishers: int


class TopicNotFound(OpenralError):
    """A topic did not appear in the graph in time; lists the topics that did."""

    def __init__(self, topic: str, timeout_s: float, existing: list[str], domain_id: int) -> None:
        self.topic = topic
        self.existing = tuple(existing)
        seen = ", ".join(existing) if existing else "(none)"
        super().__init__(
            f"topic {topic} did not appear within {timeout_s:g} s on ROS_DOMAIN_ID={domain_id}; "
            f"topics in the graph: {seen}. Is `openral deploy sim` running on this domain?"
        )


class MessageTypeError(OpenralError):
    """A message type name that cannot be imported in this environment."""


def topic_name(name: str) -> str:
    """Absolute form of a topic name (``joint_states`` → ``/joint_states``)."""
    return name if name.startswith("/") else f"/{name}"


def graph_topics(node: Node, *, include_hidden: bool = False) -> list[TopicInfo]:
    """Every topic the node currently sees, sorted by name."""
    return [
        TopicInfo(name, tuple(types), node.count_publishers(name))
        for name, types in sorted(node.get_topic_names_and_types())
        if include_hidden or name not in HIDDEN_TOPICS
    ]


def wait_for_topic(node: Node, topic: str, timeout_s: float) -> TopicInfo:
    """Block until ``topic`` has a publisher; raise TopicNotFound after ``timeout_s`` [s]."""
    topic = topic_name(topic)
    deadline = time.monotonic() + timeout_s
    while True:
        topics = graph_topics(node)
        for info in topics:
            if info.name == topic and info.publishers > 0:
                return info
        if time.monotonic() >= deadline:
            existing = [info.name for info in topics]
            raise TopicNotFound(topic, timeout_s, existing, node.context.get_domain_id())
        time.sleep(POLL_S)


def message_class(type_name: str) -> type[Any]:
    """The Python class of a ROS message type such as ``sensor_msgs/msg/Image``."""
    parts = type_name.split("/")
    if len(parts) != 3 or parts[1] != "msg" or not parts[0] or not parts[2]:
        raise MessageTypeError(f"{type_name!r} is not a message type (expected pkg/msg/Name)")
    package, _, name = parts
    try:
        cls: type[Any] = getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError) as error:
        raise MessageTypeError(
            f"message type {type_name} is not installed in this Python environment ({error}); "
            f"install the ros-{package.replace('_', '-')} wheel"
        ) from error
    return cls
