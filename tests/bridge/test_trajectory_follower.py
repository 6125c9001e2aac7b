"""TrajectoryFollower: when a path starts, what replaces what, what the hold keeps, and what
is counted; path_limits reads the manifest's envelope."""

from __future__ import annotations

import numpy as np
import pytest
from openral_bridge.joint_path import PathLimits, PathPoint, PathRefused, TrajectoryRequest
from openral_bridge.trajectory_follower import DesiredPoint, TrajectoryFollower, path_limits
from openral_core.loaded import open_robot_by_id
from openral_mujoco.state import FloatArray

LIMITS = PathLimits(
    names=("shoulder", "elbow", "gripper"),
    low=np.array([-2.0, -2.0, 0.0]),
    high=np.array([2.0, 2.0, 1.0]),
    speed=np.array([1.0, 1.0, np.inf]),
)
HOLD = np.array([0.1, -0.2, 0.7])
"""The targets in force (the hold action)."""
NOW = 10.0
PERIOD = 0.02


def _request(
    *points: tuple[float, float], start_s: float | None = None, joint: str = "shoulder"
) -> TrajectoryRequest:
    """Linear moves of one joint: (time_from_start, position) per point."""
    return TrajectoryRequest((joint,), tuple(PathPoint(t, (p,)) for t, p in points), start_s)


def _run(
    follower: TrajectoryFollower, start_s: float, ticks: int, hold: FloatArray = HOLD
) -> list[tuple[FloatArray, DesiredPoint] | None]:
    """``ticks`` control periods from ``start_s``; each action becomes the next hold."""
    steps = []
    for k in range(ticks):
        step = follower.next_action(hold, start_s + k * PERIOD, PERIOD)
        if step is not None:
            hold = step[0]
        steps.append(step)
    return steps


def _actions(steps: list[tuple[FloatArray, DesiredPoint] | None]) -> list[FloatArray | None]:
    return [None if s is None else s[0] for s in steps]


def test_a_path_without_a_stamp_starts_now_and_ends_on_its_last_point() -> None:
    follower = TrajectoryFollower(LIMITS)
    path = follower.submit(_request((0.1, 0.2)), HOLD, NOW)  # 1 rad/s: at the limit
    assert path.start_s == NOW and path.end_s == pytest.approx(NOW + 0.1)
    steps = _run(follower, NOW, 6)
    first = steps[0]
    assert first is not None
    action, desired = first
    assert action[0] == pytest.approx(0.12) and action[1:].tolist() == HOLD[1:].tolist()
    assert desired.names == ("shoulder",) and desired.time_s == pytest.approx(NOW + PERIOD)
    assert desired.positions.tolist() == pytest.approx([0.12])
    assert desired.velocities.tolist() == pytest.approx([1.0])
    last = steps[4]
    assert last is not None and last[0][0] == 0.2  # exactly on the last point
    assert steps[5] is None  # finished: the loop holds again
    assert (follower.active, follower.finished, follower.cancelled) == (False, 1, 0)


def test_a_period_ending_a_rounding_error_before_the_end_lands_on_the_last_point() -> None:
    follower = TrajectoryFollower(LIMITS)
    path = follower.submit(_request((0.3, 0.4)), HOLD, NOW)
    step = follower.next_action(HOLD, path.end_s - PERIOD - 1e-12, PERIOD)
    assert step is not None
    action, desired = step
    assert action[0] == 0.4 and desired.velocities.tolist() == [0.0]  # not 0.4 - 1e-12
    assert (follower.finished, follower.active) == (1, False)


def test_a_future_stamp_waits_for_its_start_time() -> None:
    follower = TrajectoryFollower(LIMITS)
    path = follower.submit(_request((0.1, 0.2), start_s=NOW + 0.05), HOLD, NOW)
    assert path.times_s.tolist() == pytest.approx([NOW + 0.05, NOW + 0.15])
    assert follower.active
    steps = _run(follower, NOW, 4)
    assert _actions(steps)[:2] == [None, None]  # periods ending at 10.02, 10.04
    third = steps[2]
    assert third is not None and third[1].time_s == pytest.approx(NOW + 0.06)
    assert third[0][0] == pytest.approx(0.11)  # 0.01 s into the path


def test_a_past_stamp_drops_the_points_already_passed() -> None:
    follower = TrajectoryFollower(LIMITS)
    request = _request((0.5, 1.5), (1.5, 0.5), start_s=NOW - 1.0)  # the first was at 9.5 s
    path = follower.submit(request, HOLD, NOW)
    assert path.times_s.tolist() == [NOW, NOW + 0.5]
    assert path.positions[:, 0].tolist() == [0.1, 0.5]  # from here, never via 1.5
    step = _run(follower, NOW, 1)[0]
    assert step is not None and step[0][0] == pytest.approx(0.1 + 0.8 * PERIOD)


def test_a_new_path_replaces_the_running_one_from_where_it_is_now() -> None:
    follower = TrajectoryFollower(LIMITS)
    follower.submit(_request((1.0, 0.6)), HOLD, NOW)  # 0.5 rad/s
    before = _actions(_run(follower, NOW, 10))
    last = before[-1]
    assert last is not None and last[0] == pytest.approx(0.2)
    now = NOW + 10 * PERIOD
    path = follower.submit(_request((0.5, -0.1)), last, now)
    assert path.positions[0, 0] == pytest.approx(0.2) and path.start_s == pytest.approx(now)
    after = _actions(_run(follower, now, 30, hold=last))
    assert _assert_continuous([*before, *after], speed=1.0)[-1][0] == -0.1
    assert (follower.finished, follower.cancelled) == (1, 1)


def test_a_stamped_replacement_takes_over_at_its_start_from_the_predicted_point() -> None:
    follower = TrajectoryFollower(LIMITS)
    follower.submit(_request((1.0, 0.6)), HOLD, NOW)
    first = _actions(_run(follower, NOW, 1))  # the path runs (0.5 rad/s)
    later = NOW + 0.1
    path = follower.submit(_request((0.3, 0.05), start_s=later), HOLD, NOW + PERIOD)
    assert path.start_s == later and path.positions[0, 0] == pytest.approx(0.15)
    actions = [*first, *_actions(_run(follower, NOW + PERIOD, 30))]
    assert [a[0] for a in actions[:5] if a is not None] == pytest.approx(
        [0.11, 0.12, 0.13, 0.14, 0.15]
    )  # the running path until 10.1 s, then the new one from there
    assert _assert_continuous(actions, speed=1.0)[-1][0] == 0.05
    assert (follower.finished, follower.cancelled) == (1, 1)


def _assert_continuous(actions: list[FloatArray | None], speed: float) -> FloatArray:
    """No action moves a joint further than ``speed`` allows in one period; returns the
    actions given (the ticks that followed a path)."""
    values = np.array([a for a in actions if a is not None])
    assert len(values) > 1
    assert np.abs(np.diff(values, axis=0)).max() <= speed * PERIOD * (1 + 1e-9)
    return values


def test_a_waiting_path_is_dropped_by_a_newer_one() -> None:
    follower = TrajectoryFollower(LIMITS)
    follower.submit(_request((0.1, 0.2), start_s=NOW + 0.2), HOLD, NOW)
    follower.submit(_request((0.1, 0.0), start_s=NOW + 0.1), HOLD, NOW)
    assert follower.cancelled == 1
    actions = _actions(_run(follower, NOW, 20))
    moved = [a[0] for a in actions if a is not None]
    assert moved and min(moved) == 0.0 and max(moved) <= HOLD[0]  # only the newer went down
    assert (follower.finished, follower.cancelled, follower.active) == (1, 1, False)


def test_cancel_ends_the_running_and_the_waiting_path() -> None:
    follower = TrajectoryFollower(LIMITS)
    follower.submit(_request((1.0, 0.6)), HOLD, NOW)
    _run(follower, NOW, 3)
    follower.submit(_request((1.0, 0.0), start_s=NOW + 1.0), HOLD, NOW + 3 * PERIOD)
    assert follower.cancel() is True
    assert (follower.active, follower.cancelled, follower.finished) == (False, 2, 0)
    assert _run(follower, NOW + 3 * PERIOD, 60) == [None] * 60  # neither comes back
    assert follower.cancel() is False and follower.cancelled == 2


def test_slots_the_path_does_not_name_keep_their_hold_values() -> None:
    follower = TrajectoryFollower(LIMITS)
    follower.submit(_request((0.2, 0.0), joint="elbow"), HOLD, NOW)
    hold = np.array([-1.5, 9.0, 0.25])  # whatever the loop holds now, not the submit's
    step = follower.next_action(hold, NOW, PERIOD)
    assert step is not None
    action, desired = step
    assert action[[0, 2]].tolist() == [-1.5, 0.25] and desired.names == ("elbow",)
    assert action[1] == pytest.approx(-0.2 + 0.02) and hold[1] == 9.0  # hold not written


def test_a_replacement_over_other_joints_stops_the_others_where_they_are() -> None:
    follower = TrajectoryFollower(LIMITS)
    both = TrajectoryRequest(("shoulder", "elbow"), (PathPoint(1.0, (0.6, 0.3)),))
    follower.submit(both, HOLD, NOW)
    last = _actions(_run(follower, NOW, 5))[-1]
    assert last is not None and last[1] == pytest.approx(-0.2 + 0.05)
    follower.submit(_request((0.5, 0.2)), last, NOW + 5 * PERIOD)
    after = _assert_continuous(_actions(_run(follower, NOW + 5 * PERIOD, 30, hold=last)), 1.0)
    assert set(after[:, 1]) == {last[1]}  # the elbow holds
    assert after[-1, 0] == 0.2


def test_a_refused_trajectory_changes_nothing() -> None:
    follower = TrajectoryFollower(LIMITS)
    follower.submit(_request((1.0, 0.6)), HOLD, NOW)
    with pytest.raises(PathRefused, match="shoulder would need 5"):
        follower.submit(_request((0.1, 0.6)), HOLD, NOW)
    assert (follower.active, follower.cancelled) == (True, 0)
    step = _run(follower, NOW, 1)[0]
    assert step is not None and step[0][0] == pytest.approx(0.11)


def test_path_limits_are_the_manifest_envelope_per_action_slot() -> None:
    limits = path_limits(open_robot_by_id("franka_panda"))
    assert limits.names[0] == "panda_joint1" and limits.names[-1] == "panda_finger_joint1"
    assert (limits.low[0], limits.high[0], limits.speed[0]) == (-2.8973, 2.8973, 2.175)
    assert (limits.low[3], limits.high[3]) == (-3.0718, -0.0698)
    assert limits.speed[4] == 2.61 and limits.speed[-1] == np.inf  # a gripper is not slewed
    assert limits.units[0] == "rad" and limits.units[-1] == "m"
    follower = TrajectoryFollower(limits)
    fast = TrajectoryRequest(("panda_joint1",), (PathPoint(0.1, (0.5,)),))
    with pytest.raises(PathRefused, match=r"panda_joint1 would need 5 rad/s .* 2\.175 rad/s"):
        follower.submit(fast, np.zeros(8), 0.0)


def test_a_screen_sees_the_whole_path_and_its_line_refuses_it() -> None:
    follower = TrajectoryFollower(LIMITS)
    seen: list[FloatArray] = []

    def table_below(rows: FloatArray) -> str | None:
        seen.append(rows)
        return "the path would bring hand into world (table)" if rows[:, 0].max() > 0.5 else None

    follower.screen = table_below
    follower.submit(_request((0.2, 0.3)), HOLD, NOW)  # stays above the "table"
    assert follower.active
    rows = seen[-1]
    assert rows[0].tolist() == pytest.approx(HOLD.tolist())  # from the hold
    assert rows[-1].tolist() == pytest.approx([0.3, HOLD[1], HOLD[2]])  # to the last point
    assert np.all(np.diff(rows[:, 0]) >= 0) and len(rows) >= 20  # every 10 ms of 0.2 s
    follower.cancel()
    with pytest.raises(PathRefused, match="hand into world"):
        follower.submit(_request((1.0, 0.9)), HOLD, NOW)
    assert not follower.active  # nothing waits, nothing runs
