"""The TF tree of live graphs, checked from outside: ``openral deploy sim`` as a subprocess,
read by a client on a domain of its own, as rviz or a tf2 listener would.

For the franka tabletop, the mobile Panda's room and the ALOHA tabletop, one graph at a time:

- every frame named by ``/tf``, ``/tf_static`` and the header (and ``child_frame_id``) of
  every topic the graph publishes resolves to the world frame through those transforms,
  and no frame has two parents;
- ``/robot_description`` parses, its links are TF frames, and its forward kinematics at the
  positions of one ``/joint_states`` message equal the TF chain of the same stamp
  (base frame → each link) within 1 mm;
- ``/tf`` stamps strictly increase (a tf2 buffer refuses repeated data);
- the mobile Panda's ``/odom`` pose equals the TF ``odom`` → base frame of the same stamp
  while it drives.

The topics carrying a header are discovered once the graph is up: ``deploy sim`` prints the
topics it publishes when its graph is live, and the client waits until discovery has them.
"""

from __future__ import annotations

import io
import itertools
import math
import re
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
import yourdfpy
from control_msgs.msg import DynamicJointState, JointTrajectoryControllerState
from geometry_msgs.msg import Twist
from openral_bridge.ros_messages import LATCHED
from openral_bridge.topics import (
    CMD_VEL,
    JOINT_STATES,
    ODOM,
    ROBOT_DESCRIPTION,
    ROBOT_DESCRIPTION_SEMANTIC,
    TF,
    TF_STATIC,
)
from openral_core import open_robot_by_id
from openral_core.loaded import LoadedRobot
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from openral_nodes.topic_graph import message_class
from rclpy.context import Context
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from tests.conftest import ROBOTS
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import WAIT_S, Probe, wait_until

SCENES = {
    "franka_panda": ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml",
    "panda_mobile": ROBOTS / "panda_mobile" / "scenes" / "room.yaml",
    "aloha": ROBOTS / "aloha" / "scenes" / "tabletop.yaml",
}
MOBILE = "panda_mobile"
START_WAIT_S = 90.0
"""Longest wait for deploy sim to load its scene and publish on a loaded machine [s]."""
LIVE = "running; stop with Ctrl-C"
"""What deploy sim prints once its graph is live, after its table of published topics."""
TABLE_ROW = re.compile(r"^\s*(/\S+)\s+(\w+/msg/\w+)\s", re.MULTILINE)
"""A row of deploy sim's table of published topics: the topic and its type."""
FK_TOLERANCE_M = 1e-3
FK_TOLERANCE_RAD = 1e-3
ODOM_TOLERANCE = 1e-6
"""[m and rad]"""
TF_MESSAGES = 20
"""/tf messages whose stamps are compared (a second at 20 Hz)."""

JOINT_SPACE = (JointState, DynamicJointState, JointTrajectoryControllerState)
"""Messages in joint space: an empty frame_id names no frame."""


class Recorder(Probe):
    """A :class:`Probe` that can subscribe to more topics, with a QoS of their own."""

    def __init__(self, context: Context, topics: dict[str, Any], name: str) -> None:
        super().__init__(context, topics, name)
        self.subscribe(TF_STATIC, TFMessage, LATCHED)
        self.subscribe(ROBOT_DESCRIPTION, String, LATCHED)
        self.subscribe(ROBOT_DESCRIPTION_SEMANTIC, String, LATCHED)

    def subscribe(self, topic: str, kind: Any, qos: QoSProfile) -> None:
        """Record ``topic`` too."""
        with self._condition:
            self.messages[topic] = []
        self.node.create_subscription(kind, topic, partial(self._record, topic), qos)

    def all(self, topic: str) -> list[Any]:
        """Every message of ``topic`` received so far."""
        return [received.msg for received in self.since(topic, 0.0)]


@dataclass
class Graph:
    """A live graph of one scene and a recorder of its topics."""

    robot: LoadedRobot
    recorder: Recorder
    headers: dict[str, Any]
    """The topics it publishes whose messages carry a header, and their types."""
    logs: Path


@pytest.fixture(scope="module", params=sorted(SCENES))
def graph(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[Graph]:
    robot_id: str = request.param
    logs = tmp_path_factory.mktemp(f"tf_live_{robot_id}")
    domain = claim_domain_id()
    with ros_session(domain_id=domain) as context:
        recorder = Recorder(context, {TF: TFMessage, JOINT_STATES: JointState}, "tf_client")
        with Spinner(context) as spinner, deploy_sim(SCENES[robot_id], domain, logs) as process:
            spinner.add_node(recorder.node)
            for topic in (TF, TF_STATIC, JOINT_STATES, ROBOT_DESCRIPTION):
                recorder.wait_count(topic, 1, timeout_s=START_WAIT_S)
            headers = _subscribe_to_headers(recorder, logs)
            for topic, kind in headers.items():
                if kind is not JointState:  # a JointState's frame is empty; some only on events
                    recorder.wait_count(topic, 1, timeout_s=WAIT_S)
            assert process.poll() is None, deploy_output(logs)
            yield Graph(open_robot_by_id(robot_id), recorder, headers, logs)
        recorder.node.destroy_node()  # type: ignore[no-untyped-call]


def _subscribe_to_headers(recorder: Recorder, logs: Path) -> dict[str, Any]:
    """Once the topics deploy sim lists are discovered, record every published topic whose
    type carries a header (with its publisher's reliability and durability)."""
    wait_until(lambda: LIVE in deploy_output(logs)[0], START_WAIT_S, "deploy sim's topic table")
    declared = dict(TABLE_ROW.findall(deploy_output(logs)[0]))
    assert declared.get(TF) == "tf2_msgs/msg/TFMessage", deploy_output(logs)[0]
    node = recorder.node

    def discovered() -> bool:
        return all(node.count_publishers(topic) for topic in declared)

    wait_until(discovered, WAIT_S, f"publishers of {sorted(declared)}")
    headers: dict[str, Any] = {}
    for topic, types in node.get_topic_names_and_types():
        publishers = node.get_publishers_info_by_topic(topic)
        if not publishers or topic in recorder.messages or "/_action/" in topic:
            continue  # (an action's topics carry no header of their own)
        kind = message_class(types[0], topic)
        if "header" not in kind.get_fields_and_field_types():
            continue
        offered = publishers[0].qos_profile
        qos = QoSProfile(  # type: ignore[no-untyped-call]
            depth=10, reliability=offered.reliability, durability=offered.durability
        )
        recorder.subscribe(topic, kind, qos)
        headers[topic] = kind
    unread = {t for t, kind in declared.items() if _has_header(kind, t)} - set(recorder.messages)
    assert not unread, f"topics deploy sim lists that discovery does not offer: {unread}"
    return headers


def _has_header(type_name: str, topic: str) -> bool:
    return "header" in message_class(type_name, topic).get_fields_and_field_types()


# -- transforms ------------------------------------------------------------------------------


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _matrix(t: Any, r: Any) -> np.ndarray:
    """A translation (or position) and a rotation quaternion as a 4x4 matrix."""
    rotation = np.empty(9)
    mujoco.mju_quat2Mat(rotation, np.array([r.w, r.x, r.y, r.z]))
    matrix = np.eye(4)
    matrix[:3, :3] = rotation.reshape(3, 3)
    matrix[:3, 3] = t.x, t.y, t.z
    return matrix


def _errors(actual: np.ndarray, expected: np.ndarray) -> tuple[float, float]:
    """(distance [m], angle [rad]) between two poses (4x4), accurate near zero."""
    turn = actual[:3, :3].T @ expected[:3, :3]
    skew = (turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0], turn[1, 0] - turn[0, 1])
    angle = math.atan2(float(np.linalg.norm(skew)) / 2, (np.trace(turn) - 1) / 2)
    return float(np.linalg.norm(actual[:3, 3] - expected[:3, 3])), angle


def _transforms(*messages: Any) -> dict[str, tuple[str, np.ndarray]]:
    """child → (parent, transform) of every transform in ``messages`` (later ones win)."""
    return {
        t.child_frame_id: (
            t.header.frame_id,
            _matrix(t.transform.translation, t.transform.rotation),
        )
        for message in messages
        for t in message.transforms
    }


def _chain(tree: dict[str, tuple[str, np.ndarray]], frame: str, top: str) -> np.ndarray:
    """``frame``'s pose in ``top``, chained through the parents of ``tree``."""
    pose, at, seen = np.eye(4), frame, [frame]
    while at != top:
        assert at in tree, f"frame {frame!r} has no chain to {top!r}: {' → '.join(seen)} ends"
        parent, transform = tree[at]
        pose, at = transform @ pose, parent
        assert at not in seen, f"frame {frame!r}: a loop {' → '.join([*seen, at])}"
        seen.append(at)
    return pose


def unresolved(
    tree: dict[str, tuple[str, np.ndarray]], named: dict[str, str], top: str
) -> dict[str, str]:
    """Frame → why, for each frame of ``named`` (frame → topic naming it) that ``tree`` does
    not chain to ``top``."""
    lost = {}
    for frame, topic in named.items():
        try:
            _chain(tree, frame, top)
        except AssertionError as error:
            lost[frame] = f"(on {topic}) {error}"
    return lost


def _with_tf(recorder: Recorder, messages: list[Any], what: str) -> tuple[Any, Any]:
    """(the newest of ``messages`` whose stamp a /tf message carries too, that /tf message),
    waiting for more of both. /tf is sent from a pacer job at most once per control tick, so
    a starved tick has joint states or odometry but no /tf of its stamp."""
    found: list[tuple[Any, Any]] = []

    def matched() -> bool:
        tf = {_ns(m.transforms[0].header.stamp): m for m in recorder.all(TF)}
        found[:] = [(m, tf[_ns(m.header.stamp)]) for m in messages if _ns(m.header.stamp) in tf]
        return bool(found)

    recorder.wait(matched, WAIT_S, f"a /tf stamped as one of {len(messages)} {what}")
    return found[-1]


# -- the frames ------------------------------------------------------------------------------


def _named_frames(graph: Graph) -> dict[str, str]:
    """Every frame the graph names → a topic that names it."""
    recorder, named = graph.recorder, dict[str, str]()
    for topic in list(recorder.messages):
        for msg in recorder.all(topic):
            if isinstance(msg, TFMessage):
                for t in msg.transforms:
                    named.setdefault(t.header.frame_id, topic)
                    named.setdefault(t.child_frame_id, topic)
            elif hasattr(msg, "header"):
                if msg.header.frame_id or not isinstance(msg, JOINT_SPACE):
                    named.setdefault(msg.header.frame_id, topic)
                if getattr(msg, "child_frame_id", None) is not None:
                    named.setdefault(msg.child_frame_id, topic)
    return named


def test_every_frame_named_resolves_to_the_world(graph: Graph) -> None:
    recorder = graph.recorder
    world = graph.robot.tables.frames.world
    transforms = [*recorder.all(TF_STATIC), *recorder.all(TF)]
    parents: dict[str, set[str]] = {}
    for message in transforms:
        for t in message.transforms:
            parents.setdefault(t.child_frame_id, set()).add(t.header.frame_id)
    twice = {child: sorted(names) for child, names in parents.items() if len(names) > 1}
    assert not twice, f"frames with two parents: {twice}"
    tree = _transforms(*transforms)
    named = _named_frames(graph)
    lost = unresolved(tree, named, world)
    assert not lost, "frames with no chain to the world:\n" + "\n".join(lost.values())
    print(f"{graph.robot.name}: {len(named)} frames named on {len(recorder.messages)} topics")


def test_robot_description_moves_as_tf_says(graph: Graph) -> None:
    recorder = graph.recorder
    text = recorder.latest(ROBOT_DESCRIPTION).data
    urdf = yourdfpy.URDF.load(io.StringIO(text), load_meshes=False)
    static = recorder.latest(TF_STATIC)
    frames = set(_transforms(static, *recorder.all(TF))) | {graph.robot.tables.frames.world}
    assert set(urdf.link_map) <= frames, f"links not on TF: {set(urdf.link_map) - frames}"
    state, tf = _with_tf(recorder, recorder.all(JOINT_STATES)[-50:], "joint states")
    positions = dict(zip(state.name, state.position, strict=True))
    missing = set(urdf.actuated_joint_names) - set(positions)
    assert not missing, f"URDF joints missing from /joint_states: {missing}"
    urdf.update_cfg({name: positions[name] for name in urdf.actuated_joint_names})
    tree = _transforms(static, tf)
    errors = {
        link: _errors(_chain(tree, link, urdf.base_link), urdf.get_transform(link, urdf.base_link))
        for link in urdf.link_map
    }
    distance, angle = (max(e[i] for e in errors.values()) for i in (0, 1))
    print(f"{graph.robot.name}: URDF vs TF, {len(errors)} links: {distance:.2e} m, {angle:.2e} rad")
    off = {
        link: e for link, e in errors.items() if e[0] > FK_TOLERANCE_M or e[1] > FK_TOLERANCE_RAD
    }
    assert not off, f"links where the URDF's kinematics leave TF (m, rad): {off}"


def test_the_srdf_is_latched_and_names_the_urdfs_links_and_joints(graph: Graph) -> None:
    recorder = graph.recorder
    recorder.wait_count(ROBOT_DESCRIPTION_SEMANTIC, 1, timeout_s=WAIT_S)
    urdf = yourdfpy.URDF.load(
        io.StringIO(recorder.latest(ROBOT_DESCRIPTION).data), load_meshes=False
    )
    srdf = ET.fromstring(recorder.latest(ROBOT_DESCRIPTION_SEMANTIC).data)
    assert srdf.get("name") == urdf.robot.name
    arm = next(g for g in srdf.iter("group") if g.get("name") == "arm")
    manifest = [j.name for j in graph.robot.description.joints]
    assert [j.get("name") for j in arm.iter("joint")] == [
        name for name in manifest if name in [j.get("name") for j in arm.iter("joint")]
    ]
    for joint in srdf.iter("joint"):
        assert joint.get("name") in urdf.joint_map, joint.get("name")
    for element in (*srdf.iter("link"), *srdf.iter("disable_collisions")):
        for key in ("name", "link1", "link2"):
            if element.get(key) is not None:
                assert element.get(key) in urdf.link_map, element.get(key)


def test_tf_stamps_strictly_increase(graph: Graph) -> None:
    recorder = graph.recorder
    recorder.wait_count(TF, TF_MESSAGES, timeout_s=WAIT_S)
    stamps: list[int] = []
    for message in recorder.all(TF):
        one = {_ns(t.header.stamp) for t in message.transforms}
        assert len(one) == 1, f"a /tf message with stamps {sorted(one)}"
        stamps.extend(one)
    repeated = [(a, b) for a, b in itertools.pairwise(stamps) if b <= a]
    assert not repeated, f"/tf stamps [ns] that do not increase: {repeated[:5]}"


@pytest.mark.parametrize("graph", [MOBILE], indirect=True)
def test_odom_is_the_tf_of_the_base_while_it_drives(graph: Graph) -> None:
    recorder = graph.recorder
    twist = recorder.node.create_publisher(Twist, CMD_VEL, 10)
    wait_until(lambda: twist.get_subscription_count() > 0, WAIT_S, "a /cmd_vel subscriber")
    start = time.monotonic()
    command = Twist()
    command.linear.x, command.angular.z = 0.3, 0.3
    for tick in range(21):  # 1 s at 20 Hz
        time.sleep(max(0.0, start + tick / 20 - time.monotonic()))
        twist.publish(command)
    twist.publish(Twist())
    moving = [m for m in recorder.all(ODOM)[-40:] if m.twist.twist.linear.x > 0.1]
    assert moving, "the base did not drive"
    odom, tf = _with_tf(recorder, moving, "odometry messages")
    names = graph.robot.tables.frames
    assert (odom.header.frame_id, odom.child_frame_id) == (names.odom, names.base)
    tree = _transforms(tf)
    assert tree[names.base][0] == names.odom
    position = odom.pose.pose.position
    pose = _matrix(position, odom.pose.pose.orientation)
    distance, angle = _errors(tree[names.base][1], pose)
    assert distance < ODOM_TOLERANCE and angle < ODOM_TOLERANCE, (
        f"/odom and TF {names.odom} → {names.base} at {_ns(odom.header.stamp)} ns differ by "
        f"{distance:.3g} m, {angle:.3g} rad (odom x {position.x:.6f} m)"
    )
