"""Helpers of the deploy-sim tests: an isolated domain, a probe, event-driven waits.

Each test process claims its own ROS domain id (``claim_domain_id``: a lock file held for
the process's lifetime) and keeps discovery on loopback, so parallel runs and other
graphs on this machine never see each other. Waits are event driven: a condition variable
fed by subscription callbacks, with generous timeouts for a loaded two-core machine.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import pytest
from openral_bridge.ros_messages import LATCHED
from openral_bridge.topics import ACTION_SPEC, ROBOT_DESCRIPTION
from openral_core.models import RobotDescription
from openral_nodes.manifest_node import ManifestLifecycleNode
from openral_nodes.runtime import Spinner, claim_domain_id
from rclpy.context import Context
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image, JointState
from std_srvs.srv import Trigger

from tests.conftest import REPO

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
DOMAIN_ID = claim_domain_id()
os.environ["ROS_DOMAIN_ID"] = str(DOMAIN_ID)

FRANKA_SCENE = REPO / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
CAMERAS = ("agentview", "wrist")
WAIT_S = 15.0
"""Longest wait for anything that should happen within a second or two on an idle machine."""


def wait_until(predicate: Callable[[], bool], timeout_s: float = WAIT_S, what: str = "") -> None:
    """Poll ``predicate`` (cheap, side-effect free) every 10 ms until true or fail."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s} s waiting for {what or predicate}")
        time.sleep(0.01)


def call_trigger(client: Any, name: str) -> Any:
    """Call the ``std_srvs/Trigger`` service ``name`` through ``client`` and return the
    response (fails the test when it is not offered or does not answer)."""
    assert client.wait_for_service(timeout_sec=10.0), f"{name} is not offered"
    future = client.call_async(Trigger.Request())
    wait_until(future.done, 15.0, f"the answer of {name}")
    return future.result()


@dataclass(frozen=True)
class Received:
    """One message and its arrival time (``time.monotonic()``)."""

    at: float
    msg: Any


class Probe:
    """A test node that records every message of some topics and lets tests wait on them."""

    def __init__(self, context: Context, topics: dict[str, Any], name: str = "test_probe"):
        self.node = Node(name, context=context)
        self.messages: dict[str, list[Received]] = {topic: [] for topic in topics}
        self._condition = threading.Condition()
        for topic, kind in topics.items():
            qos = LATCHED if topic in (ACTION_SPEC, ROBOT_DESCRIPTION) else 50
            self.node.create_subscription(kind, topic, partial(self._record, topic), qos)

    def _record(self, topic: str, msg: Any) -> None:
        with self._condition:
            self.messages[topic].append(Received(time.monotonic(), msg))
            self._condition.notify_all()

    def wait(
        self, predicate: Callable[[], bool], timeout_s: float = WAIT_S, what: str = ""
    ) -> None:
        """Block until ``predicate`` (evaluated under the lock after every message) holds."""
        with self._condition:
            if not self._condition.wait_for(predicate, timeout_s):
                counts = {t: len(m) for t, m in self.messages.items()}
                pytest.fail(f"timed out after {timeout_s} s waiting for {what}; got {counts}")

    def since(self, topic: str, start: float) -> list[Received]:
        """Messages of ``topic`` that arrived at or after ``start``."""
        with self._condition:
            return [r for r in self.messages[topic] if r.at >= start]

    def wait_count(
        self, topic: str, count: int, start: float = 0.0, timeout_s: float = WAIT_S
    ) -> list[Received]:
        """Wait for ``count`` messages of ``topic`` arriving at or after ``start``."""
        self.wait(
            lambda: sum(r.at >= start for r in self.messages[topic]) >= count,
            timeout_s,
            f"{count} message(s) on {topic}",
        )
        return self.since(topic, start)[:count] if count else []

    def latest(self, topic: str) -> Any:
        with self._condition:
            return self.messages[topic][-1].msg


def image_topic(camera: str) -> str:
    return f"/openral/cameras/{camera}/image"


def info_topic(camera: str) -> str:
    return f"/openral/cameras/{camera}/camera_info"


PROBE_TOPICS: dict[str, Any] = {
    "/joint_states": JointState,
    "/openral/manifest_joint_states": JointState,
    "/clock": Clock,
    ACTION_SPEC: JointState,
    **{image_topic(c): Image for c in CAMERAS},
    **{info_topic(c): CameraInfo for c in CAMERAS},
}


@dataclass
class Deployed:
    """The franka default scene running as a live node, plus a probe and the spinner."""

    node: ManifestLifecycleNode
    probe: Probe
    spinner: Spinner
    description: RobotDescription
    activated_at: float

    def node_stats(self) -> dict[str, int]:
        """Counters of the node, read on the spin thread (no race with its callbacks)."""

        def read() -> dict[str, int]:
            loop = self.node.loop
            return {
                "accepted": self.node.actions_accepted,
                "refused": self.node.actions_refused,
                "applied": loop.applied if loop else -1,
                "superseded": loop.superseded if loop else -1,
                "ticks": loop.ticks if loop else -1,
            }

        return self.spinner.call(read)
