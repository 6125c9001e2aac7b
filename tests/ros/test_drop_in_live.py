"""deploy sim as a robot's driver is judged from outside: fresh state at the update rate, and
``--no-tf`` beside a robot_state_publisher.

- On the franka tabletop (tf on), /joint_states and /tf come at 100 Hz ± 5 % of wall time
  with at least 95 % distinct stamps (each message a new state); on the mobile Panda's room
  /joint_states and /odom likewise.
- With ``--no-tf`` (franka tabletop, mobile Panda's room), the graph sends no transform of a
  URDF link (robot_state_publisher's job), and a robot_state_publisher stand-in (yourdfpy's
  forward kinematics over /robot_description at the newest /joint_states) together with what
  the graph still sends (world, odometry, scene cameras) resolves every frame_id the graph
  names, sensor frames on the robot included (they are in the URDF).
"""

from __future__ import annotations

import io
import time
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import pytest
import yourdfpy
from nav_msgs.msg import Odometry
from openral_bridge.topics import JOINT_STATES, ODOM, ROBOT_DESCRIPTION, TF, TF_STATIC
from openral_core import open_robot_by_id
from openral_core.loaded import LoadedRobot
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.test_tf_live import (
    SCENES,
    START_WAIT_S,
    Graph,
    Recorder,
    _named_frames,
    _subscribe_to_headers,
    _transforms,
    unresolved,
)

pytestmark = pytest.mark.exclusive  # rates of wall time: run alone

RATE_HZ = 100.0
WINDOW_S = 4.0
"""Wall time the rates are measured over [s]."""
CASES = {
    "franka_panda": ("franka_panda", ()),
    "franka_panda --no-tf": ("franka_panda", ("--no-tf",)),
    "panda_mobile --no-tf": ("panda_mobile", ("--no-tf",)),
}


@dataclass
class Live:
    graph: Graph
    no_tf: bool

    @property
    def robot(self) -> LoadedRobot:
        return self.graph.robot


@pytest.fixture(scope="module")
def live(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[Live]:
    robot_id, extra = CASES[request.param]
    logs = tmp_path_factory.mktemp("drop_in")
    domain = claim_domain_id()
    topics = {TF: TFMessage, JOINT_STATES: JointState, ODOM: Odometry}
    with ros_session(domain_id=domain) as context:
        recorder = Recorder(context, topics, "drop_in_client")
        with (
            Spinner(context) as spinner,
            deploy_sim(SCENES[robot_id], domain, logs, extra) as process,
        ):
            spinner.add_node(recorder.node)
            for topic in (JOINT_STATES, ROBOT_DESCRIPTION):
                recorder.wait_count(topic, 1, timeout_s=START_WAIT_S)
            headers = _subscribe_to_headers(recorder, logs)
            assert process.poll() is None, deploy_output(logs)
            graph = Graph(open_robot_by_id(robot_id), recorder, headers, logs)
            yield Live(graph, "--no-tf" in extra)
        recorder.node.destroy_node()  # type: ignore[no-untyped-call]


def _stamps(messages: list[object], topic: str) -> list[int]:
    if topic == TF:
        return [
            m.transforms[0].header.stamp.sec * 10**9 + m.transforms[0].header.stamp.nanosec
            for m in messages
            if m.transforms
        ]  # type: ignore[attr-defined]
    return [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in messages]  # type: ignore[attr-defined]


@pytest.mark.parametrize("live", sorted(CASES), indirect=True)
def test_state_streams_come_fresh_at_the_update_rate(live: Live) -> None:
    recorder = live.graph.recorder
    topics = [JOINT_STATES]
    topics += [ODOM] if live.robot.name == "panda_mobile" else []
    topics += [TF] if not live.no_tf else []
    start = time.monotonic()
    time.sleep(WINDOW_S)
    for topic in topics:
        received = [r for r in recorder.since(topic, start) if r.at <= start + WINDOW_S]
        stamps = _stamps([r.msg for r in received], topic)
        rate = len(received) / WINDOW_S
        distinct = len(set(stamps)) / len(stamps)
        print(
            f"{live.robot.name} {topic}: {rate:.1f} Hz of wall time, {distinct:.1%} distinct stamps"
        )
        assert abs(rate - RATE_HZ) <= 0.05 * RATE_HZ, f"{topic}: {rate:.1f} Hz"
        assert distinct >= 0.95, f"{topic}: {distinct:.1%} distinct stamps"
        assert all(np.diff(stamps) > 0), f"{topic}: a stamp went back or repeated"


def _fk(text: str, state: JointState) -> dict[str, tuple[str, np.ndarray]]:
    """What a robot_state_publisher sends at ``state``: child link → (parent, transform)."""
    urdf = yourdfpy.URDF.load(io.StringIO(text), load_meshes=False)
    positions = dict(zip(state.name, state.position, strict=True))
    urdf.update_cfg({name: positions[name] for name in urdf.actuated_joint_names})
    return {
        joint.child: (joint.parent, urdf.get_transform(joint.child, joint.parent))
        for joint in urdf.robot.joints
    }


@pytest.mark.parametrize("live", [c for c in sorted(CASES) if "--no-tf" in c], indirect=True)
def test_no_tf_leaves_the_urdf_to_a_robot_state_publisher(live: Live) -> None:
    recorder = live.graph.recorder
    text = recorder.latest(ROBOT_DESCRIPTION).data
    rsp = _fk(text, recorder.latest(JOINT_STATES))
    sent = [*recorder.all(TF_STATIC), *recorder.all(TF)]
    doubled = {t.child_frame_id for m in sent for t in m.transforms} & set(rsp)
    assert not doubled, f"the graph sends URDF frames with --no-tf: {sorted(doubled)}"
    tree = {**_transforms(*sent), **rsp}
    world = live.robot.tables.frames.world
    named = _named_frames(live.graph)
    lost = unresolved(tree, named, world)
    assert not lost, "frames the URDF and the graph do not resolve:\n" + "\n".join(lost.values())
    sensors = {s.frame_id for s in live.robot.description.sensors} & set(rsp)
    resolved = f"{len(named)} frames resolved; sensors in the URDF: {sorted(sensors)}"
    print(f"{live.robot.name} --no-tf: {resolved}")
    assert "wrist_optical_frame" in sensors  # the wrist camera rides the hand: in the URDF
