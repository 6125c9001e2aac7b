"""Tests for base_bridge.py: /cmd_vel drives the mobile Panda's base in its room scene and
/odom reports it, over real rclpy topics; refusals while E-stopped or for a non-finite
command change nothing. The HAL is ticked by the test (20 Hz of simulated time per tick)."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from openral_bridge.base_bridge import BaseBridge
from openral_bridge.pacer import Pacer
from openral_core import open_robot_by_id
from openral_core.loader import load_scene
from openral_hal.factory import HalMode, build_hal
from openral_hal.protocol import MobileBaseHal
from openral_hal.sim_attached import SimAttachedHAL
from openral_nodes.runtime import Spinner
from rclpy.context import Context
from rclpy.node import Node

from tests.conftest import ROBOTS
from tests.ros.ros_helpers import wait_until

ROOM = ROBOTS / "panda_mobile" / "scenes" / "room.yaml"


@pytest.fixture
def hal() -> Iterator[SimAttachedHAL]:
    hal = build_hal(open_robot_by_id("panda_mobile"), mode=HalMode.SIM, scene=load_scene(ROOM))
    assert isinstance(hal, SimAttachedHAL)
    hal.connect()
    yield hal
    hal.disconnect()


class Rig:
    """The bridge on a node, a client node that sends Twists and keeps every Odometry."""

    def __init__(self, context: Context, hal: SimAttachedHAL, spinner: Spinner) -> None:
        self.hal, self.spinner, self.lock = hal, spinner, threading.Lock()
        self.node = Node("base_bridge_test", context=context)
        self.client = Node("base_bridge_client", context=context)
        self.odometry: list[Any] = []
        self.client.create_subscription(Odometry, "/odom", self.odometry.append, 50)
        self.twist = self.client.create_publisher(Twist, "/cmd_vel", 10)
        assert isinstance(hal, MobileBaseHal) and hal.base is not None
        self.bridge = BaseBridge(self.node, hal, 50.0, self.lock)
        self.pacer = Pacer()
        spinner.add_node(self.node)
        spinner.add_node(self.client)
        spinner.call(self.bridge.start, self.pacer)
        self.pacer.start()
        wait_until(lambda: self.twist.get_subscription_count() > 0, what="/cmd_vel matched")

    def send(self, vx: float, wz: float = 0.0, *, counted: str = "accepted") -> None:
        """Publish one Twist and wait until the bridge has taken or refused it."""
        before = getattr(self.bridge, counted)
        msg = Twist()
        msg.linear.x, msg.angular.z = vx, wz
        self.twist.publish(msg)
        wait_until(lambda: getattr(self.bridge, counted) > before, what=f"/cmd_vel {counted}")

    def tick(self, count: int) -> None:
        for _ in range(count):
            with self.lock:
                self.hal.tick(None)

    def close(self) -> None:
        assert self.pacer.stop()
        self.spinner.call(self.bridge.stop)
        self.node.destroy_node()  # type: ignore[no-untyped-call]
        self.client.destroy_node()  # type: ignore[no-untyped-call]


@pytest.fixture
def rig(ros_context: Context, hal: SimAttachedHAL) -> Iterator[Rig]:
    with Spinner(ros_context) as spinner:
        rig = Rig(ros_context, hal, spinner)
        yield rig
        rig.close()


def test_cmd_vel_0_3_m_s_for_2_s_moves_the_base_0_6_m_in_odom(rig: Rig) -> None:
    for _ in range(40):  # 2.0 s of simulated time, a command every control period
        rig.send(0.3)
        rig.tick(1)
    rig.send(0.0)  # stop, as a teleop does when its key is released
    rig.tick(20)
    rig.odometry.clear()
    wait_until(lambda: bool(rig.odometry), what="/odom after the drive")
    odom = rig.odometry[-1]
    assert odom.header.frame_id == "odom" and odom.child_frame_id == "base_link"
    for covariance in (odom.pose.covariance, odom.twist.covariance):  # the planar drive's
        matrix = np.reshape(covariance, (6, 6))
        assert np.all(np.diag(matrix) > 0) and not np.any(matrix - np.diag(np.diag(matrix)))
        planar, fixed = np.diag(matrix)[[0, 1, 5]], np.diag(matrix)[[2, 3, 4]]
        assert planar.min() > fixed.max()  # x, y, yaw move; z, roll, pitch cannot
    assert odom.pose.pose.position.x == pytest.approx(0.6, abs=0.05)
    assert abs(odom.pose.pose.position.y) < 0.01
    assert abs(odom.twist.twist.linear.x) < 0.01  # stopped
    assert odom.header.stamp.sec + odom.header.stamp.nanosec * 1e-9 == pytest.approx(
        rig.hal.read_state().sim_time_s, abs=1e-6
    )


def test_an_estop_stops_the_base_and_refuses_cmd_vel(rig: Rig) -> None:
    rig.send(0.3)
    rig.tick(10)
    assert rig.hal.base_odometry().vx_m_s > 0.2
    with rig.lock:
        rig.hal.estop()
    rig.send(0.3, counted="refused")
    rig.tick(4)  # frozen: the E-stopped scene does not advance
    assert rig.hal.base_odometry().vx_m_s == pytest.approx(0.0, abs=1e-9) or rig.hal.estopped
    assert rig.hal.base is not None and rig.hal.base.command_in_force == (0.0, 0.0, 0.0)


def test_a_non_finite_command_is_refused_and_changes_nothing(rig: Rig) -> None:
    rig.send(0.2)
    assert rig.hal.base is not None
    before = rig.hal.base.command_in_force
    rig.send(float("nan"), counted="refused")
    assert rig.hal.base.command_in_force == before
    assert rig.bridge.refused == 1 and rig.bridge.accepted == 1
