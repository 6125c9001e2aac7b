"""``openral deploy real --robot franka_panda --transport ros2_control:robot`` with deploy sim
as the robot (namespace /robot) and deploy real's own graph under /real, on one domain: a
FollowJointTrajectory goal sent to deploy real moves the robot's arm, and killing the robot
latches deploy real's E-stop with one line. In simulation, not on hardware."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from control_msgs.action import FollowJointTrajectory
from sensor_msgs.msg import JointState

from tests.conftest import ROBOTS
from tests.real.deploy_helpers import openral, remote_graph, stop
from tests.ros.action_client import PANDA_ARM, _AtomicActionClient, goal, succeeded
from tests.ros.lifecycle_client import deploy_output, deploy_sim

pytestmark = pytest.mark.exclusive  # two live graphs and a 100 Hz stream that must not lag

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
ROBOT_STATES = "/robot/joint_states"
ACTION = "/real/joint_trajectory_controller/follow_joint_trajectory"


def _arm(message: JointState) -> list[float]:
    positions = dict(zip(message.name, message.position, strict=True))
    return [positions[name] for name in PANDA_ARM]


def test_deploy_real_drives_the_robot_through_its_ros2_control_driver(tmp_path: Path) -> None:
    with (
        remote_graph({ROBOT_STATES: JointState}) as remote,
        deploy_sim(SCENE, remote.domain, tmp_path, ("--namespace", "robot"), robot=True) as robot,
    ):
        remote.probe.wait_count(ROBOT_STATES, 1, timeout_s=90.0)
        real = openral(
            "deploy", "real", "--robot", "franka_panda", "--transport", "ros2_control:robot",
            "--namespace", "real", "--domain-id", str(remote.domain),
        )  # fmt: skip
        try:
            client = _AtomicActionClient(remote.probe.node, FollowJointTrajectory, ACTION)
            assert client.wait_for_server(timeout_sec=60.0), stop(real)
            start = _arm(remote.probe.latest(ROBOT_STATES))
            target = [start[0] + 0.3, *start[1:]]
            succeeded(client, goal(PANDA_ARM, [(2.0, target)]))
            time.sleep(0.5)
            reached = _arm(remote.probe.latest(ROBOT_STATES))
            assert max(abs(a - b) for a, b in zip(reached, target, strict=True)) < 0.02
            robot.kill()
            robot.wait(10)
            time.sleep(1.0)
        finally:
            _, err = stop(real)
    fault = [line for line in err.splitlines() if "E-stop latched" in line]
    assert len(fault) == 1 and "joint_states stopped" in fault[0], (fault, deploy_output(tmp_path))
