"""Trajectories and resets from outside the franka tabletop graph: bad ones and the CLI.

- malformed or unsafe ``JointTrajectory`` messages (NaN, wrong widths, unknown or repeated
  joints, 10^5 copies of a joint name, 10^5 points, times that do not increase,
  nanoseconds out of range, no points, a final velocity, a position outside the limits) are
  each refused: its reason on ``/openral/joint_trajectory/refused`` at once, a warning
  naming the field in the log (throttled); the robot does not move and the graph keeps
  publishing;
- ``openral rskill trajectory`` moves two joints and prints how closely they tracked the
  path; a refused trajectory is one ``error:`` line with the reason and exit 1;
- ``openral ros reset`` prints what was reset and exits 0.
"""

from __future__ import annotations

import gc
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from control_msgs.action import FollowJointTrajectory
from openral_bridge.topics import (
    ESTOP,
    JOINT_STATES,
    JOINT_TRAJECTORY_REFUSED,
    JOINT_TRAJECTORY_STATE,
    RELEASE_ESTOP,
)
from openral_nodes.trajectory_request import trajectory_msg

from tests.conftest import REPO
from tests.ros.action_client import TrajectoryActionClient, goal
from tests.ros.goal_flood import READY as FLOOD_READY
from tests.ros.lifecycle_client import DEPLOY_NODE, outside_client
from tests.ros.trajectory_client import JOINTS, Client, franka_graph

Result = FollowJointTrajectory.Result

OPENRAL = Path(sys.executable).parent / "openral"


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Client]:
    yield from franka_graph(tmp_path_factory.mktemp("trajectory_hostile"))


def _bad(client: Client) -> dict[str, tuple[object, str]]:
    """Name → (message, what its refusal must say)."""
    q = client.positions(client.probe.latest(JOINT_STATES)).tolist()
    nan = trajectory_msg(JOINTS, [1.0], [[q[0], float("nan")]])
    wide = trajectory_msg(JOINTS, [1.0], [[*q, 0.0]])
    unknown = trajectory_msg(("panda_joint1", "panda_jiont4"), [1.0], [q])
    repeated = trajectory_msg(("panda_joint1", "panda_joint1"), [1.0], [q])
    backwards = trajectory_msg(JOINTS, [1.0, 0.5], [q, q])
    nanosec = trajectory_msg(JOINTS, [1.0], [q])
    nanosec.points[0].time_from_start.nanosec = 2_000_000_000
    empty = trajectory_msg(JOINTS, [], [])
    names = trajectory_msg(("panda_joint1",) * 100_000, [1.0], [[q[0]] * 100_000])
    points = trajectory_msg(JOINTS, [0.001 * (k + 1) for k in range(100_000)], [q] * 100_000)
    moving_end = trajectory_msg(JOINTS, [1.0], [q], [[0.1, 0.0]])
    outside = trajectory_msg(JOINTS, [2.0], [[q[0], 0.5]])
    return {
        "nan": (nan, "points[0].positions: panda_joint4 is nan; expected a number"),
        "wide": (wide, "points[0].positions has 3 values; expected 2"),
        "unknown": (
            unknown,
            "'panda_jiont4' is not a joint of this robot (did you mean panda_joint4?)",
        ),
        "repeated": (repeated, "panda_joint1 named more than once"),
        "1e5 names": (names, "the trajectory names 100000 joints; the robot has 8"),
        "1e5 points": (points, "the trajectory has 100000 points; at most 10000"),
        "backwards": (backwards, "points[1].time_from_start (0.5 s) is not after points[0]'s"),
        "nanosec": (nanosec, "time_from_start.nanosec is 2000000000"),
        "empty": (empty, "the trajectory has no points"),
        "moving_end": (moving_end, "points[0].velocities must be 0"),
        "outside": (outside, "panda_joint4 = 0.5 is outside its limits [-3.0718, -0.0698]"),
    }


def _still(client: Client) -> np.ndarray:
    """Positions of the two joints once the arm has stopped settling (a fresh graph's arm
    sags into its servos' grip for a second or two)."""

    def resting() -> bool:
        velocities = client.probe.latest(JOINT_STATES).velocity
        return bool(np.abs(np.asarray(velocities)).max() < 1e-4)

    deadline = time.monotonic() + 20.0
    while not resting() and time.monotonic() < deadline:
        time.sleep(0.1)
    return client.positions(client.probe.latest(JOINT_STATES))


def test_each_bad_trajectory_is_refused_with_its_reason_and_moves_nothing(client: Client) -> None:
    before = _still(client)
    started = time.monotonic()
    for name, (msg, reason) in _bad(client).items():
        sent = time.monotonic()
        client.trajectory.publish(msg)
        refusal = client.probe.wait_count(JOINT_TRAJECTORY_REFUSED, 1, sent, timeout_s=20.0)
        assert reason in refusal[0].msg.data, f"{name}: {refusal[0].msg.data!r}"
    first = next(iter(_bad(client).values()))[1]
    assert first in client.stderr()  # and in the log (throttled: not each of them)
    assert not client.probe.since(JOINT_TRAJECTORY_STATE, started)
    after = client.probe.wait_count(JOINT_STATES, 5, time.monotonic())[-1].msg
    assert np.abs(client.positions(after) - before).max() < 1e-3
    assert "Traceback" not in client.stderr()


def _openral(client: Client, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(OPENRAL), *args], capture_output=True, text=True, env=client.env, timeout=60
    )


def test_rskill_trajectory_moves_the_joints_and_prints_the_tracking(client: Client) -> None:
    moves = ["--move", "panda_joint1=0.3", "--move", "panda_joint4=0.3"]
    result = _openral(client, "rskill", "trajectory", *moves, "--relative", "--seconds", "1.5")
    assert result.returncode == 0, result.stderr
    rows = {
        line.split("│")[1].strip(): line for line in result.stdout.splitlines() if "│ panda" in line
    }
    assert set(rows) == set(JOINTS)
    summary = result.stdout.strip().splitlines()[-1]
    assert summary.startswith("followed 30 desired points; joints within 0.0")
    assert float(summary.split("within ")[1].split()[0]) < 0.02
    back = ["--move", "panda_joint1=-0.3", "--move", "panda_joint4=-0.3", "--relative"]
    assert _openral(client, "rskill", "trajectory", *back, "--cubic").returncode == 0


def test_rskill_trajectory_reports_a_refusal_in_one_line(client: Client) -> None:
    result = _openral(
        client, "rskill", "trajectory", "--move", "panda_joint1=2.5", "--seconds", "0.5"
    )
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: the graph refused the trajectory: panda_joint1 would need ")
    assert lines[0].endswith("its velocity_limit is 2.175 rad/s")


def test_the_docs_example_sends_a_trajectory_the_graph_follows(client: Client) -> None:
    start = client.positions(client.probe.latest(JOINT_STATES))[0]
    script = REPO / "docs" / "examples" / "send_trajectory.py"
    result = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, env=client.env, timeout=60
    )
    assert result.returncode == 0, result.stderr
    name, value = result.stdout.strip().removeprefix("last desired point: ").split(" = ")
    assert name == "panda_joint1"
    assert float(value.removesuffix(" rad")) == pytest.approx(start + 0.3, abs=0.01)
    reached = client.positions(client.probe.latest(JOINT_STATES))[0]
    assert reached == pytest.approx(start + 0.3, abs=0.01)


def test_ros_reset_prints_what_was_reset(client: Client) -> None:
    result = _openral(client, "ros", "reset")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("franka_panda: scene reset with seed 0 (start pose, objects)")


ESTOP_LIMIT_S = 0.1
"""Longest E-stop round trip accepted while the flood runs [s]."""


def _hostile_goals(q: list[float]) -> list[tuple[object, int, str]]:
    """(goal, result code, words of its reason) of each hostile goal."""
    nan = goal(JOINTS, [(1.0, [q[0], float("nan")])])
    names = goal(("panda_joint1",) * 100_000, [(1.0, [q[0]] * 100_000)])
    points = goal(JOINTS, [(0.001 * (k + 1), q) for k in range(100_000)])
    backwards = goal(JOINTS, [(1.0, q), (0.5, q)])
    nanosec = goal(JOINTS, [(1.0, q)])
    nanosec.trajectory.points[0].time_from_start.nanosec = 1_000_000_000  # type: ignore[attr-defined]
    return [
        (nan, Result.INVALID_GOAL, "panda_joint4 is nan"),
        (names, Result.INVALID_JOINTS, "panda_joint1 named more than once"),
        (points, Result.INVALID_GOAL, "100000 points; at most 10000"),
        (backwards, Result.INVALID_GOAL, "is not after points[0]'s"),
        (nanosec, Result.INVALID_GOAL, "time_from_start.nanosec is 1000000000"),
    ]


def test_each_hostile_goal_is_rejected_with_its_reason(client: Client) -> None:
    action = TrajectoryActionClient(client.probe.node)
    q = client.positions(client.probe.latest(JOINT_STATES)).tolist()
    probe = client.probe
    try:
        for message, _code, words in _hostile_goals(q):
            since = time.monotonic()
            assert action.rejected(message, timeout_s=60.0), words
            probe.wait(lambda s=since: probe.since(JOINT_TRAJECTORY_REFUSED, s), 10.0, words)
            reasons = [r.msg.data for r in probe.since(JOINT_TRAJECTORY_REFUSED, since)]
            assert any(words in reason for reason in reasons), (words, reasons)
    finally:
        action.destroy()


@contextmanager
def _goal_flood(client: Client) -> Iterator[list[int]]:
    """:mod:`tests.ros.goal_flood` running on the graph's domain until the block ends; the
    list then holds the number of goals it sent."""
    q = client.positions(client.probe.latest(JOINT_STATES)).tolist()
    command = [sys.executable, "-m", "tests.ros.goal_flood", str(client.domain), *map(str, q)]
    process = subprocess.Popen(
        command, cwd=REPO, env=client.env, text=True, stdin=subprocess.PIPE,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    assert process.stdout is not None
    if process.stdout.readline().strip() != FLOOD_READY:
        pytest.fail(f"the flood did not start: {process.communicate('', timeout=30.0)[1]}")
    sent: list[int] = []
    try:
        yield sent
    finally:
        out, err = process.communicate("", timeout=30.0)
    assert process.returncode == 0, err
    sent.append(int(out.split()[-1]))


@pytest.mark.exclusive  # E-stop latencies under a flood: run alone
def test_a_flood_of_goals_never_delays_the_estop_or_joint_states(client: Client) -> None:
    with outside_client(client.domain, DEPLOY_NODE, "estop_during_flood") as peer:
        # a first call of each service, not measured: it may still wait on the discovery of
        # the reply's endpoints (seen: the first E-stop at ~0.1 s, the other nine 5-35 ms)
        peer.trigger(ESTOP)
        peer.trigger(RELEASE_ESTOP)
        # What is measured is the graph: a garbage collection in this process (which holds
        # the objects of every test run before) would read as a late E-stop or a gap, and
        # the flood runs in a process of its own (its serialising would hold this GIL).
        gc.collect()
        gc.disable()
        try:
            with _goal_flood(client) as sent:
                started = time.monotonic()
                round_trips = []
                time.sleep(0.5)
                for _ in range(10):
                    response, round_trip = peer.trigger(ESTOP)
                    assert response.success, response.message
                    round_trips.append(round_trip)
                    assert peer.trigger(RELEASE_ESTOP)[0].success
                    time.sleep(0.2)
        finally:
            gc.enable()
    received = client.probe.since(JOINT_STATES, started)
    gaps = np.diff([r.at for r in received])
    stamps = [r.msg.header.stamp.sec + 1e-9 * r.msg.header.stamp.nanosec for r in received]
    print(
        f"{sent[0]} goals in {received[-1].at - started:.1f} s; E-stop round trips "
        f"{np.round(round_trips, 4).tolist()} s; largest /joint_states gap {gaps.max():.3f} s "
        f"(arrivals), {np.diff(stamps).max():.3f} s (stamps)"
    )
    assert max(round_trips) < ESTOP_LIMIT_S
    assert gaps.max() < 0.25  # 50 Hz, never stopped by the flood
    assert "Traceback" not in client.stderr()
