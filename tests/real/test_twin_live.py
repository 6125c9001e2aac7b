"""``deploy real --twin SCENE`` on the Panda, with deploy sim standing in for its ros2_control
driver (namespace /robot): a FollowJointTrajectory goal into the table is refused naming
the pair and the robot does not move; the twin's camera shows what the robot's own
simulation shows at the same joints."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from control_msgs.action import FollowJointTrajectory
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import String
from std_srvs.srv import Trigger

from tests.conftest import ROBOTS
from tests.real.deploy_helpers import openral, remote_graph, stop
from tests.real.stand_in import RELEASE, ROBOT_STATES, arm_joints
from tests.ros.action_client import PANDA_ARM, _AtomicActionClient, goal
from tests.ros.lifecycle_client import deploy_sim
from tests.ros.ros_helpers import call_trigger, wait_until

pytestmark = pytest.mark.exclusive  # two live graphs on a real-time link

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
FOLLOW = "/real/joint_trajectory_controller/follow_joint_trajectory"
REFUSED = "/real/openral/joint_trajectory/refused"
TWIN_CAMERA = "/real/openral/cameras/agentview/image"
ROBOT_CAMERA = "/robot/openral/cameras/agentview/image"
SAME_PICTURE = 3.0
"""Largest mean difference [of 255] between the twin's frame and the robot's own."""


def _pixels(message: Image) -> np.ndarray:
    return np.frombuffer(bytes(message.data), dtype=np.uint8).reshape(
        message.height, message.width, -1
    )


def test_a_goal_into_the_table_is_refused_and_the_twin_shows_the_measured_pose(
    tmp_path: Path,
) -> None:
    topics = {
        ROBOT_STATES: JointState,
        REFUSED: String,
        TWIN_CAMERA: Image,
        ROBOT_CAMERA: Image,
    }
    with remote_graph(topics) as remote:
        follow = _AtomicActionClient(remote.probe.node, FollowJointTrajectory, FOLLOW)
        with deploy_sim(SCENE, remote.domain, tmp_path, ("--namespace", "robot"), robot=True):
            remote.probe.wait_count(ROBOT_STATES, 1, timeout_s=90.0)
            real = openral(
                "deploy", "real", "--robot", "franka_panda", "--transport",
                "ros2_control:robot", "--twin", str(SCENE), "--namespace", "real",
                "--domain-id", str(remote.domain),
            )  # fmt: skip
            try:
                remote.probe.wait_count(TWIN_CAMERA, 1, timeout_s=90.0)
                time.sleep(2.0)  # the cameras' renderers were made before the loop started
                release = remote.probe.node.create_client(Trigger, RELEASE)
                call_trigger(release, RELEASE)  # the stand-in may have paused at start (rare)
                before = np.array(arm_joints(remote.probe.latest(ROBOT_STATES)))
                into_table = before.copy()
                into_table[1], into_table[3] = 1.5, -1.0  # the hand reaches down, far
                sent = follow.send_goal_async(goal(PANDA_ARM, [(3.0, list(into_table))]))
                wait_until(sent.done, 10.0, "the goal's answer")
                assert not sent.result().accepted
                remote.probe.wait_count(REFUSED, 1, timeout_s=10.0)
                line = remote.probe.latest(REFUSED).data
                assert "scene_table" in line and "\n" not in line, line  # not the E-stop's
                time.sleep(2.0)
                after = np.array(arm_joints(remote.probe.latest(ROBOT_STATES)))
                assert np.abs(after - before).max() < 0.005  # the robot never moved
                asked = time.monotonic()  # the robot renders every 10 s: its next frame
                remote.probe.wait_count(ROBOT_CAMERA, 1, asked, timeout_s=30.0)
                robot_frame = _pixels(remote.probe.latest(ROBOT_CAMERA))
                remote.probe.wait_count(TWIN_CAMERA, 1, time.monotonic(), timeout_s=10.0)
                twin_frame = _pixels(remote.probe.latest(TWIN_CAMERA))
            finally:
                _, err = stop(real)
    latches = [line for line in err.splitlines() if "E-stop latched" in line]
    print(f"E-stop latches while it ran: {len(latches)}")
    assert all("joint_states stopped" in line for line in latches), err  # only the stream rule
    assert robot_frame.shape == twin_frame.shape
    difference = np.abs(robot_frame.astype(int) - twin_frame.astype(int)).mean()
    print(f"twin vs robot agentview: mean difference {difference:.2f} of 255")
    assert difference < SAME_PICTURE, difference
