"""Trajectory goals: the start joined from the measured state within the start tolerance,
refusal kinds, linear checks of hostile requests, the follower telling why a path ended, and
judge() deciding a goal as joint_trajectory_controller does."""

from __future__ import annotations

import numpy as np
import pytest
from openral_bridge.joint_path import (
    MAX_POINTS,
    JointPath,
    PathLimits,
    PathPoint,
    PathRefused,
    PathStart,
    Refusal,
    TrajectoryRequest,
    plan_path,
)
from openral_bridge.trajectory_follower import TrajectoryFollower
from openral_bridge.trajectory_goal import Outcome, Tolerances, judge

NAMES = ("shoulder", "elbow")
LIMITS = PathLimits(
    names=NAMES,
    low=np.array([-2.0, -2.0]),
    high=np.array([2.0, 2.0]),
    speed=np.array([1.0, 1.0]),
    units=("rad", "rad"),
)
NOW = 5.0
COMMANDED = np.array([0.0, -0.5])
SAGGED = COMMANDED + np.array([0.0, -0.04])
"""An arm that hangs 0.04 rad below its target in the elbow."""


def _from(first: tuple[float, ...], *, start_tolerance: float = 0.05) -> JointPath:
    request = TrajectoryRequest(
        NAMES, (PathPoint(0.0, first, (0.0, 0.0)), PathPoint(2.0, (0.3, -0.2), (0.0, 0.0)))
    )
    start = PathStart(NOW, COMMANDED, np.zeros(2), SAGGED, start_tolerance)
    return plan_path(request, LIMITS, start)


def test_a_plan_from_where_a_sagging_arm_is_is_joined_from_the_measured_state() -> None:
    path = _from(tuple(SAGGED))
    np.testing.assert_array_equal(path.positions[0], SAGGED)  # no jump back to the target
    np.testing.assert_array_equal(path.velocities[0], [0.0, 0.0])


def test_a_first_point_near_the_command_still_starts_from_the_command() -> None:
    path = _from(tuple(COMMANDED + 0.005))
    np.testing.assert_array_equal(path.positions[0], COMMANDED)


def test_beyond_the_start_tolerance_the_trajectory_is_refused_with_both_distances() -> None:
    with pytest.raises(PathRefused) as refused:
        _from(tuple(SAGGED + np.array([0.0, -0.07])))  # 0.07 past where the arm hangs
    message = str(refused.value)
    assert "elbow is commanded to -0.5 and measured at -0.54" in message
    assert (
        "0.05 from the measured position" in message and refused.value.kind is Refusal.INVALID_GOAL
    )
    with pytest.raises(PathRefused):  # without a start tolerance, no join from the measured
        _from(tuple(SAGGED), start_tolerance=0.0)


@pytest.mark.parametrize(
    ("names", "kind"),
    [
        (("elbow",) * 100_000, Refusal.INVALID_JOINTS),
        (("x" * 100_000,), Refusal.INVALID_JOINTS),
        ((), Refusal.INVALID_JOINTS),
    ],
    ids=["100000 repeats", "a 100 kB name", "none"],
)
def test_bad_joint_names_are_invalid_joints_in_one_line(
    names: tuple[str, ...], kind: Refusal
) -> None:
    request = TrajectoryRequest(names, (PathPoint(1.0, (0.0,) * len(names)),))
    with pytest.raises(PathRefused) as refused:
        plan_path(request, LIMITS, PathStart(NOW, COMMANDED, np.zeros(2)))
    assert refused.value.kind is kind
    assert len(str(refused.value)) < 300 and "\n" not in str(refused.value)


def test_a_trajectory_that_ended_before_now_is_an_old_header_timestamp() -> None:
    request = TrajectoryRequest(NAMES, (PathPoint(1.0, (0.1, -0.4)),), start_s=NOW - 3.0)
    with pytest.raises(PathRefused) as refused:
        plan_path(request, LIMITS, PathStart(NOW, COMMANDED, np.zeros(2)))
    assert refused.value.kind is Refusal.OLD_HEADER_TIMESTAMP


def test_more_than_max_points_is_refused() -> None:
    point = PathPoint(1.0, (0.0, 0.0))
    request = TrajectoryRequest(NAMES, (point,) * (MAX_POINTS + 1))
    with pytest.raises(PathRefused, match=f"at most {MAX_POINTS}"):
        plan_path(request, LIMITS, PathStart(NOW, COMMANDED, np.zeros(2)))


def _ramp(source: str = "a test") -> TrajectoryRequest:
    return TrajectoryRequest(NAMES, (PathPoint(1.0, (0.5, -0.5)),), source=source)


def test_the_follower_says_why_each_path_ended_early() -> None:
    follower = TrajectoryFollower(LIMITS)
    ended: list[tuple[JointPath, str]] = []
    follower.on_end = lambda path, reason: ended.append((path, reason))
    first = follower.submit(_ramp("goal A"), COMMANDED, NOW)
    second = follower.submit(_ramp("goal B"), COMMANDED, NOW)  # replaces the waiting one
    assert ended == [(first, "replaced by goal B before it started")]
    assert follower.next_action(COMMANDED, NOW, 0.05) is not None  # B runs
    third = follower.submit(_ramp("the topic"), COMMANDED, NOW + 0.05)
    follower.next_action(COMMANDED, NOW + 0.05, 0.05)  # C takes over from the running B
    assert ended[-1] == (second, "replaced by the topic")
    assert not follower.cancel("unrelated", path=second)  # only the named path, if it runs
    assert follower.follows(third) and follower.cancel("the E-stop latched", path=third)
    assert ended[-1] == (third, "the E-stop latched") and not follower.active


def _path() -> JointPath:
    request = TrajectoryRequest(NAMES, (PathPoint(1.0, (0.5, -0.5), (0.0, 0.0)),))
    return plan_path(request, LIMITS, PathStart(NOW, COMMANDED, np.zeros(2)))


def _tolerances(path_pos: float = 0.0, goal_pos: float = 0.0, goal_time: float = 0.0) -> Tolerances:
    two = np.ones(2)
    return Tolerances(two * path_pos, two * 0.0, two * goal_pos, two * 0.01, goal_time)


def test_judge_aborts_off_the_path_only_while_the_path_runs() -> None:
    path, tolerances = _path(), _tolerances(path_pos=0.05)
    middle = NOW + 0.5
    wanted = path.sample(middle)[0]
    near = judge(path, tolerances, wanted + 0.04, np.zeros(2), middle)
    far = judge(path, tolerances, wanted + np.array([0.0, 0.06]), np.zeros(2), middle)
    assert near.outcome is Outcome.RUNNING
    assert far.outcome is Outcome.PATH_TOLERANCE_VIOLATED
    assert far.message.startswith("elbow is 0.06 from its desired position (tolerance 0.05)")
    np.testing.assert_allclose(far.error_positions, [0.0, -0.06])


def test_judge_succeeds_once_within_the_goal_tolerance_and_stopped() -> None:
    path, tolerances = _path(), _tolerances(goal_pos=0.01)
    end = path.end_s
    goal = path.positions[-1]
    assert judge(path, tolerances, goal + 0.02, np.zeros(2), end).outcome is Outcome.RUNNING
    moving = np.array([0.0, 0.05])  # there, but not stopped (stopped_velocity_tolerance)
    assert judge(path, tolerances, goal + 0.005, moving, end).outcome is Outcome.RUNNING
    done = judge(path, tolerances, goal + 0.005, np.zeros(2), end + 0.05)
    assert done.outcome is Outcome.SUCCEEDED and done.message == "goal reached"


def test_judge_gives_up_after_goal_time_and_not_before() -> None:
    path, tolerances = _path(), _tolerances(goal_pos=0.01, goal_time=0.5)
    off = path.positions[-1] + 0.02
    assert judge(path, tolerances, off, np.zeros(2), path.end_s + 0.5).outcome is Outcome.RUNNING
    late = judge(path, tolerances, off, np.zeros(2), path.end_s + 0.55)
    assert late.outcome is Outcome.GOAL_TOLERANCE_VIOLATED
    assert "0.5 s after the trajectory's last point" in late.message
    forever = _tolerances(goal_pos=0.01, goal_time=0.0)  # 0: no limit, as the controller
    assert judge(path, forever, off, np.zeros(2), path.end_s + 60.0).outcome is Outcome.RUNNING
