"""Joint trajectories and the reset service of the franka tabletop, from outside the graph.

``openral deploy sim`` runs as a subprocess; a client on a domain of its own sends
``trajectory_msgs/JointTrajectory`` on ``/openral/joint_trajectory`` and calls
``/openral/reset`` as a ROS tool would, and reads ``/joint_states``, the trajectory state
and the wrist camera:

- panda_joint1 and panda_joint4 each move +0.5 rad in 2.0 s (a two-point trajectory):
  ``/joint_states`` is within 0.02 rad of the straight-line path at 0.5, 1.0, 1.5 and
  2.0 s after its start; the same with velocities (a cubic) against the cubic path;
- a trajectory over a velocity limit is refused whole (one warning naming the joint and
  the speed) and moves nothing;
- a ``safe_action`` pre-empts a trajectory, the E-stop aborts one;
- after 5 s of motion ``/openral/reset`` brings ``/joint_states`` back to the start state
  within 1e-6 rad and the wrist camera shows the episode's first frame again, pixel for
  pixel: the first frame after an earlier reset of the same seed, and the graph's very
  first frame when the client caught it (discovery on a loaded machine may miss it).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from openral_bridge.topics import (
    ESTOP,
    JOINT_STATES,
    JOINT_TRAJECTORY_STATE,
    RELEASE_ESTOP,
    RESET,
)
from openral_nodes.trajectory_request import trajectory_msg
from std_msgs.msg import Float64MultiArray

from tests.ros.trajectory_client import JOINTS, WRIST, Client, franka_graph, stamp_s

TOLERANCE_RAD = 0.02


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Client]:
    yield from franka_graph(tmp_path_factory.mktemp("trajectory_live"))


def _send_plus_half(
    client: Client, *, cubic: bool, lead_ticks: int = 10
) -> tuple[float, np.ndarray]:
    """Send +0.5 rad on both joints in 2.0 s, starting ``lead_ticks`` ticks from now (a
    header stamp in simulated time); returns (start time, start positions)."""
    start_positions = client.positions(client.probe.latest(JOINT_STATES))
    msg = trajectory_msg(
        JOINTS,
        [0.0, 2.0],
        [start_positions.tolist(), (start_positions + 0.5).tolist()],
        [[0.0, 0.0], [0.0, 0.0]] if cubic else None,
    )
    start_s = client.now_s() + lead_ticks * 0.05  # on the tick grid: /clock is a tick's time
    msg.header.stamp.sec = int(start_s)
    msg.header.stamp.nanosec = round((start_s - int(start_s)) * 1e9)
    client.trajectory.publish(msg)
    return start_s, start_positions


@pytest.mark.parametrize("cubic", [False, True], ids=["linear", "cubic"])
def test_a_two_point_trajectory_is_followed_within_0_02_rad(client: Client, cubic: bool) -> None:
    _settle(client)
    now = time.monotonic()
    start_s, q0 = _send_plus_half(client, cubic=cubic)
    for offset in (0.5, 1.0, 1.5, 2.0):
        s = offset / 2.0
        shape = 3 * s**2 - 2 * s**3 if cubic else s
        expected = q0 + 0.5 * shape
        reached = client.positions(client.state_at(start_s + offset, now))
        error = reached - expected
        kind = "cubic" if cubic else "linear"
        print(f"{kind} t={offset:.1f} s: error {error.round(4).tolist()} rad")
        assert np.abs(error).max() < TOLERANCE_RAD
    desired = client.probe.since(JOINT_TRAJECTORY_STATE, now)
    assert desired and list(desired[-1].msg.name) == list(JOINTS)
    assert np.allclose(desired[-1].msg.position, q0 + 0.5, atol=1e-9)
    _back(client, q0)


def test_a_trajectory_over_the_velocity_limit_is_refused_and_moves_nothing(client: Client) -> None:
    _settle(client)
    before = client.positions(client.probe.latest(JOINT_STATES))
    msg = trajectory_msg(JOINTS, [0.5], [(before + np.array([1.5, 0.0])).tolist()])  # 3 rad/s
    now = time.monotonic()
    client.trajectory.publish(msg)
    time.sleep(1.5)
    after = client.positions(client.probe.latest(JOINT_STATES))
    assert np.abs(after - before).max() < 1e-3
    assert not client.probe.since(JOINT_TRAJECTORY_STATE, now)
    err = client.stderr()
    refusals = [line for line in err.splitlines() if "trajectory refused" in line]
    assert refusals and "panda_joint1 would need 3 " in refusals[-1], refusals
    assert "velocity_limit is 2.175 rad/s" in refusals[-1]


def test_safe_action_preempts_and_estop_aborts_a_trajectory(client: Client) -> None:
    _settle(client)
    q0 = client.positions(client.probe.latest(JOINT_STATES))
    for interrupt in ("safe_action", "estop"):
        client.trajectory.publish(trajectory_msg(JOINTS, [4.0], [(q0 + 0.4).tolist()]))
        client.probe.wait_count(JOINT_TRAJECTORY_STATE, 3, time.monotonic())
        if interrupt == "safe_action":
            hold = client.probe.latest(JOINT_STATES)
            client.action.publish(Float64MultiArray(data=list(hold.position[:8])))
        else:
            assert client.call(ESTOP).message.endswith("the joint trajectory is aborted")
        time.sleep(0.3)
        quiet_from = time.monotonic()
        time.sleep(0.5)
        assert not client.probe.since(JOINT_TRAJECTORY_STATE, quiet_from), interrupt
    assert client.call(RELEASE_ESTOP).success
    _back(client, q0)


def _start_of_episode(client: Client, after: float) -> tuple[float, Any, Any]:
    """(stamp, wrist frame, joint state) of the first step after a reset called at
    ``after``: the earliest simulated time published since (time starts again)."""
    client.probe.wait_count(WRIST, 1, after, timeout_s=15.0)
    time.sleep(0.5)
    first = min(client.probe.since(WRIST, after), key=lambda r: stamp_s(r.msg)).msg
    return stamp_s(first), first, client.state_at(stamp_s(first), after)


def test_reset_restores_the_start_state_and_the_first_frame(client: Client) -> None:
    before = time.monotonic()
    answer = client.call(RESET)
    assert answer.success, answer.message
    assert "seed 0" in answer.message
    print(f"reset: {answer.message}")
    start_s, frame, joints = _start_of_episode(client, before)
    goal = (client.positions(joints) + 0.6).tolist()
    client.trajectory.publish(trajectory_msg(JOINTS, [5.0], [goal]))
    time.sleep(5.0)
    moved = client.probe.latest(JOINT_STATES)
    assert np.abs(client.positions(moved) - client.positions(joints)).max() > 0.3
    again = time.monotonic()
    assert client.call(RESET).success
    stamp, frame_again, joints_again = _start_of_episode(client, again)
    assert stamp == start_s
    assert np.abs(np.array(joints_again.position) - np.array(joints.position)).max() < 1e-6
    assert bytes(frame_again.data) == bytes(frame.data)
    first = client.probe.messages[WRIST][0].msg  # the graph's very first frame, if caught
    if stamp_s(first) == start_s:
        assert bytes(first.data) == bytes(frame.data)


def _settle(client: Client) -> None:
    """Let an earlier test's motion die down."""
    time.sleep(0.5)


def _back(client: Client, q0: np.ndarray) -> None:
    """Return the two joints to ``q0`` over 2 s and wait for it."""
    here = client.positions(client.probe.latest(JOINT_STATES))
    client.trajectory.publish(trajectory_msg(JOINTS, [0.0, 2.0], [here.tolist(), q0.tolist()]))
    time.sleep(2.8)
