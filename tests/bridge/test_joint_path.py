"""plan_path: every refusal rule names its field in one line; the exact speed check agrees
with dense sampling; sample() is continuous and hits every knot (hypothesis properties)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from openral_bridge.joint_path import (
    MAX_POINTS,
    SPEED_SLACK,
    START_TOLERANCE,
    JointPath,
    PathLimits,
    PathPoint,
    PathRefused,
    PathStart,
    TrajectoryRequest,
    plan_path,
)
from openral_bridge.trajectory_follower import TrajectoryFollower
from openral_mujoco.state import FloatArray

NAMES = ("shoulder", "elbow", "slide", "gripper")
LIMITS = PathLimits(
    names=NAMES,
    low=np.array([-2.0, -1.0, 0.0, 0.0]),
    high=np.array([2.0, 1.0, 0.5, 0.04]),
    speed=np.array([1.0, 2.0, 0.25, np.inf]),
    units=("rad", "rad", "m", "m"),
)
NOW = 10.0
START = PathStart(NOW, np.array([0.1, -0.2, 0.3, 0.02]), np.zeros(4))
SAMPLES = 2049
"""Samples per segment of the dense checks (2048 intervals)."""


def _request(
    names: tuple[str, ...], *points: tuple[float, tuple[float, ...], tuple[float, ...]]
) -> TrajectoryRequest:
    return TrajectoryRequest(names, tuple(PathPoint(t, p, v) for t, p, v in points))


def _refusal(request: TrajectoryRequest, start: PathStart = START) -> str:
    with pytest.raises(PathRefused) as refused:
        plan_path(request, LIMITS, start)
    message = str(refused.value)
    assert "\n" not in message and message
    return message


NAN, INF = math.nan, math.inf
REFUSALS = {
    "unknown joint": (
        _request(("elbw",), (1.0, (0.0,), ())),
        "joint_names: 'elbw' is not a joint of this robot (did you mean elbow?)",
    ),
    "repeated joint": (
        _request(("elbow", "slide", "elbow"), (1.0, (0.0, 0.3, 0.0), ())),
        "joint_names: elbow named more than once",
    ),
    "no joints": (_request((), (1.0, (), ())), "joint_names is empty"),
    "no points": (_request(("elbow",)), "the trajectory has no points"),
    "short positions": (
        _request(("elbow", "slide"), (1.0, (0.0, 0.3), ()), (2.0, (0.0,), ())),
        "points[1].positions has 1 values; expected 2",
    ),
    "velocities width": (
        _request(("elbow", "slide"), (1.0, (0.0, 0.3), (0.0,))),
        "points[0].velocities has 1 values; expected 0 or 2",
    ),
    "NaN position": (
        _request(("shoulder", "elbow"), (1.0, (0.1, NAN), ())),
        "points[0].positions: elbow is nan; expected a number",
    ),
    "inf velocity": (
        _request(("shoulder",), (1.0, (0.1,), (0.0,)), (2.0, (0.1,), (-INF,))),
        "points[1].velocities: shoulder is -inf; expected a number",
    ),
    "NaN time": (
        _request(("elbow",), (NAN, (0.0,), ())),
        "points[0].time_from_start is nan; expected a finite time >= 0 s",
    ),
    "inf time": (
        _request(("elbow",), (1.0, (0.0,), ()), (INF, (0.0,), ())),
        "points[1].time_from_start is inf",
    ),
    "negative time": (
        _request(("elbow",), (-0.5, (0.0,), ())),
        "points[0].time_from_start is -0.5",
    ),
    "repeated time": (
        _request(("elbow",), (1.0, (0.0,), ()), (1.0, (0.1,), ())),
        "points[1].time_from_start (1 s) is not after points[0]'s (1 s)",
    ),
    "time going back": (
        _request(("elbow",), (2.0, (0.0,), ()), (1.5, (0.1,), ())),
        "points[1].time_from_start (1.5 s) is not after points[0]'s (2 s)",
    ),
    "outside limits": (
        _request(("slide", "elbow"), (1.0, (0.3, -0.2), ()), (3.0, (0.3, 1.5), ())),
        "points[1].positions: elbow = 1.5 is outside its limits [-1, 1]",
    ),
    "first point away from the start": (
        _request(("elbow", "shoulder"), (0.0, (-0.2, 0.6), ()), (2.0, (0.0, 0.6), ())),
        "points[0] is at time 0 but shoulder is commanded to 0.1 now, 0.5 away",
    ),
    "moving at the end": (
        _request(("elbow",), (1.0, (0.0,), (0.5,)), (2.0, (0.1,), (0.1,))),
        "points[1].velocities must be 0: the joints stop there",
    ),
    "too fast": (
        _request(("elbow", "shoulder"), (1.0, (-0.2, 1.6), ())),
        "shoulder would need 1.5 rad/s between the start and t=11.000 s; "
        "its velocity_limit is 1 rad/s",
    ),
    "too fast in metres": (
        _request(("slide",), (1.0, (0.3,), ()), (2.0, (0.0,), ())),
        "slide would need 0.3 m/s between knot 1 and t=12.000 s; its velocity_limit is 0.25 m/s",
    ),
}


@pytest.mark.parametrize("case", REFUSALS, ids=str)
def test_each_rule_refuses_the_whole_trajectory_naming_its_field(case: str) -> None:
    request, expected = REFUSALS[case]
    assert expected in _refusal(request)


def test_a_trajectory_that_ended_before_now_is_refused() -> None:
    request = _request(("elbow",), (1.0, (0.0,), ()), (2.0, (0.1,), ()))
    late = TrajectoryRequest(request.joint_names, request.points, start_s=NOW - 3.0)
    assert _refusal(late) == (
        "the trajectory ended at t=9.000 s (simulated), before now (t=10.000 s)"
    )


def test_more_points_than_allowed_are_refused_before_any_is_read() -> None:
    point = PathPoint(1.0, (NAN,))
    request = TrajectoryRequest(("elbow",), (point,) * (MAX_POINTS + 1))
    assert _refusal(request) == f"the trajectory has {MAX_POINTS + 1} points; at most {MAX_POINTS}"


def test_a_cubic_that_overshoots_the_limit_between_its_knots_is_refused() -> None:
    """0.1 -> 0.85 rad in 1 s is 0.75 rad/s in a straight line, but a cubic from rest to
    rest peaks at 1.5 times that: 1.125 rad/s, over the limit of 1."""
    linear = _request(("shoulder",), (1.0, (0.85,), ()))
    assert plan_path(linear, LIMITS, START).end_s == NOW + 1.0
    cubic = _request(("shoulder",), (1.0, (0.85,), (0.0,)))
    assert "shoulder would need 1.125 rad/s" in _refusal(cubic)


def test_a_huge_knot_velocity_is_refused_not_turned_into_nan() -> None:
    """A finite velocity whose Hermite tangent (velocity x duration) overflows once made
    the exact speed NaN, and NaN > limit is False: the path was accepted and sampled inf."""
    request = _request(("shoulder",), (2.0, (0.2,), (1e308,)), (4.0, (0.3,), (0.0,)))
    assert "shoulder would need 1e+308 rad/s" in _refusal(request)


def test_a_cubic_that_bulges_past_a_position_limit_between_knots_is_refused() -> None:
    """Both knots inside [-1, 1], speeds within 2 rad/s, but leaving 0.9 at 2 rad/s to come
    back to 0.9 a second later carries the cubic to 1.4 in between."""
    bulge = _request(("elbow",), (1.0, (0.9,), (2.0,)), (2.0, (0.9,), (0.0,)))
    message = _refusal(bulge)
    assert message.startswith("elbow would reach 1.")
    assert message.endswith("outside its limits [-1, 1]")
    within = _request(("elbow",), (1.0, (0.5,), (0.5,)), (2.0, (0.6,), (0.0,)))
    assert plan_path(within, LIMITS, START).end_s == NOW + 2.0


def test_an_unlimited_joint_is_refused_an_unbounded_speed() -> None:
    """The gripper has no speed limit, but a tangent that overflows is no speed at all."""
    request = _request(("gripper",), (2.0, (0.03,), (1e308,)), (4.0, (0.02,), (0.0,)))
    assert "gripper would need an unbounded speed" in _refusal(request)


def test_a_path_exactly_at_its_limit_passes() -> None:
    request = _request(("shoulder",), (1.5, (1.6,), ()))  # 1.5 rad in 1.5 s: 1 rad/s
    path = plan_path(request, LIMITS, START)
    assert path.segment(0).fastest() == pytest.approx([1.0], rel=1e-12)


def test_the_start_knot_stands_for_a_point_at_time_zero_near_it() -> None:
    near = START.positions[1] + 0.9 * START_TOLERANCE
    request = _request(("elbow",), (0.0, (near,), ()), (1.0, (0.5,), ()))
    path = plan_path(request, LIMITS, START)
    assert path.times_s.tolist() == [NOW, NOW + 1.0]
    assert path.positions[:, 0].tolist() == [START.positions[1], 0.5]  # no jump to ``near``


def test_passed_points_are_dropped_and_a_future_start_waits() -> None:
    points = _request(("slide", "elbow"), (0.5, (0.3, 0.0), ()), (2.0, (0.4, 0.5), ())).points
    past = plan_path(TrajectoryRequest(("slide", "elbow"), points, NOW - 1.0), LIMITS, START)
    assert past.times_s.tolist() == [NOW, NOW + 1.0]  # the point at 9.5 s is gone
    assert past.slots.tolist() == [2, 1] and past.positions[0].tolist() == [0.3, -0.2]
    future = plan_path(TrajectoryRequest(("slide", "elbow"), points, NOW + 3.0), LIMITS, START)
    assert future.times_s.tolist() == [NOW + 3.0, NOW + 3.5, NOW + 5.0]
    at_rest, speed = future.sample(NOW + 2.0)
    assert at_rest.tolist() == [0.3, -0.2] and speed.tolist() == [0.0, 0.0]


# -- properties ------------------------------------------------------------------------------

WIDTH = 3
position = st.floats(-2.0, 2.0)
velocity = st.floats(-3.0, 3.0)


@dataclass(frozen=True)
class Knots:
    durations: list[float]
    positions: list[list[float]]
    velocities: list[list[float] | None]


@st.composite
def knots(draw: st.DrawFn, count: tuple[int, int] = (2, 4)) -> Knots:
    n = draw(st.integers(*count))
    row = st.lists(position, min_size=WIDTH, max_size=WIDTH)
    speeds = st.none() | st.lists(velocity, min_size=WIDTH, max_size=WIDTH)
    return Knots(
        durations=draw(st.lists(st.floats(0.05, 4.0), min_size=n - 1, max_size=n - 1)),
        positions=draw(st.lists(row, min_size=n, max_size=n)),
        velocities=draw(st.lists(speeds, min_size=n, max_size=n)),
    )


def _path(k: Knots, start_s: float = NOW) -> JointPath:
    nan_row = [math.nan] * WIDTH
    return JointPath(
        names=NAMES[:WIDTH],
        slots=np.arange(WIDTH),
        times_s=start_s + np.concatenate([[0.0], np.cumsum(k.durations)]),
        positions=np.array(k.positions),
        velocities=np.array([nan_row if v is None else v for v in k.velocities]),
    )


def _speeds(path: JointPath, k: int, lo: float = 0.0, hi: float = 1.0) -> FloatArray:
    """|velocity| of segment ``k`` at SAMPLES fractions from ``lo`` to ``hi`` of it, ends
    included (one row per sample): what sample() gives inside the segment, and at its ends
    the segment's own limits (sample() there is the next segment's, or at rest)."""
    t0, t1 = float(path.times_s[k]), float(path.times_s[k + 1])
    times = t0 + (t1 - t0) * np.linspace(lo, hi, SAMPLES)
    return np.array([np.abs(path.segment(k).at(float(t))[1]) for t in times])


@settings(max_examples=60, deadline=None)
@given(knots(count=(2, 3)))
def test_the_exact_speed_is_the_densely_sampled_maximum(k: Knots) -> None:
    path = _path(k)
    for segment in range(len(path.times_s) - 1):
        exact, sampled = path.segment(segment).fastest(), _speeds(path, segment).max(axis=0)
        assert np.all(exact >= sampled * (1.0 - 1e-12))  # a bound, never below (rounding)
        assert exact == pytest.approx(sampled, rel=1e-6, abs=1e-12)


def _planned(k: Knots) -> tuple[TrajectoryRequest, PathStart, JointPath]:
    """A request from ``k`` (its first knot is where the joints are now, moving at its
    velocities or at rest) and the path plan_path should build for it."""
    if k.velocities[-1] is not None:  # the joints must stop at the last point
        k.velocities[-1] = [0.0] * WIDTH
    offsets = np.cumsum(k.durations)
    points = tuple(
        PathPoint(float(t), tuple(p), tuple(v or ()))
        for t, p, v in zip(offsets, k.positions[1:], k.velocities[1:], strict=True)
    )
    v0 = k.velocities[0] or [0.0] * WIDTH
    start = PathStart(NOW, np.array(k.positions[0]), np.array(v0))
    expected = _path(Knots(k.durations, k.positions, [v0, *k.velocities[1:]]))
    return TrajectoryRequest(NAMES[:WIDTH], points), start, expected


SPEED_LIMITS = PathLimits(
    NAMES[:WIDTH], np.full(WIDTH, -2.0), np.full(WIDTH, 2.0), np.array([1.0, 2.0, 3.0])
)


@settings(max_examples=60, deadline=None)
@given(knots())
def test_accepted_paths_keep_to_the_limits_and_refused_ones_break_them(k: Knots) -> None:
    request, start, expected = _planned(k)
    segments = range(len(expected.times_s) - 1)
    try:
        path = plan_path(request, SPEED_LIMITS, start)
    except PathRefused as refused:
        name = str(refused).split(" ", 1)[0]
        joint = NAMES.index(name)
        if str(refused).startswith(f"{name} would reach "):  # a cubic bulging past a limit
            worst_position = max(np.abs(_positions(expected, s)[:, joint]).max() for s in segments)
            assert worst_position > SPEED_LIMITS.high[joint]
            return
        assert str(refused).startswith(f"{name} would need ")
        worst = max(_peak_speed(expected, s, joint) for s in segments)
        assert worst > SPEED_LIMITS.speed[joint] * (1.0 + SPEED_SLACK)
        return
    for field in ("times_s", "positions", "velocities"):
        np.testing.assert_array_equal(getattr(path, field), getattr(expected, field))
    for s in segments:
        assert np.all(_speeds(path, s) <= SPEED_LIMITS.speed * (1.0 + SPEED_SLACK))
        inside = np.abs(_positions(path, s)) <= SPEED_LIMITS.high + 1e-12
        assert np.all(inside)


def _positions(path: JointPath, k: int) -> FloatArray:
    """Positions of segment ``k`` at SAMPLES fractions of it, ends included."""
    t0, t1 = float(path.times_s[k]), float(path.times_s[k + 1])
    times = t0 + (t1 - t0) * np.linspace(0.0, 1.0, SAMPLES)
    return np.array([path.segment(k).at(float(t))[0] for t in times])


def _peak_speed(path: JointPath, k: int, joint: int) -> float:
    """The dense maximum of one joint on segment ``k``, sampled again around its coarse
    peak (2048 times as fine)."""
    coarse = _speeds(path, k)[:, joint]
    i = int(np.argmax(coarse))
    grid = np.linspace(0.0, 1.0, SAMPLES)
    lo, hi = float(grid[max(i - 1, 0)]), float(grid[min(i + 1, SAMPLES - 1)])
    return max(float(coarse[i]), float(_speeds(path, k, lo, hi)[:, joint].max()))


@settings(max_examples=80, deadline=None)
@given(knots(count=(2, 5)), st.floats(1e-9, 1e-6))
def test_sample_hits_every_knot_and_is_continuous_there(k: Knots, eps: float) -> None:
    path = _path(k)
    for i, time_s in enumerate(path.times_s):
        at, _ = path.sample(float(time_s))
        np.testing.assert_array_equal(at, path.positions[i])
        for side in (-eps, eps):
            near, _ = path.sample(float(time_s) + side)
            assert np.abs(near - at).max() <= 1000.0 * eps + 1e-12  # no path here is that fast
    before, rest = path.sample(path.start_s - 1.0)
    after, stop = path.sample(path.end_s + 1.0)
    assert before.tolist() == k.positions[0] and after.tolist() == k.positions[-1]
    assert not rest.any() and not stop.any()


@settings(max_examples=60, deadline=None)
@given(knots(count=(2, 4)), st.floats(0.01, 0.99))
def test_the_sampled_velocity_is_the_derivative_of_the_sampled_position(
    k: Knots, fraction: float
) -> None:
    path = _path(k)
    h = 1e-6
    for s in range(len(path.times_s) - 1):
        t0, t1 = path.times_s[s], path.times_s[s + 1]
        t = float(t0 + (t1 - t0) * fraction)
        ahead, behind, (_, v) = path.sample(t + h), path.sample(t - h), path.sample(t)
        numeric = (ahead[0] - behind[0]) / (2 * h)
        np.testing.assert_allclose(numeric, v, rtol=1e-5, atol=1e-5)


hostile = st.sampled_from(
    [REFUSALS[c][0] for c in ("unknown joint", "NaN time", "outside limits", "too fast")]
)


@settings(max_examples=30, deadline=None)
@given(hostile, st.integers(0, 30), st.booleans())
def test_a_refused_request_leaves_a_follower_as_it_was(
    bad: TrajectoryRequest, ticks: int, waiting: bool
) -> None:
    good = _request(("shoulder", "elbow"), (1.0, (0.6, 0.0), (0.0, 0.0)))
    later = TrajectoryRequest(good.joint_names, good.points, start_s=NOW + 0.2)
    twins = (TrajectoryFollower(LIMITS), TrajectoryFollower(LIMITS))
    for follower in twins:
        follower.submit(good, START.positions, NOW)
        if waiting:
            follower.submit(later, START.positions, NOW)
    with pytest.raises(PathRefused):
        twins[0].submit(bad, START.positions, NOW)
    for tick in range(ticks):
        now = NOW + 0.02 * tick
        steps = [f.next_action(START.positions, now, 0.02) for f in twins]
        assert (steps[0] is None) == (steps[1] is None)
        if steps[0] is not None and steps[1] is not None:
            np.testing.assert_array_equal(steps[0][0], steps[1][0])
    counts = [(f.active, f.finished, f.cancelled) for f in twins]
    assert counts[0] == counts[1]
