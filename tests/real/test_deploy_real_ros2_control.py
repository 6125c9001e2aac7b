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
from std_srvs.srv import Trigger

from tests.conftest import ROBOTS
from tests.real.deploy_helpers import openral, remote_graph, stop
from tests.real.stand_in import RELEASE, ROBOT_STATES, release_and_move, steady
from tests.ros.action_client import _AtomicActionClient
from tests.ros.lifecycle_client import deploy_output, deploy_sim

pytestmark = pytest.mark.exclusive  # two live graphs and a 100 Hz stream that must not lag

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
ACTION = "/real/joint_trajectory_controller/follow_joint_trajectory"


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
            steady(remote)  # deploy real joining may have paused the robot's stream once
            release = remote.probe.node.create_client(Trigger, RELEASE)
            release_and_move(remote, release, client, 0.3)
            killed_at = time.time()
            robot.kill()
            robot.wait(10)
            time.sleep(1.0)
        finally:
            _, err = stop(real)
    fault = [line for line in err.splitlines() if "E-stop latched" in line]
    assert all("joint_states stopped" in line for line in fault), (fault, deploy_output(tmp_path))
    after_kill = [line for line in fault if _logged_at(line) >= killed_at]
    assert len(after_kill) == 1, (fault, deploy_output(tmp_path))  # one line for the kill


def _logged_at(line: str) -> float:
    """The wall-clock time [s] of a ROS log line (``[LEVEL] [sec.nsec] [node]: ...``)."""
    return float(line.split("] [", 2)[1])
