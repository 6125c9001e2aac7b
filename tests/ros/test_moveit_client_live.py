"""A MoveIt-like client drives the franka tabletop unchanged, at franka_description's names.

``openral deploy sim`` runs as a subprocess; an outside rclpy client does what MoveIt's
simple controller manager and a planning pipeline do:

- reads the latched ``/robot_description`` and ``/robot_description_semantic`` and finds
  franka_description's links and joints and the SRDF's arm group over panda_joint1..7;
- asks ``/controller_manager/list_controllers`` and ``list_hardware_interfaces`` which
  controllers run and what they claim;
- plans grasp poses over the red cube (IK with mink on its own copy of the scene, seed 0:
  where the graph's cube is), sends them as FollowJointTrajectory goals to
  ``/joint_trajectory_controller/follow_joint_trajectory`` and opens and closes the
  gripper with GripperCommand on ``/gripper_controller/gripper_cmd``: each arm goal ends
  within 0.01 rad of its last point, the gripper opens to reach its goal, closes on the
  cube (stalled at the cube's width, not reached) and keeps it while the arm lifts;
- ``switch_controller`` deactivates the trajectory controller (a goal is then rejected)
  and activates it again; ``/dynamic_joint_states`` and ``controller_state`` flow.
"""

from __future__ import annotations

import math
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import mink
import mujoco
import numpy as np
import pytest
from action_msgs.msg import GoalStatus
from control_msgs.action import GripperCommand
from control_msgs.msg import DynamicJointState, JointTrajectoryControllerState
from controller_manager_msgs.srv import ListControllers, ListHardwareInterfaces, SwitchController
from openral_bridge.ros_messages import LATCHED
from openral_bridge.topics import (
    DYNAMIC_JOINT_STATES,
    GRIPPER_COMMAND,
    JOINT_STATES,
    JTC_STATE,
    ROBOT_DESCRIPTION,
    ROBOT_DESCRIPTION_SEMANTIC,
)
from openral_core import load_scene, open_robot_by_id
from openral_hal.factory import build_hal
from openral_hal.sim_attached import SimAttachedHAL
from openral_hal.tool_centre import ee_command
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.action import ActionClient
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from tests.conftest import ROBOTS
from tests.ros.action_client import PANDA_ARM, TrajectoryActionClient, goal
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import Probe, wait_until

pytestmark = pytest.mark.exclusive  # tracking within 0.01 rad in real time: run alone

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
START_WAIT_S = 90.0
LINKS = [f"panda_link{i}" for i in range(9)] + [
    "panda_hand",
    "panda_leftfinger",
    "panda_rightfinger",
]
JOINTS = [*PANDA_ARM, "panda_finger_joint1", "panda_finger_joint2"]
CUBE_HALF_M = 0.025
"""The red cube's half size (MuJoCo box sizes are halves): where each finger stops [m]."""


@dataclass
class Graph:
    probe: Probe
    node: Node
    action: TrajectoryActionClient
    gripper: Any
    texts: dict[str, str]
    """The latched descriptions by topic."""

    def call(self, kind: Any, name: str, request: Any = None) -> Any:
        client = self.node.create_client(kind, name)
        assert client.wait_for_service(timeout_sec=10.0), name
        future = client.call_async(request if request is not None else kind.Request())
        wait_until(future.done, 10.0, name)
        self.node.destroy_client(client)
        return future.result()

    def arm(self) -> np.ndarray:
        msg = self.probe.latest(JOINT_STATES)
        return np.array([msg.position[list(msg.name).index(j)] for j in PANDA_ARM])

    def finger(self) -> float:
        msg = self.probe.latest(JOINT_STATES)
        return float(msg.position[list(msg.name).index("panda_finger_joint1")])


@pytest.fixture(scope="module")
def graph(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Graph]:
    logs = tmp_path_factory.mktemp("moveit_client")
    domain = claim_domain_id()
    topics = {
        JOINT_STATES: JointState,
        DYNAMIC_JOINT_STATES: DynamicJointState,
        JTC_STATE: JointTrajectoryControllerState,
    }
    with ros_session(domain_id=domain) as context:
        probe = Probe(context, topics, name="moveit_like_client")
        texts: dict[str, str] = {}
        for latched in (ROBOT_DESCRIPTION, ROBOT_DESCRIPTION_SEMANTIC):
            probe.node.create_subscription(
                String, latched, lambda m, t=latched: texts.__setitem__(t, m.data), LATCHED
            )
        with Spinner(context) as spinner, deploy_sim(SCENE, domain, logs) as process:
            spinner.add_node(probe.node)
            probe.wait_count(JOINT_STATES, 1, timeout_s=START_WAIT_S)
            action = TrajectoryActionClient(probe.node, timeout_s=START_WAIT_S)
            gripper = ActionClient(probe.node, GripperCommand, GRIPPER_COMMAND)
            assert gripper.wait_for_server(timeout_sec=30.0), deploy_output(logs)
            yield Graph(probe, probe.node, action, gripper, texts)
            assert process.poll() is None, deploy_output(logs)
            gripper.destroy()
            action.destroy()
        probe.node.destroy_node()  # type: ignore[no-untyped-call]


def _latched(graph: Graph, topic: str) -> str:
    wait_until(lambda: topic in graph.texts, 60.0, topic)
    return graph.texts[topic]


def test_the_descriptions_have_franka_descriptions_names(graph: Graph) -> None:
    urdf = ET.fromstring(_latched(graph, ROBOT_DESCRIPTION))
    links = {link.get("name") for link in urdf.iter("link")}
    joints = {joint.get("name") for joint in urdf.iter("joint")}
    assert set(LINKS) <= links, sorted(set(LINKS) - links)
    assert set(JOINTS) <= joints, sorted(set(JOINTS) - joints)
    srdf = ET.fromstring(_latched(graph, ROBOT_DESCRIPTION_SEMANTIC))
    arm = next(g for g in srdf.iter("group") if g.get("name") == "arm")
    assert [j.get("name") for j in arm.iter("joint")] == list(PANDA_ARM)


def test_the_controller_manager_lists_what_runs_and_claims(graph: Graph) -> None:
    listed = {
        c.name: c
        for c in graph.call(ListControllers, "/controller_manager/list_controllers").controller
    }
    assert set(listed) == {
        "joint_state_broadcaster",
        "joint_trajectory_controller",
        "gripper_controller",
    }
    jtc = listed["joint_trajectory_controller"]
    assert (
        jtc.state == "active"
        and jtc.type == "joint_trajectory_controller/JointTrajectoryController"
    )
    assert list(jtc.claimed_interfaces) == [f"{j}/position" for j in PANDA_ARM]
    assert list(listed["gripper_controller"].claimed_interfaces) == ["panda_finger_joint1/position"]
    assert jtc.update_rate == 100
    hardware = graph.call(ListHardwareInterfaces, "/controller_manager/list_hardware_interfaces")
    claimed = {i.name for i in hardware.command_interfaces if i.is_claimed}
    assert claimed == {f"{j}/position" for j in [*PANDA_ARM, "panda_finger_joint1"]}
    assert "panda_joint4/effort" in {i.name for i in hardware.state_interfaces}


def _plan(poses: list[tuple[float, float]]) -> list[np.ndarray]:
    """Arm joint positions putting the TCP over the red cube at each (height above the cube
    [m], yaw turn) pose, the hand turned to the cube's faces: IK (mink) on this process's
    own copy of the scene (seed 0, as the graph)."""
    robot = open_robot_by_id("franka_panda")
    hal = build_hal(robot, mode="sim", scene=load_scene(SCENE))
    assert isinstance(hal, SimAttachedHAL)
    hal.connect()
    try:
        handles = hal.mujoco_handles()
        command = ee_command(hal, robot)
        assert handles is not None and command is not None
        model, data = handles
        cube = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "scene_red_cube")
        w, x, y, z = data.xquat[cube]
        cube_yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        commanded = np.asarray(hal.hold_action()[:7], dtype=np.float64)
        start = command.ee.commanded_pose(data, commanded)
        rotation = start.rotation().as_matrix()
        hand_yaw = math.atan2(rotation[1, 0], rotation[0, 0])
        turn = (cube_yaw - hand_yaw + math.pi / 4) % (math.pi / 2) - math.pi / 4
        plans = []
        for height, _ in poses:
            target = mink.SE3.from_rotation_and_translation(
                mink.SO3.from_z_radians(turn) @ start.rotation(),
                data.xpos[cube] + np.array([0.0, 0.0, height]),
            )
            for _ in range(400):
                commanded = command.ee.joint_targets(data, commanded, target, 0.05)
            plans.append(commanded.copy())
        return plans
    finally:
        hal.disconnect()


def _move(graph: Graph, to: np.ndarray, seconds: float) -> None:
    q = graph.arm()
    status, result, _ = graph.action.run(
        goal(PANDA_ARM, [(0.0, q.tolist()), (seconds, to.tolist())])
    )
    assert status == GoalStatus.STATUS_SUCCEEDED, result.error_string
    time.sleep(0.3)
    error = np.abs(graph.arm() - to).max()
    print(f"arm within {error:.4f} rad of the goal's last point")
    assert error < 0.01


def _grip(graph: Graph, position: float) -> Any:
    message = GripperCommand.Goal()
    message.command.position, message.command.max_effort = position, 70.0
    future = graph.gripper.send_goal_async(message)
    wait_until(future.done, 10.0, "the gripper goal's acceptance")
    handle = future.result()
    assert handle.accepted
    result = handle.get_result_async()
    wait_until(result.done, 30.0, "the gripper goal's result")
    assert result.result().status == GoalStatus.STATUS_SUCCEEDED
    return result.result().result


def test_it_picks_the_cube_with_the_trajectory_and_gripper_actions(graph: Graph) -> None:
    above, at = _plan([(0.10, 0.0), (0.0, 0.0)])
    opened = _grip(graph, 0.04)
    assert opened.reached_goal and not opened.stalled and abs(opened.position - 0.04) < 0.01
    _move(graph, above, 3.0)
    _move(graph, at, 2.0)
    closed = _grip(graph, 0.0)
    print(f"closed on the cube: {closed.position:.4f} m per finger, effort {closed.effort:.1f}")
    assert closed.stalled and not closed.reached_goal
    assert abs(closed.position - CUBE_HALF_M) < 0.004  # stopped by the cube, not at 0
    _move(graph, above, 2.0)
    assert abs(graph.finger() - CUBE_HALF_M) < 0.004  # still holding it, 10 cm up


def test_switch_controller_deactivates_and_activates_the_trajectory_controller(
    graph: Graph,
) -> None:
    switch = SwitchController.Request(deactivate_controllers=["joint_trajectory_controller"])
    switch.strictness = SwitchController.Request.STRICT
    answer = graph.call(SwitchController, "/controller_manager/switch_controller", switch)
    assert answer.ok, answer.message
    q = graph.arm()
    assert graph.action.rejected(goal(PANDA_ARM, [(0.0, q.tolist()), (1.0, q.tolist())]))
    unknown = SwitchController.Request(activate_controllers=["nope"], strictness=2)
    refused = graph.call(SwitchController, "/controller_manager/switch_controller", unknown)
    assert not refused.ok and "no controller 'nope'" in refused.message
    again = SwitchController.Request(activate_controllers=["joint_trajectory_controller"])
    assert graph.call(SwitchController, "/controller_manager/switch_controller", again).ok
    status, _, _ = graph.action.run(goal(PANDA_ARM, [(0.0, q.tolist()), (0.5, q.tolist())]))
    assert status == GoalStatus.STATUS_SUCCEEDED


def test_dynamic_joint_states_and_controller_state_flow(graph: Graph) -> None:
    since = time.monotonic()
    graph.probe.wait(
        lambda: len(graph.probe.since(JTC_STATE, since)) >= 10, 10.0, "controller_state"
    )
    state = graph.probe.latest(JTC_STATE)
    assert list(state.joint_names) == list(PANDA_ARM)
    np.testing.assert_allclose(
        state.error.positions, np.subtract(state.reference.positions, state.feedback.positions)
    )
    dynamic = graph.probe.latest(DYNAMIC_JOINT_STATES)
    assert "panda_joint1" in dynamic.joint_names
    values = dynamic.interface_values[list(dynamic.joint_names).index("panda_joint1")]
    assert list(values.interface_names) == ["position", "velocity", "effort"]
