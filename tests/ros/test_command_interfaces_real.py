"""The command interfaces of a node whose HAL is real hardware without a loop of its own,
driven over ROS.

Such a HAL has no control loop: an action goes to it at once, a joint trajectory is refused
with the reason, and ``/openral/reset`` answers ``success: false`` because software cannot
put a real robot back. (A real HAL with its own loop, the Feetech arms', follows
trajectories: tests/real/test_deploy_real.py.)
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from openral_bridge.topics import JOINT_TRAJECTORY, RESET, SAFE_ACTION
from openral_core import open_robot_by_id
from openral_hal.factory import RealOptions
from openral_nodes.command_interfaces import CommandInterfaces
from openral_nodes.runtime import Spinner
from openral_nodes.service_call import call_trigger
from openral_nodes.trajectory_request import trajectory_msg
from rclpy.context import Context
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory

from tests.ros.ros_helpers import wait_until
from tests.sim_attach.test_build_hal import RealArm


@pytest.fixture
def real(ros_context: Context) -> Iterator[tuple[CommandInterfaces, RealArm, Node]]:
    hal = RealArm(open_robot_by_id("franka_panda"), None, RealOptions())
    hal.connect()
    node = Node("real_commands", context=ros_context)
    client = Node("real_client", context=ros_context)
    commands = CommandInterfaces(node, hal, threading.Lock(), None, warn_every_s=0.0)
    commands.create()
    with Spinner(ros_context) as spinner:
        spinner.add_node(node)
        spinner.add_node(client)
        yield commands, hal, client
    node.destroy_node()  # type: ignore[no-untyped-call]
    client.destroy_node()  # type: ignore[no-untyped-call]


def _publish(client: Node, kind: Any, topic: str, msg: Any) -> None:
    publisher = client.create_publisher(kind, topic, 10)
    wait_until(lambda: publisher.get_subscription_count() > 0, 10.0, f"a subscriber of {topic}")
    publisher.publish(msg)


def test_an_action_goes_to_the_real_hal_at_once(
    real: tuple[CommandInterfaces, RealArm, Node],
) -> None:
    commands, hal, client = real
    action = np.linspace(0.1, 0.8, len(hal.action_names))
    _publish(client, Float64MultiArray, SAFE_ACTION, Float64MultiArray(data=action.tolist()))
    wait_until(lambda: commands.accepted == 1, 10.0, "the action")
    assert np.array_equal(hal.hold_action(), action)


def test_a_trajectory_is_refused_and_reset_answers_false(
    real: tuple[CommandInterfaces, RealArm, Node],
) -> None:
    commands, hal, client = real
    msg = trajectory_msg(["panda_joint1"], [1.0], [[0.1]])
    _publish(client, JointTrajectory, JOINT_TRAJECTORY, msg)
    wait_until(lambda: commands.trajectories_refused == 1, 10.0, "the refusal")
    assert np.array_equal(hal.hold_action(), np.zeros(len(hal.action_names)))
    answer = call_trigger(client, RESET, 10.0)
    assert not answer.success and answer.message.startswith("a real robot cannot be reset")
    assert not commands.follows_trajectories
