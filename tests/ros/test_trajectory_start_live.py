"""A plan that starts where a sagging arm is: the H1's torque-PD hip hangs 0.04 rad below its
target under gravity, and a FollowJointTrajectory goal whose first point is where the joint
is measured (as MoveIt plans from /joint_states) is accepted and followed; one beyond the
robot's start tolerance is refused with both distances.

``openral deploy sim`` runs the H1 tabletop as a subprocess; the client is outside.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from action_msgs.msg import GoalStatus
from control_msgs.action import FollowJointTrajectory
from openral_bridge.topics import ACTION_SPEC, JOINT_STATES
from openral_bridge.topics import JOINT_TRAJECTORY_REFUSED as REFUSED
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from tests.conftest import ROBOTS
from tests.ros.action_client import TrajectoryActionClient, goal
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import Probe

H1_SCENE = ROBOTS / "h1" / "scenes" / "tabletop.yaml"
JOINT = "left_hip_pitch"
START_WAIT_S = 90.0
Result = FollowJointTrajectory.Result


@pytest.fixture(scope="module")
def h1(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Probe, TrajectoryActionClient]]:
    logs: Path = tmp_path_factory.mktemp("trajectory_start")
    domain = claim_domain_id()
    with ros_session(domain_id=domain) as context:
        topics = {JOINT_STATES: JointState, ACTION_SPEC: JointState, REFUSED: String}
        probe = Probe(context, topics, name="start_client")
        with Spinner(context) as spinner, deploy_sim(H1_SCENE, domain, logs) as process:
            spinner.add_node(probe.node)
            probe.wait_count(JOINT_STATES, 1, timeout_s=START_WAIT_S)
            action = TrajectoryActionClient(probe.node, timeout_s=START_WAIT_S)
            assert process.poll() is None, deploy_output(logs)
            yield probe, action
            action.destroy()
        probe.node.destroy_node()  # type: ignore[no-untyped-call]


def _measured_and_commanded(probe: Probe) -> tuple[float, float]:
    """The hip's position on /joint_states once it hangs still, and its target (the hold
    action the graph announced)."""

    def still() -> bool:
        msg = probe.latest(JOINT_STATES)
        return abs(msg.velocity[list(msg.name).index(JOINT)]) < 1e-3

    probe.wait(still, 20.0, f"{JOINT} at rest")
    msg = probe.latest(JOINT_STATES)
    measured = float(msg.position[list(msg.name).index(JOINT)])
    spec = probe.wait_count(ACTION_SPEC, 1, timeout_s=20.0)[0].msg
    return measured, float(spec.position[list(spec.name).index(JOINT)])


def test_a_goal_from_where_a_sagging_joint_hangs_is_accepted_and_followed(
    h1: tuple[Probe, TrajectoryActionClient],
) -> None:
    probe, action = h1
    measured, commanded = _measured_and_commanded(probe)
    sag = commanded - measured
    print(f"{JOINT}: commanded {commanded:.4f} rad, measured {measured:.4f} rad, sag {sag:.4f}")
    assert 0.03 < abs(sag) < 0.05  # a real sag, past the 0.01 rad of a commanded start
    message = goal((JOINT,), [(0.0, [measured]), (2.0, [measured + 0.1])])
    status, result, sent = action.run(message)
    assert (status, result.error_code) == (GoalStatus.STATUS_SUCCEEDED, Result.SUCCESSFUL)
    first = sent.feedback[0][1]
    assert abs(first.desired.positions[0] - measured) < 0.01  # joined from where it hung


def test_a_goal_beyond_the_start_tolerance_is_refused_with_both_distances(
    h1: tuple[Probe, TrajectoryActionClient],
) -> None:
    probe, action = h1
    measured, _ = _measured_and_commanded(probe)
    away = measured - 0.06 if measured - 0.06 > -1.5 else measured + 0.06
    since = time.monotonic()
    assert action.rejected(goal((JOINT,), [(0.0, [away]), (2.0, [away])]))
    probe.wait(lambda: probe.since(REFUSED, since), 5.0, "the refusal's reason")
    reason = probe.since(REFUSED, since)[-1].msg.data
    assert f"{JOINT} is commanded to" in reason
    assert "measured at" in reason
    assert "trajectory.start_tolerance" in reason
    still = probe.latest(JOINT_STATES)
    assert abs(still.position[list(still.name).index(JOINT)] - measured) < 0.005
