"""FollowJointTrajectory against the live franka tabletop, from outside, as MoveIt uses it.

``openral deploy sim`` runs as a subprocess; an rclpy action client on its domain sends
goals to ``/joint_trajectory_controller/follow_joint_trajectory``:

- 3 points over 3 s on panda_joint1..7 succeed with goal tolerance 0.01 rad, with feedback
  every tick (stamps 0.01 s of simulated time apart: the state rate);
- a goal that cannot run (an unknown or missing joint, a trajectory that ended before now or
  stamped in wall time, NaN, a bad tolerance, a first point far from the joints) is
  REJECTED at goal time, its reason on /openral/joint_trajectory/refused, and nothing
  moves; a tiny path tolerance ends ABORTED with PATH_TOLERANCE_VIOLATED and an unmeetable
  goal tolerance with GOAL_TOLERANCE_VIOLATED after goal_time_tolerance, with the reason;
- the E-stop aborts a running goal (and rejects the next); a newer goal pre-empts the
  running one; a cancelled goal ends CANCELED and its path stops within one control tick.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from itertools import pairwise

import numpy as np
import pytest
from action_msgs.msg import GoalStatus
from control_msgs.action import FollowJointTrajectory
from openral_bridge.topics import (
    ESTOP,
    JOINT_STATES,
    JOINT_TRAJECTORY_REFUSED,
    JOINT_TRAJECTORY_STATE,
    RELEASE_ESTOP,
)

from tests.ros.action_client import PANDA_ARM, TrajectoryActionClient, goal
from tests.ros.trajectory_client import Client, franka_graph, stamp_s

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone

Result = FollowJointTrajectory.Result
PERIOD_S = 0.05
"""The franka tabletop's control period [s]."""
STATE_PERIOD_S = 0.01
"""The tabletop's state period (100 Hz): a tick, and a feedback, each."""


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Client]:
    yield from franka_graph(tmp_path_factory.mktemp("follow_joint_trajectory"))


@pytest.fixture(scope="module")
def action(client: Client) -> Iterator[TrajectoryActionClient]:
    action = TrajectoryActionClient(client.probe.node)
    yield action
    action.destroy()


def _arm(client: Client) -> np.ndarray:
    """Where panda_joint1..7 are now (/joint_states)."""
    msg = client.probe.latest(JOINT_STATES)
    names = list(msg.name)
    return np.array([msg.position[names.index(n)] for n in PANDA_ARM])


def _move(q: np.ndarray, by: float, seconds: float = 2.0, **tolerances: float) -> object:
    return goal(PANDA_ARM, [(0.0, q.tolist()), (seconds, (q + by).tolist())], **tolerances)


def test_a_three_point_goal_succeeds_within_0_01_rad_with_feedback_every_tick(
    client: Client, action: TrajectoryActionClient
) -> None:
    q0 = _arm(client)
    points = [(0.0, q0.tolist()), (1.5, (q0 + 0.15).tolist()), (3.0, (q0 + 0.25).tolist())]
    message = goal(PANDA_ARM, points, goal_tolerance=0.01, goal_time_s=1.0)
    status, result, sent = action.run(message)
    assert (status, result.error_code) == (GoalStatus.STATUS_SUCCEEDED, Result.SUCCESSFUL)
    reached = _arm(client)
    print(f"reached - goal: {np.round(reached - q0 - 0.25, 4).tolist()} rad")
    assert np.abs(reached - (q0 + 0.25)).max() < 0.01
    stamps = np.array([stamp_s(f) for _, f in sent.feedback])
    wall = np.diff([t for t, _ in sent.feedback])
    print(f"{len(stamps)} feedback messages, wall interval median {np.median(wall):.4f} s")
    gaps = [(round(a, 3), round(b, 3)) for a, b in pairwise(stamps) if b - a > 0.011]
    assert len(stamps) >= 3.0 / STATE_PERIOD_S - 2, f"missing between {gaps}"  # one a tick
    np.testing.assert_allclose(np.diff(stamps), STATE_PERIOD_S, atol=1e-6)  # every tick once
    last = sent.feedback[-1][1]
    assert list(last.joint_names) == list(PANDA_ARM)
    np.testing.assert_allclose(
        np.array(last.error.positions),
        np.array(last.desired.positions) - np.array(last.actual.positions),
    )
    status, _, _ = action.run(_move(reached, -0.25, seconds=2.0))  # back where it started
    assert status == GoalStatus.STATUS_SUCCEEDED


@pytest.mark.parametrize(
    ("case", "words"),
    [
        ("unknown joint", "'panda_joint8' is not a joint of this robot"),
        ("missing joint", "expected 7, one per joint"),
        ("old stamp", "before now"),
        ("wall-clock stamp", "a clock mismatch?"),
        ("NaN", "panda_joint3 is nan"),
        ("bad tolerance", "goal_tolerance[0].position is -2.0"),
        ("start too far", "trajectory.start_tolerance"),
    ],
)
def test_a_bad_goal_is_rejected_at_goal_time_with_its_reason(
    client: Client, action: TrajectoryActionClient, case: str, words: str
) -> None:
    q = _arm(client)
    message = _move(q, 0.1)
    trajectory = message.trajectory  # type: ignore[attr-defined]
    if case == "unknown joint":
        trajectory.joint_names[-1] = "panda_joint8"
    elif case == "missing joint":  # a point with fewer positions than joints
        trajectory.points[1].positions = trajectory.points[1].positions[:-1]
    elif case == "old stamp":  # started 5 s ago, ended 3 s ago
        client.probe.wait(lambda: client.now_s() > 6.0, 30.0, "6 s of simulated time")
        trajectory.header.stamp.sec = int(client.now_s()) - 5
    elif case == "wall-clock stamp":  # a client on wall time under simulated time
        trajectory.header.stamp.sec = int(time.time())
    elif case == "NaN":
        trajectory.points[1].positions[2] = float("nan")
    elif case == "start too far":
        trajectory.points[0].positions[0] += 0.5
    else:
        message = _move(q, 0.1, goal_tolerance=-2.0)
    since = time.monotonic()
    assert action.rejected(message), f"{case}: accepted"
    client.probe.wait(
        lambda: client.probe.since(JOINT_TRAJECTORY_REFUSED, since), 5.0, "the refusal"
    )
    reasons = [r.msg.data for r in client.probe.since(JOINT_TRAJECTORY_REFUSED, since)]
    assert any(words in reason for reason in reasons), reasons
    assert np.abs(_arm(client) - q).max() < 0.005  # nothing moved


def test_path_and_goal_tolerance_violations_abort_with_their_codes(
    client: Client, action: TrajectoryActionClient
) -> None:
    q = _arm(client)
    status, result, _ = action.run(_move(q, 0.2, path_tolerance=1e-4))
    assert (status, result.error_code) == (
        GoalStatus.STATUS_ABORTED,
        Result.PATH_TOLERANCE_VIOLATED,
    )
    assert "(path_tolerance)" in result.error_string
    q = _arm(client)
    started = client.now_s()
    message = _move(q, 0.05, seconds=1.0, goal_tolerance=1e-6, goal_time_s=0.3)
    status, result, _ = action.run(message)
    assert (status, result.error_code) == (
        GoalStatus.STATUS_ABORTED,
        Result.GOAL_TOLERANCE_VIOLATED,
    )
    assert "0.3 s after the trajectory's last point" in result.error_string
    assert client.now_s() - started >= 1.3 - PERIOD_S  # it waited out goal_time_tolerance


def test_the_estop_aborts_a_running_goal_and_refuses_the_next(
    client: Client, action: TrajectoryActionClient
) -> None:
    q = _arm(client)
    sent = action.send(_move(q, -0.2, seconds=3.0))
    client.probe.wait(lambda: len(sent.feedback) >= 10, 10.0, "10 feedback messages")
    response = client.call(ESTOP)
    assert response.success and "aborted" in response.message
    status, result = action.result(sent)
    assert status == GoalStatus.STATUS_ABORTED
    assert result.error_string == "the trajectory stopped: the E-stop latched"
    assert action.rejected(_move(_arm(client), 0.1))  # "the E-stop is latched", logged
    assert client.call(RELEASE_ESTOP).success


def test_a_newer_goal_preempts_the_running_one(
    client: Client, action: TrajectoryActionClient
) -> None:
    q = _arm(client)
    first = action.send(_move(q, 0.3, seconds=3.0))
    client.probe.wait(lambda: len(first.feedback) >= 10, 10.0, "10 feedback messages")
    second = action.send(_move(q, 0.0, seconds=1.0))  # back to q at rest: from where it is
    status, result = action.result(first)
    assert (status, result.error_code) == (GoalStatus.STATUS_ABORTED, Result.INVALID_GOAL)
    assert result.error_string == "pre-empted by a newer goal"
    assert action.result(second)[0] == GoalStatus.STATUS_SUCCEEDED


def test_a_cancelled_goal_stops_its_path_within_one_control_tick(
    client: Client, action: TrajectoryActionClient
) -> None:
    q = _arm(client)
    sent = action.send(_move(q, 0.3, seconds=3.0))
    client.probe.wait(lambda: len(sent.feedback) >= 20, 10.0, "20 feedback messages")
    cancel_wall, cancel_sim = time.monotonic(), client.now_s()
    assert len(action.cancel(sent).goals_canceling) == 1
    status, _ = action.result(sent)
    assert status == GoalStatus.STATUS_CANCELED
    time.sleep(0.5)
    later = [
        stamp_s(r.msg)
        for r in client.probe.since(JOINT_TRAJECTORY_STATE, cancel_wall)
        if stamp_s(r.msg) > cancel_sim + 2 * PERIOD_S + 1e-6  # the /clock seen lags a tick
    ]
    assert not later, f"desired points after the cancel: {later}"
    moved = _arm(client) - q
    assert 0.0 < moved.max() < 0.3  # stopped part-way
