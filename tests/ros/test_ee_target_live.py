"""Deploy sim's end-effector interface on the franka tabletop, from outside the graph.

``openral deploy sim`` runs as a subprocess; a client on a domain of its own publishes
``geometry_msgs/PoseStamped`` on ``/openral/ee_target`` and reads ``/openral/tcp_pose``, the
IK's targets on ``/openral/ee_target/state`` and the refusals:

- the first 20 ticks towards a target give the same arm targets, within 1e-6 rad, as 20
  ``ee_pose`` steps of the gymnasium env with that pose from the same start (one IK, one
  meaning of the mode); the published TCP pose then comes within 1 cm of it (the servos'
  sag under gravity: the commanded pose reaches it exactly);
- a target in another frame, with a NaN or a zero quaternion, or while the E-stop is
  latched, is refused with its reason on ``/openral/ee_target/refused`` and moves nothing;
- a ``safe_action`` ends the target (the state topic goes quiet).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from openral_bridge.topics import (
    ACTION_SPEC,
    EE_TARGET,
    EE_TARGET_REFUSED,
    EE_TARGET_STATE,
    ESTOP,
    JOINT_STATES,
    RELEASE_ESTOP,
    RESET,
    SAFE_ACTION,
    TCP_POSE,
)
from openral_eval import make_env
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import Trigger

from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import FRANKA_SCENE, Probe, call_trigger, wait_until

START_WAIT_S = 90.0
BASE = "base_link"
TICKS = 20
SAG_M = 0.01
"""How far the measured TCP may hang below a reached target [m] (see the first test)."""


class EeClient:
    """A probe of the graph, the target and action publishers, the Trigger services."""

    def __init__(self, probe: Probe, logs: Path) -> None:
        node = probe.node
        self.probe, self.logs = probe, logs
        self.target = node.create_publisher(PoseStamped, EE_TARGET, 10)
        self.action = node.create_publisher(Float64MultiArray, SAFE_ACTION, 10)
        names = (RESET, ESTOP, RELEASE_ESTOP)
        self.services = {name: node.create_client(Trigger, name) for name in names}

    def call(self, name: str) -> Any:
        return call_trigger(self.services[name], name)

    def send(self, pose: np.ndarray, frame: str = BASE) -> float:
        """Publish one target (7 values: position, w, x, y, z); returns when it was sent."""
        msg = PoseStamped()
        msg.header.frame_id = frame
        p, q = msg.pose.position, msg.pose.orientation
        p.x, p.y, p.z = (float(v) for v in pose[:3])
        q.w, q.x, q.y, q.z = (float(v) for v in pose[3:7])
        sent = time.monotonic()
        self.target.publish(msg)
        return sent

    def tcp(self) -> np.ndarray:
        """The latest ``/openral/tcp_pose`` as 7 values."""
        msg = self.probe.latest(TCP_POSE)
        p, q = msg.pose.position, msg.pose.orientation
        return np.array([p.x, p.y, p.z, q.w, q.x, q.y, q.z])


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[EeClient]:
    logs = tmp_path_factory.mktemp("ee_target_live")
    domain = claim_domain_id()
    topics = {
        JOINT_STATES: JointState,
        ACTION_SPEC: JointState,
        TCP_POSE: PoseStamped,
        EE_TARGET_STATE: JointState,
        EE_TARGET_REFUSED: String,
    }
    with ros_session(domain_id=domain) as context:
        probe = Probe(context, topics, name="ee_target_client")
        with Spinner(context) as spinner, deploy_sim(FRANKA_SCENE, domain, logs) as process:
            spinner.add_node(probe.node)
            for topic in (JOINT_STATES, TCP_POSE):
                probe.wait_count(topic, 1, timeout_s=START_WAIT_S)
            ee = EeClient(probe, logs)
            wait_until(lambda: ee.target.get_subscription_count() > 0, 10.0, "subscriber")
            assert process.poll() is None, deploy_output(logs)
            yield ee
        probe.node.destroy_node()  # type: ignore[no-untyped-call]


def _env_targets(target: np.ndarray) -> np.ndarray:
    """The arm's targets after each of :data:`TICKS` ``ee_pose`` steps of the env."""
    env = make_env(str(FRANKA_SCENE), action_mode="ee_pose", seed=0)
    try:
        env.reset(seed=0)
        hal = env.unwrapped.hal  # type: ignore[attr-defined]
        arm = env.unwrapped.actions.ee.ee.arm  # type: ignore[attr-defined]
        gripper = float(hal.hold_action()[-1])
        rows = []
        for _ in range(TICKS):
            env.step(np.concatenate([target, [gripper]]))
            rows.append(np.array(hal.hold_action())[arm])
        return np.array(rows)
    finally:
        env.close()


def test_deploy_sim_follows_a_target_as_the_env_does(client: EeClient) -> None:
    assert client.call(RESET).success
    time.sleep(0.3)  # a /openral/tcp_pose after the reset
    start = client.tcp()
    target = start + np.array([0.05, 0.0, -0.05, 0, 0, 0, 0])
    sent = client.send(target)
    client.probe.wait_count(EE_TARGET_STATE, TICKS, sent, timeout_s=15.0)
    deployed = np.array([r.msg.position for r in client.probe.since(EE_TARGET_STATE, sent)])
    expected = _env_targets(target)
    gap = float(np.abs(deployed[:TICKS] - expected).max())
    print(f"largest gap over {TICKS} ticks, deploy sim vs env: {gap:.3g} rad")
    assert gap <= 1e-6
    # the commanded pose reaches the target exactly; the measured TCP hangs below it by the
    # position servo's sag under gravity (about 8 mm there: the model has no compensation)
    wait_until(lambda: np.linalg.norm(client.tcp()[:3] - target[:3]) < SAG_M, 10.0, "the target")


@pytest.mark.parametrize(
    ("frame", "change", "reason"),
    [
        ("world", None, "expected the base frame 'base_link'"),
        (BASE, ("nan", 0), "pose.position.x is nan"),
        (BASE, ("zero", 3), "pose.orientation has norm 0"),
    ],
    ids=["frame", "nan", "zero-quaternion"],
)
def test_a_bad_target_is_refused_and_moves_nothing(
    client: EeClient, frame: str, change: tuple[str, int] | None, reason: str
) -> None:
    _quiet(client)
    pose = client.tcp() + np.array([0.05, 0, 0, 0, 0, 0, 0])
    if change is not None:
        kind, index = change
        pose[index:] = np.nan if kind == "nan" else 0.0
    sent = client.send(pose, frame)
    client.probe.wait_count(EE_TARGET_REFUSED, 1, sent, timeout_s=10.0)
    assert reason in client.probe.since(EE_TARGET_REFUSED, sent)[-1].msg.data
    time.sleep(0.3)
    assert not client.probe.since(EE_TARGET_STATE, sent)


def test_estop_refuses_and_safe_action_ends_a_target(client: EeClient) -> None:
    _quiet(client)
    pose = client.tcp() + np.array([0.0, 0.05, 0, 0, 0, 0, 0])
    assert client.call(ESTOP).success
    sent = client.send(pose)
    client.probe.wait_count(EE_TARGET_REFUSED, 1, sent, timeout_s=10.0)
    assert "E-stop" in client.probe.since(EE_TARGET_REFUSED, sent)[-1].msg.data
    assert client.call(RELEASE_ESTOP).success
    sent = client.send(pose)
    client.probe.wait_count(EE_TARGET_STATE, 3, sent, timeout_s=10.0)
    hold = client.probe.latest(ACTION_SPEC)
    client.action.publish(Float64MultiArray(data=list(hold.position)))
    time.sleep(0.3)
    quiet_from = time.monotonic()
    time.sleep(0.5)
    assert not client.probe.since(EE_TARGET_STATE, quiet_from)


def _quiet(client: EeClient) -> None:
    """No target in force: the latest action spec's hold goes out as a safe_action."""
    hold = client.probe.latest(ACTION_SPEC)
    client.action.publish(Float64MultiArray(data=list(hold.position)))
    time.sleep(0.3)
