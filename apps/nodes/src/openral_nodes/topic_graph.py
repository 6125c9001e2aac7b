"""What the ROS graph holds: topic names, types and publishers, and their message classes.

Graph queries read rmw's discovery cache, which DDS threads fill in the background, so
they need no executor; waiting is polling that cache every ``POLL_S`` seconds.

A topic's type name comes from whichever peer advertises it, so it never names a module
to import: only the packages in ``DECODABLE_PACKAGES`` are decoded.
"""

from __future__ import annotations

import importlib
import re
import time
from dataclasses import dataclass
from typing import Any

from openral_core.errors import OpenralError, escaped
from rclpy.exceptions import InvalidTopicNameException
from rclpy.node import Node
from rclpy.validate_full_topic_name import validate_full_topic_name

HIDDEN_TOPICS = frozenset({"/rosout", "/parameter_events"})
"""Topics every node creates; listed only on request."""
POLL_S = 0.05
"""Interval between discovery-cache reads while waiting (s)."""
DECODABLE_PACKAGES = (
    "builtin_interfaces",
    "geometry_msgs",
    "lifecycle_msgs",
    "nav_msgs",
    "rcl_interfaces",
    "rosgraph_msgs",
    "sensor_msgs",
    "std_msgs",
    "trajectory_msgs",
)
"""ROS message packages whose types are decoded (the ``ros`` extra and rclpy's own)."""
MESSAGE_NAME = re.compile(r"[A-Z][A-Za-z0-9]*")
"""A ROS message name: CamelCase, letters and digits."""


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
    """A topic type this process does not decode: not a message, not allowed or not installed."""


class TopicNameError(OpenralError):
    """A topic name that ROS would reject."""


def topic_name(name: str) -> str:
    """Absolute form of a valid topic name (``joint_states`` → ``/joint_states``).

    Raises:
        TopicNameError: ROS does not accept the name (e.g. ``/a[b]``, ``/1x``, ``/a//b``).
    """
    full = name if name.startswith("/") else f"/{name}"
    try:
        validate_full_topic_name(full)
    except InvalidTopicNameException as error:
        reason = str(error).splitlines()[0].removeprefix("Invalid topic name: ").rstrip(":")
        raise TopicNameError(f"{escaped(name)} is not a valid ROS topic name: {reason}") from None
    return full


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


def message_class(type_name: str, topic: str) -> type[Any]:
    """The class of ``topic``'s type, e.g. ``sensor_msgs/msg/Image``, from an allowed package.

    ``type_name`` is whatever a peer advertised: the package must be one of
    ``DECODABLE_PACKAGES`` and the name a ROS message name before anything is imported.

    Raises:
        MessageTypeError: not ``pkg/msg/Name``, a package outside the allow-list, or a
            name that package does not define as a message.
    """
    shown = escaped(type_name)
    parts = type_name.split("/")
    if len(parts) != 3 or parts[1] != "msg":
        raise MessageTypeError(
            f"topic {topic} has type {shown}, which is not a message type (expected pkg/msg/Name)"
        )
    package, _, name = parts
    if package not in DECODABLE_PACKAGES:
        raise MessageTypeError(
            f"topic {topic} has type {shown}, which openral does not decode; "
            f"decodable packages: {', '.join(DECODABLE_PACKAGES)}"
        )
    if not MESSAGE_NAME.fullmatch(name):
        raise MessageTypeError(f"topic {topic} has type {shown}: {name!r} is not a message name")
    try:
        module = importlib.import_module(f"{package}.msg")
    except ImportError as error:
        raise MessageTypeError(
            f"topic {topic} has type {shown}, but {package} is not installed ({error}); "
            f"install the ros-{package.replace('_', '-')} wheel"
        ) from None
    cls = getattr(module, name, None)
    if not isinstance(cls, type) or not hasattr(cls, "get_fields_and_field_types"):
        raise MessageTypeError(f"topic {topic} has type {shown}, which {package} does not define")
    return cls
