"""Trajectories and resets from outside the franka tabletop graph: bad ones and the CLI.

- malformed or unsafe ``JointTrajectory`` messages (NaN, wrong widths, unknown or repeated
  joints, times that do not increase, nanoseconds out of range, no points, a final
  velocity, a position outside the limits) are each refused with one warning naming the
  field; the robot does not move and the graph keeps publishing;
- ``openral rskill trajectory`` moves two joints and prints how closely they tracked the
  path; a refused trajectory is one ``error:`` line and exit 1 (read from ``/rosout``);
- ``openral ros reset`` prints what was reset and exits 0.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from openral_bridge.topics import JOINT_STATES, JOINT_TRAJECTORY_STATE
from openral_nodes.trajectory_request import trajectory_msg

from tests.conftest import REPO
from tests.ros.trajectory_client import JOINTS, Client, franka_graph

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
        client.trajectory.publish(msg)
        deadline = time.monotonic() + 10.0
        while reason not in client.stderr() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert reason in client.stderr(), f"{name}: no warning containing {reason!r}"
        time.sleep(2.1)  # refusals are warned at most once per 2 s
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
