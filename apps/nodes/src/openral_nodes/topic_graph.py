"""What the ROS graph holds: topic names, types and publishers, and their interface classes.

Graph queries read rmw's discovery cache, which DDS threads fill in the background, so
they need no executor; waiting is polling that cache every ``POLL_S`` seconds.

A topic's (or service's) type name comes from whichever peer advertises it, so it never
names a module to import: only the packages in ``DECODABLE_PACKAGES`` are decoded and only
those in ``SERVICE_PACKAGES`` are called.
"""

from __future__ import annotations

import importlib
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

from openral_core.errors import OpenralError, escaped
from rclpy.exceptions import InvalidTopicNameException
from rclpy.node import Node
from rclpy.validate_full_topic_name import validate_full_topic_name

HIDDEN_TOPICS = frozenset({"/rosout", "/parameter_events"})
"""Topics every node creates; listed only on request."""


def is_hidden(name: str) -> bool:
    """Whether a topic is listed only on request: one every node creates, or one with a
    token starting with ``_`` (an action's ``/_action/feedback`` and ``/_action/status``),
    which ``ros2 topic list`` hides too."""
    return name in HIDDEN_TOPICS or any(token.startswith("_") for token in name.split("/"))


T = TypeVar("T")

POLL_S = 0.05
"""Interval between discovery-cache reads while waiting (s)."""
DECODABLE_PACKAGES = (
    "action_msgs",
    "builtin_interfaces",
    "control_msgs",
    "controller_manager_msgs",
    "geometry_msgs",
    "lifecycle_msgs",
    "nav_msgs",
    "rcl_interfaces",
    "rosgraph_msgs",
    "sensor_msgs",
    "std_msgs",
    "tf2_msgs",
    "trajectory_msgs",
)
"""ROS message packages whose types are decoded (the ``ros`` extra, rclpy's own and the
interface packages built at setup: tf2_msgs, control_msgs, controller_manager_msgs), and
whose actions' feedback is (see :data:`ACTION_FEEDBACK`)."""
SERVICE_PACKAGES = (
    "lifecycle_msgs",
    "nav_msgs",
    "rcl_interfaces",
    "sensor_msgs",
    "std_srvs",
    "type_description_interfaces",
)
"""ROS packages whose service types ``openral ros call`` builds (installed with rclpy or
the ``ros`` extra)."""
MESSAGE_NAME = re.compile(r"[A-Z][A-Za-z0-9]*")
"""A ROS message or service name: CamelCase, letters and digits."""
ACTION_FEEDBACK = re.compile(r"([A-Z][A-Za-z0-9]*)_FeedbackMessage")
"""The message of an action's ``<name>/_action/feedback`` topic, ``pkg/action/<this>``:
the action's name and ``_FeedbackMessage``."""
_KINDS = {
    "msg": ("message", "decode", "decodable", DECODABLE_PACKAGES),
    "srv": ("service", "call", "callable", SERVICE_PACKAGES),
}
"""Per interface kind: its noun, what openral does with it (verb, adjective) and the
packages allowed."""


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
    """A topic or service type this process does not decode: not a message (service), not
    allowed or not installed."""


class TopicNameError(OpenralError):
    """A topic or service name that ROS would reject."""


def topic_name(name: str, *, service: bool = False) -> str:
    """Absolute form of a valid topic (or ``service``) name (``joint_states`` →
    ``/joint_states``).

    Raises:
        TopicNameError: ROS does not accept the name (e.g. ``/a[b]``, ``/1x``, ``/a//b``).
    """
    full = name if name.startswith("/") else f"/{name}"
    try:
        validate_full_topic_name(full)
    except InvalidTopicNameException as error:
        reason = str(error).splitlines()[0].removeprefix("Invalid topic name: ").rstrip(":")
        if service:
            reason = reason.replace("topic name", "service name", 1)
        what = "service" if service else "topic"
        raise TopicNameError(f"{escaped(name)} is not a valid ROS {what} name: {reason}") from None
    return full


def graph_topics(node: Node, *, include_hidden: bool = False) -> list[TopicInfo]:
    """Every topic the node currently sees, sorted by name."""
    return [
        TopicInfo(name, tuple(types), node.count_publishers(name))
        for name, types in sorted(node.get_topic_names_and_types())
        if include_hidden or not is_hidden(name)
    ]


SETTLED_S = 0.6
"""The graph counts as discovered once its topic list has not changed for this long [s]:
a participant's endpoints arrive one by one (a subscriber-only topic such as /cmd_vel can
come last)."""


def settled_topics(
    node: Node, *, wait_s: float, longest_s: float, include_hidden: bool = False
) -> tuple[list[TopicInfo], float]:
    """The topics after ``wait_s`` of discovery, once the list has stayed the same for
    :data:`SETTLED_S` (or ``longest_s`` in all, whatever it is then; empty: nothing came);
    and the seconds waited."""
    return settled(
        lambda: graph_topics(node, include_hidden=include_hidden),
        wait_s=wait_s,
        longest_s=longest_s,
        found=bool,
    )


def settled(
    read: Callable[[], T], *, wait_s: float, longest_s: float, found: Callable[[T], bool]
) -> tuple[T, float]:
    """What ``read`` returns after ``wait_s`` of discovery, once it has stayed the same for
    :data:`SETTLED_S` while ``found`` holds (or ``longest_s`` in all, whatever it is then);
    and the seconds waited."""
    start = time.monotonic()
    time.sleep(wait_s)
    seen = read()
    changed = time.monotonic()
    while True:
        now = time.monotonic()
        if (found(seen) and now - changed >= SETTLED_S) or now - start >= longest_s:
            return seen, now - start
        time.sleep(POLL_S)
        latest = read()
        if latest != seen:
            seen, changed = latest, time.monotonic()


def wait_for_topic(node: Node, topic: str, timeout_s: float) -> TopicInfo:
    """Block until ``topic`` (hidden ones too) has a publisher; raise TopicNotFound after
    ``timeout_s`` [s], naming the other topics (hidden ones only when ``topic`` is)."""
    topic = topic_name(topic)
    deadline = time.monotonic() + timeout_s
    while True:
        topics = graph_topics(node, include_hidden=True)
        for info in topics:
            if info.name == topic and info.publishers > 0:
                return info
        if time.monotonic() >= deadline:
            shown = [info for info in topics if is_hidden(topic) or not is_hidden(info.name)]
            existing = [info.name for info in shown]
            raise TopicNotFound(topic, timeout_s, existing, node.context.get_domain_id())
        time.sleep(POLL_S)


def message_class(type_name: str, topic: str) -> type[Any]:
    """The class of ``topic``'s type, e.g. ``sensor_msgs/msg/Image`` (or an action's
    feedback, ``control_msgs/action/FollowJointTrajectory_FeedbackMessage``), from an
    allowed package.

    ``type_name`` is whatever a peer advertised: the package must be one of
    ``DECODABLE_PACKAGES`` and the name a ROS message name before anything is imported.

    Raises:
        MessageTypeError: not ``pkg/msg/Name`` (or ``pkg/action/Name_FeedbackMessage``), a
            package outside the allow-list, or a name that package does not define.
    """
    return _interface_class(type_name, "msg", f"topic {topic}")


def service_class(type_name: str, service: str) -> type[Any]:
    """The class of ``service``'s type, e.g. ``std_srvs/srv/Trigger``, from one of
    ``SERVICE_PACKAGES`` (checked, like :func:`message_class`, before anything is imported).

    Raises:
        MessageTypeError: not ``pkg/srv/Name``, a package outside the allow-list, or a
            name that package does not define as a service.
    """
    return _interface_class(type_name, "srv", f"service {service}")


def _interface_class(type_name: str, kind: str, subject: str) -> type[Any]:
    noun, verb, adjective, packages = _KINDS[kind]
    shown = escaped(type_name)
    parts = type_name.split("/")
    feedback = kind == "msg" and len(parts) == 3 and parts[1] == "action"
    if len(parts) != 3 or not (parts[1] == kind or feedback):
        raise MessageTypeError(
            f"{subject} has type {shown}, which is not a {noun} type (expected pkg/{kind}/Name)"
        )
    package, folder, name = parts
    if package not in packages:
        raise MessageTypeError(
            f"{subject} has type {shown}, which openral does not {verb}; "
            f"{adjective} packages: {', '.join(packages)}"
        )
    action = ACTION_FEEDBACK.fullmatch(name) if feedback else None
    if not (action or (not feedback and MESSAGE_NAME.fullmatch(name))):
        raise MessageTypeError(f"{subject} has type {shown}: {name!r} is not a {noun} name")
    try:
        module = importlib.import_module(f"{package}.{folder}")
    except ImportError as error:
        raise MessageTypeError(
            f"{subject} has type {shown}, but {package} is not installed ({error}); "
            f"install the ros-{package.replace('_', '-')} wheel"
        ) from None
    if action:  # pkg.action.Name.Impl.FeedbackMessage
        impl = getattr(getattr(module, action.group(1), None), "Impl", None)
        cls = getattr(impl, "FeedbackMessage", None)
    else:
        cls = getattr(module, name, None)
    member = "get_fields_and_field_types" if kind == "msg" else "Request"
    if not isinstance(cls, type) or not hasattr(cls, member):
        raise MessageTypeError(f"{subject} has type {shown}, which {package} does not define")
    return cls
