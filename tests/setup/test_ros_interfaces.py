"""The ROS interface packages that ./bootstrap builds into .venv (interfaces/: no wheels exist).

Jazzy peers compare RIHS01 type hashes, so ours must equal upstream Jazzy's: TFMessage as a
peer sees it on the wire, the action and the tolerance messages from the type descriptions
the build generated (re-hashed here). Two rclpy nodes then use both packages for real: a
latched /tf_static and a FollowJointTrajectory goal with feedback and a result. Last, the
bootstrap build step is a no-op once built.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from control_msgs.msg import JointComponentTolerance, JointTolerance
from openral_bridge.ros_messages import LATCHED
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from rclpy.action import ActionClient, ActionServer
from rclpy.action.server import ServerGoalHandle
from rclpy.context import Context
from rclpy.node import Node
from rclpy.task import Future
from rclpy.topic_endpoint_info import TopicEndpointInfo
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from tests.conftest import REPO

# Upstream Jazzy's hashes (tf2_msgs 0.36, control_msgs 5.8 and ros2_control's
# controller_manager_msgs 4.46 from their jazzy branches: generated from upstream's own files).
TF_MESSAGE = "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"
FOLLOW_JOINT_TRAJECTORY = "RIHS01_738ebcb7a2d7cfa42f9f1001cc99ce3a4383d1cfe508015d9be8485e4b1c66f6"
FJT_FEEDBACK_MESSAGE = "RIHS01_80398fcb9674a79081a9906e2ccf0c804dd7cb15e22e362e606ee87186beab71"
JOINT_TOLERANCE = "RIHS01_c254f9cece0f3b733017b6990fd46d1326e25242d6b8844398c97d9a88e7d648"
JOINT_COMPONENT_TOLERANCE = (
    "RIHS01_739ea7566931944d33830fa10f1bf5e7a7fbdc3172bce7a7eaac642bd6e3ffa4"
)
GRIPPER_COMMAND = "RIHS01_e17c0e644eccf14bea84a0a93e0977182872c2eb7873ca6694900059b46dbc84"
GRIPPER_COMMAND_MSG = "RIHS01_57eb8f326c9889ca8bb34ead82cc94cc09bf6bc5c3b6c09546dca3a00b589890"
JTC_STATE = "RIHS01_51d8dd89cc624cbe9daaeeb4d80d6de9b86168ffdc3be41fefc0953e3c26e480"
DYNAMIC_JOINT_STATE = "RIHS01_18024c98a62697680f581108eeed40b28fb4542fa0ac5a8e36f56c62b6813d26"
INTERFACE_VALUE = "RIHS01_74a12144ef6b7af67533195cb30f7f607d3301b66950208a72d280695f3e190c"
CONTROLLER_STATE = "RIHS01_9a8780ab9814b6032978a07c6c7033cf1a7894ac8d948a6fb72afea07b04cc83"
HARDWARE_INTERFACE = "RIHS01_b4c556991db81ca56a49338b5e8f0675a6707faee54fba161d2bbd4d963d418a"
LIST_CONTROLLERS = "RIHS01_4f8e36bb1fa5afdeba45c2d56ae6a2097b1493a253f961dd6290c085033bd189"
LIST_HARDWARE_INTERFACES = "RIHS01_c3e561a6e8cc7b9d577d8065c783038e51f6950cbe9bed67fb117a3e2e04d8f1"
SWITCH_CONTROLLER = "RIHS01_d4ad10aa5da7808bc522d55d4123d8ef79de73d049d165639d7663ac37cc9895"
SHARE = Path(sys.prefix) / "share"
WAIT_S = 10.0
ACTION = "/arm/follow_joint_trajectory"


def _description(interface: str) -> dict[str, Any]:
    """The type description JSON the build installed for ``pkg/kind/Name``."""
    package, kind, name = interface.split("/")
    data: dict[str, Any] = json.loads((SHARE / package / kind / f"{name}.json").read_text())
    return data


def _rihs01(type_description_msg: dict[str, Any]) -> str:
    """RIHS01 of a type description (REP 2011): sha256 of its JSON without default values."""
    hashable = copy.deepcopy(type_description_msg)
    for description in [hashable["type_description"], *hashable["referenced_type_descriptions"]]:
        for field in description["fields"]:
            del field["default_value"]
    return "RIHS01_" + hashlib.sha256(json.dumps(hashable).encode()).hexdigest()


@pytest.mark.parametrize(
    ("interface", "expected"),
    [
        ("tf2_msgs/msg/TFMessage", TF_MESSAGE),
        ("control_msgs/action/FollowJointTrajectory", FOLLOW_JOINT_TRAJECTORY),
        ("control_msgs/msg/JointTolerance", JOINT_TOLERANCE),
        ("control_msgs/msg/JointComponentTolerance", JOINT_COMPONENT_TOLERANCE),
        ("control_msgs/action/GripperCommand", GRIPPER_COMMAND),
        ("control_msgs/msg/GripperCommand", GRIPPER_COMMAND_MSG),
        ("control_msgs/msg/JointTrajectoryControllerState", JTC_STATE),
        ("control_msgs/msg/DynamicJointState", DYNAMIC_JOINT_STATE),
        ("control_msgs/msg/InterfaceValue", INTERFACE_VALUE),
        ("controller_manager_msgs/msg/ControllerState", CONTROLLER_STATE),
        ("controller_manager_msgs/msg/HardwareInterface", HARDWARE_INTERFACE),
        ("controller_manager_msgs/srv/ListControllers", LIST_CONTROLLERS),
        ("controller_manager_msgs/srv/ListHardwareInterfaces", LIST_HARDWARE_INTERFACES),
        ("controller_manager_msgs/srv/SwitchController", SWITCH_CONTROLLER),
    ],
)
def test_the_generated_type_hash_is_upstream_jazzys(interface: str, expected: str) -> None:
    description = _description(interface)
    recorded = {entry["type_name"]: entry["hash_string"] for entry in description["type_hashes"]}
    assert recorded[interface] == expected
    assert description["type_description_msg"]["type_description"]["type_name"] == interface
    assert _rihs01(description["type_description_msg"]) == expected


@pytest.fixture(scope="module")
def domain() -> int:
    """A ROS domain id of this process's own."""
    return claim_domain_id()


@pytest.fixture(scope="module")
def context(domain: int) -> Iterator[Context]:
    """An rclpy context on ``domain``, discovery on loopback only."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        with ros_session(domain_id=domain) as context:
            yield context


def _wait(future: Future, what: str) -> Any:
    """The result of ``future`` (completed by the spinning executor), failing after WAIT_S."""
    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    if not done.wait(WAIT_S):
        pytest.fail(f"no {what} within {WAIT_S} s")
    return future.result()


def _publisher(node: Node, topic: str) -> TopicEndpointInfo:
    """The one publisher of ``topic`` in ``node``'s graph, once discovered with its node's name
    (the endpoint can be seen before the ros_discovery_info naming its node, for a moment
    ``_NODE_NAME_UNKNOWN_``)."""
    deadline = time.monotonic() + WAIT_S
    while not (publishers := node.get_publishers_info_by_topic(topic)) or any(
        p.node_name == "_NODE_NAME_UNKNOWN_" for p in publishers
    ):
        if time.monotonic() > deadline:
            pytest.fail(f"no named publisher of {topic} discovered within {WAIT_S} s")
        time.sleep(0.01)
    [publisher] = publishers
    return publisher


# A peer in a process of its own, started with none of the variables the venv's ROS
# start-up sets: the built packages load from .venv as they are.
TALKER = """
import sys
import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.context import Context
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from tf2_msgs.msg import TFMessage

context = Context()
rclpy.init(context=context, domain_id=int(sys.argv[1]))
node = Node("tf_talker", context=context)
latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
transform = TransformStamped(child_frame_id="base_link")
transform.header.frame_id = "world"
transform.transform.translation.x = 0.25
transform.transform.rotation.w = 1.0
node.create_publisher(TFMessage, "/tf_static", latched).publish(TFMessage(transforms=[transform]))
print("published", flush=True)
sys.stdin.read()
node.destroy_node()
context.try_shutdown()
"""
SET_BY_VENV = ("LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE", "AMENT_PREFIX_PATH")


def test_a_latched_tf_message_from_another_process_arrives_with_jazzys_hash(
    context: Context, domain: int
) -> None:
    env = {key: value for key, value in os.environ.items() if key not in SET_BY_VENV}
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    talker = subprocess.Popen(
        [sys.executable, "-c", TALKER, str(domain)],
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    listener = Node("tf_listener", context=context)
    spinner = Spinner(context)
    try:
        assert talker.stdout is not None
        assert talker.stdout.readline() == "published\n", talker.communicate(timeout=WAIT_S)
        received: Future = Future()
        listener.create_subscription(TFMessage, "/tf_static", received.set_result, LATCHED)
        spinner.add_node(listener)
        spinner.start()
        message = _wait(received, "/tf_static message")
        assert [t.child_frame_id for t in message.transforms] == ["base_link"]
        assert message.transforms[0].transform.translation.x == 0.25
        publisher = _publisher(listener, "/tf_static")
        assert publisher.node_name == "tf_talker"
        assert str(publisher.topic_type_hash) == TF_MESSAGE
    finally:
        spinner.stop()
        listener.destroy_node()
        talker.communicate(input="", timeout=WAIT_S)
    assert talker.returncode == 0, talker.stderr


def _goal() -> FollowJointTrajectory.Goal:
    point = JointTrajectoryPoint(positions=[0.1, -0.2], time_from_start=Duration(nanosec=200))
    return FollowJointTrajectory.Goal(
        trajectory=JointTrajectory(joint_names=["joint1", "joint2"], points=[point]),
        path_tolerance=[JointTolerance(name="joint1", position=0.05)],
        component_goal_tolerance=[
            JointComponentTolerance(
                joint_name="base", component=JointComponentTolerance.ROTATION, position=0.1
            )
        ],
        goal_time_tolerance=Duration(sec=1),
    )


def test_a_follow_joint_trajectory_goal_is_accepted_and_succeeds(context: Context) -> None:
    node = Node("fjt_peers", context=context)
    goals: list[FollowJointTrajectory.Goal] = []

    def execute(handle: ServerGoalHandle) -> FollowJointTrajectory.Result:
        goals.append(handle.request)
        feedback = FollowJointTrajectory.Feedback(joint_names=handle.request.trajectory.joint_names)
        handle.publish_feedback(feedback)
        handle.succeed()
        return FollowJointTrajectory.Result(
            error_code=FollowJointTrajectory.Result.SUCCESSFUL, error_string="done"
        )

    server = ActionServer(node, FollowJointTrajectory, ACTION, execute)
    client = ActionClient(node, FollowJointTrajectory, ACTION)
    spinner = Spinner(context)
    spinner.add_node(node)
    spinner.start()
    try:
        assert client.wait_for_server(timeout_sec=WAIT_S), "the action server was not discovered"
        feedback: list[Any] = []
        handle = _wait(client.send_goal_async(_goal(), feedback.append), "goal response")
        assert handle.accepted
        response = _wait(handle.get_result_async(), "result")
        assert response.status == GoalStatus.STATUS_SUCCEEDED
        assert response.result.error_code == FollowJointTrajectory.Result.SUCCESSFUL
        assert response.result.error_string == "done"
        assert [f.feedback.joint_names for f in feedback] == [["joint1", "joint2"]]
        [goal] = goals
        assert goal.trajectory.points[0].positions.tolist() == [0.1, -0.2]
        assert goal.path_tolerance[0].position == 0.05
        assert goal.component_goal_tolerance[0].component == 5
        assert goal.goal_time_tolerance.sec == 1
        feedback_publisher = _publisher(node, f"{ACTION}/_action/feedback")
        assert str(feedback_publisher.topic_type_hash) == FJT_FEEDBACK_MESSAGE
        recorded = {
            entry["type_name"]: entry["hash_string"]
            for entry in _description("control_msgs/action/FollowJointTrajectory")["type_hashes"]
        }
        assert recorded["control_msgs/action/FollowJointTrajectory_FeedbackMessage"] == (
            FJT_FEEDBACK_MESSAGE
        )
    finally:
        spinner.stop()
        client.destroy()
        server.destroy()
        node.destroy_node()


def test_bootstrap_builds_nothing_once_the_interfaces_are_built() -> None:
    run = subprocess.run(
        ["./bootstrap", "--list"], cwd=REPO, capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr
    assert "building ROS interface" not in run.stdout + run.stderr
    assert (Path(sys.prefix) / ".openral-interfaces.sha256").is_file()
