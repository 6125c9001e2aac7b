"""Real-rclpy fixtures for the rskill runner and ``openral ros`` tests.

Every test process claims its own ROS domain (``claim_domain_id``: a lock file held until
the process exits, shared with the deploy-sim tests) and keeps discovery on loopback, so
parallel test runs and other graphs on this machine never see each other. ``FakeGraph``
plays the part of ``openral deploy sim``: franka camera frames of distinct solid colours,
joint states and a latched action spec; it records what arrives on ``/openral/safe_action``.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from openral_bridge.ros_messages import LATCHED, image_msg, joint_state_msg, stamp
from openral_bridge.topics import ACTION_SPEC
from openral_cli import main
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.context import Context
from rclpy.node import Node
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import Float64MultiArray

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
DOMAIN_ID = claim_domain_id()

FRANKA_JOINTS = [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
HOLD = np.array([0.0, -0.4, 0.0, -2.2, 0.0, 1.9, 0.8, 0.04])
"""The action spec's hold action: one value per franka action slot."""
JOINT_POSITIONS = np.linspace(0.1, 0.8, len(FRANKA_JOINTS))
COLOURS = {"agentview": (200, 40, 10), "wrist": (10, 60, 220)}
"""Solid RGB colour of each fake camera, so a frame shows which sensor it came from."""
FRAME_SHAPE = (48, 64)
CAMERA_HZ = 10.0


def wait_until(condition: Callable[[], bool], timeout_s: float = 10.0) -> bool:
    """Poll ``condition`` every 20 ms until true or ``timeout_s`` passes."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


class FakeGraph(Node):
    """What ``openral deploy sim`` publishes for franka, minus the simulation."""

    def __init__(self, context: Context, cameras: tuple[str, ...], action_spec: bool) -> None:
        super().__init__("fake_deploy_sim", context=context)
        self.actions: list[np.ndarray] = []
        self._lock = threading.Lock()
        self._cameras = {
            name: self.create_publisher(Image, f"/openral/cameras/{name}/image", 5)
            for name in cameras
        }
        spec = JointState(name=FRANKA_JOINTS, position=HOLD.tolist())
        self._spec_pub = self.create_publisher(JointState, ACTION_SPEC, LATCHED)
        if action_spec:
            self._spec_pub.publish(spec)
        self._joints = self.create_publisher(JointState, "/joint_states", 10)
        self.create_subscription(Float64MultiArray, "/openral/safe_action", self._on_action, 10)
        self.create_timer(1.0 / CAMERA_HZ, self._publish)

    def _publish(self) -> None:
        now = stamp(time.monotonic())
        for name, publisher in self._cameras.items():
            frame = np.empty((*FRAME_SHAPE, 3), np.uint8)
            frame[:] = COLOURS[name]
            publisher.publish(image_msg(frame, now, name))
        zeros = np.zeros(len(FRANKA_JOINTS))
        self._joints.publish(joint_state_msg(FRANKA_JOINTS, JOINT_POSITIONS, zeros, zeros, now))

    def _on_action(self, msg: Any) -> None:
        with self._lock:
            self.actions.append(np.array(msg.data))

    def received(self) -> list[np.ndarray]:
        """Actions received so far."""
        with self._lock:
            return list(self.actions)


class RosHarness:
    """One rclpy context spun on a background thread; nodes added to it spin too."""

    def __init__(self, context: Context, spinner: Spinner) -> None:
        self.context = context
        self.spinner = spinner
        self.nodes: list[Node] = []

    def add(self, node: Node) -> Node:
        self.nodes.append(node)
        self.spinner.add_node(node)
        return node

    def fake_graph(
        self, cameras: tuple[str, ...] = ("agentview", "wrist"), action_spec: bool = True
    ) -> FakeGraph:
        graph = FakeGraph(self.context, cameras, action_spec)
        self.add(graph)
        return graph


@pytest.fixture
def ros() -> Iterator[RosHarness]:
    """A spun rclpy context on this process's domain; nodes are destroyed afterwards."""
    with ros_session(DOMAIN_ID) as context:
        spinner = Spinner(context)
        harness = RosHarness(context, spinner.start())
        try:
            yield harness
        finally:
            spinner.stop()
            for node in harness.nodes:
                node.destroy_node()


def run_cli(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str
) -> tuple[int, str, str]:
    """``openral ARGS`` through the entry point on this process's ROS domain: exit code,
    stdout, stderr."""
    monkeypatch.setenv("ROS_DOMAIN_ID", str(DOMAIN_ID))
    monkeypatch.setenv("COLUMNS", "300")
    monkeypatch.setattr(sys, "argv", ["openral", *args])
    with pytest.raises(SystemExit) as exit_:
        main.run()
    captured = capsys.readouterr()
    assert isinstance(exit_.value.code, int)
    return exit_.value.code, captured.out, captured.err
